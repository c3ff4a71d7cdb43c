//! `robowire.g1`'s service objects: `G1Loco` (service `sport`, Unitree's `LocoClient`) and
//! `G1ArmActions` (service `arm`, `G1ArmActionClient`), each a call with the GIL released.

use std::future::Future;

use pyo3::prelude::*;
use unitree::g1::{G1, G1Error};

use super::{Shared, blocking, client};
use crate::errors::{Kind, error};

/// Runs `call` on the client's service that `service` picks (a clone: the client's lock is not
/// held while it waits), with the GIL released.
fn service_call<S: Clone, T: Send, F>(
    py: Python<'_>,
    shared: &Shared,
    service: impl FnOnce(&G1) -> &S,
    call: impl FnOnce(S) -> F,
) -> PyResult<T>
where
    F: Future<Output = Result<T, G1Error>> + Send,
{
    // The client itself is not kept while the call waits: `close()` does not wait for it.
    let service = service(&*client(shared)?).clone();
    blocking(py, call(service))
}

/// `#[pyclass] struct $class` (a service of the client, `$pick` picks it: the facade's
/// `$service`) and its `call`: runs a call on the service with the GIL released.
macro_rules! service_class {
    ($(#[$doc:meta])* $class:ident, $service:ty, $pick:path) => {
        $(#[$doc])*
        #[pyclass(module = "robowire.g1", frozen)]
        pub(crate) struct $class {
            pub(super) client: Shared,
        }

        impl $class {
            fn call<T: Send, F>(&self, py: Python<'_>, call: impl FnOnce($service) -> F) -> PyResult<T>
            where
                F: Future<Output = Result<T, G1Error>> + Send,
            {
                service_call(py, &self.client, $pick, call)
            }
        }
    };
}

service_class!(
    /// The G1's locomotion service (service `sport`, Unitree's `LocoClient`). Arguments are checked
    /// before anything is sent (`ArgumentError`); a refusal is a `ServiceError` with its `code`:
    /// 7301 (locomotion unavailable after `G1.release()`, until `G1.select_mode()`), 7302 (no such
    /// FSM id), 7303 (no such arm task). Every call waits at most the client's `service_timeout_s`.
    Loco, unitree::g1::Loco, G1::loco
);

#[pymethods]
impl Loco {
    /// GetFsmId: the controller's state (0 zero torque, 1 damp, 2 squat, 3 sit, 4 stand up,
    /// 500 walking, …).
    fn fsm_id(&self, py: Python<'_>) -> PyResult<i64> {
        self.call(py, |l| async move { l.fsm_id().await })
    }

    /// GetFsmMode.
    fn fsm_mode(&self, py: Python<'_>) -> PyResult<i64> {
        self.call(py, |l| async move { l.fsm_mode().await })
    }

    /// SetFsmId `fsm_id`.
    fn set_fsm(&self, py: Python<'_>, fsm_id: i64) -> PyResult<()> {
        self.call(py, |l| async move { l.set_fsm(fsm_id).await })
    }

    /// FSM 0: zero torque (the robot falls if not held).
    fn zero_torque(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |l| async move { l.zero_torque().await })
    }

    /// FSM 1: damping.
    fn damp(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |l| async move { l.damp().await })
    }

    /// FSM 2: squat.
    fn squat(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |l| async move { l.squat().await })
    }

    /// FSM 3: sit.
    fn sit(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |l| async move { l.sit().await })
    }

    /// FSM 4: stand up (locked standing).
    fn stand_up(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |l| async move { l.stand_up().await })
    }

    /// FSM 500: the walking controller (where `set_velocity`, arm actions and `rt/arm_sdk` work).
    fn start(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |l| async move { l.start().await })
    }

    /// SetVelocity: walk at `vx_mps` forward (|vx| ≤ 1 m/s), `vy_mps` left (|vy| ≤ 0.5 m/s),
    /// `yaw_radps` counter-clockwise (|yaw| ≤ 1 rad/s) for `duration_s` (0..=864000 s). Raises
    /// `ArgumentError` (nothing sent) for NaN or a value out of its bound.
    #[pyo3(signature = (vx_mps, vy_mps, yaw_radps, duration_s = 1.0))]
    fn set_velocity(&self, py: Python<'_>, vx_mps: f32, vy_mps: f32, yaw_radps: f32, duration_s: f32) -> PyResult<()> {
        self.call(py, |l| async move { l.set_velocity(vx_mps, vy_mps, yaw_radps, duration_s).await })
    }

    /// Stops walking: velocity 0 for 1 s (Unitree's `StopMove`).
    fn stop_move(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |l| async move { l.stop_move().await })
    }

    /// SetBalanceMode: 0 balance stand, 1 continuous gait. Raises `ArgumentError` for another.
    fn set_balance_mode(&self, py: Python<'_>, mode: u8) -> PyResult<()> {
        let mode = match mode {
            0 => unitree::g1::BalanceMode::BalanceStand,
            1 => unitree::g1::BalanceMode::ContinuousGait,
            other => {
                return Err(error(
                    Kind::Argument,
                    format!("balance mode {other}: 0 (balance stand) or 1 (continuous gait)"),
                ));
            }
        };
        self.call(py, |l| async move { l.set_balance_mode(mode).await })
    }

    /// GetBalanceMode: 0 balance stand, 1 continuous gait.
    fn balance_mode(&self, py: Python<'_>) -> PyResult<u8> {
        self.call(py, |l| async move { l.balance_mode().await.map(|m| m as u8) })
    }

    /// SetStandHeight, m (0..=2).
    fn set_stand_height(&self, py: Python<'_>, height_m: f32) -> PyResult<()> {
        self.call(py, |l| async move { l.set_stand_height(height_m).await })
    }

    /// GetStandHeight, m.
    fn stand_height(&self, py: Python<'_>) -> PyResult<f32> {
        self.call(py, |l| async move { l.stand_height().await })
    }

    /// SetSwingHeight, m (0..=2).
    fn set_swing_height(&self, py: Python<'_>, height_m: f32) -> PyResult<()> {
        self.call(py, |l| async move { l.set_swing_height(height_m).await })
    }

    /// GetSwingHeight, m.
    fn swing_height(&self, py: Python<'_>) -> PyResult<f32> {
        self.call(py, |l| async move { l.swing_height().await })
    }

    /// SetArmTask `task` (wave hand 0, turning wave 1, shake hand 2 and 3).
    fn set_arm_task(&self, py: Python<'_>, task: i64) -> PyResult<()> {
        self.call(py, |l| async move { l.set_arm_task(task).await })
    }

    fn __repr__(&self) -> String {
        format!("Loco(open={})", self.client.is_open())
    }
}

service_class!(
    /// The G1's arm action service (service `arm`, Unitree's `G1ArmActionClient`). A refusal is a
    /// `ServiceError` with its `code`: 7400 (`rt/arm_sdk` in use: ramp its weight to 0 first), 7401
    /// (the arms hold an action: `release_arm()`), 7402 (no such action), 7404 (actions run only in
    /// FSM 500, 501 and 801). Every call waits at most the client's `service_timeout_s`.
    ArmActions, unitree::g1::ArmActions, G1::arm
);

#[pymethods]
impl ArmActions {
    /// ExecuteAction `action_id` (Unitree's ids: 99 release the arms, 11 two-hand kiss, 15
    /// hands up, 17 clap, 18 high five, 19 hug, 20 heart, 26 high wave, 27 shake hand, …).
    fn execute_action(&self, py: Python<'_>, action_id: i64) -> PyResult<()> {
        self.call(py, |a| async move { a.execute_action(action_id).await })
    }

    /// Action 99: the arms let go of a held action.
    fn release_arm(&self, py: Python<'_>) -> PyResult<()> {
        self.call(py, |a| async move { a.release_arm().await })
    }

    /// GetActionList: the answer's data as the robot sends it (JSON text).
    fn action_list(&self, py: Python<'_>) -> PyResult<String> {
        self.call(py, |a| async move { a.action_list().await })
    }

    fn __repr__(&self) -> String {
        format!("ArmActions(open={})", self.client.is_open())
    }
}
