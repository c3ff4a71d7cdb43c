//! [`Loco`]: the G1's locomotion service (service `sport`, Unitree's `LocoClient`,
//! `unitree_proto::api::g1_loco`) as typed calls. Arguments are checked before anything is sent;
//! the service's documented refusals are typed ([`G1Error::LocoStateUnavailable`],
//! [`G1Error::InvalidFsmId`], [`G1Error::InvalidTaskId`]).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use crate::UnitreeError;
use crate::services::ServiceHandle;
use serde_json::Value;
use unitree_proto::api::g1_loco::{self, error, fsm};

use crate::g1::G1Error;
use crate::g1::error::within;

/// robowire's bound on the forward velocity of [`Loco::set_velocity`], m/s (either way).
pub const VX_MAX_MPS: f32 = 1.0;
/// robowire's bound on the sideways velocity, m/s (either way).
pub const VY_MAX_MPS: f32 = 0.5;
/// robowire's bound on the yaw rate, rad/s (either way).
pub const YAW_RATE_MAX_RADPS: f32 = 1.0;
/// The longest duration of a velocity command, s (Unitree's continuous `Move` sends 864000).
pub const VELOCITY_DURATION_MAX_S: f32 = 864_000.0;
/// The highest stand or swing height robowire sends, m.
pub const HEIGHT_MAX_M: f32 = 2.0;

/// What the walking controller balances with (`SetBalanceMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum BalanceMode {
    /// 0: stands still when not moving.
    BalanceStand = 0,
    /// 1: keeps stepping.
    ContinuousGait = 1,
}

/// A velocity command, checked before it is sent: every value finite, |vx| ≤ [`VX_MAX_MPS`],
/// |vy| ≤ [`VY_MAX_MPS`], |yaw| ≤ [`YAW_RATE_MAX_RADPS`], duration in 0..=
/// [`VELOCITY_DURATION_MAX_S`]. The controller may limit further.
///
/// ```
/// use unitree::g1::Velocity;
/// let walk = Velocity { vx_mps: 0.3, vy_mps: 0.0, yaw_radps: 0.1, duration_s: 1.0 };
/// assert_eq!(walk.parameter().unwrap(), r#"{"velocity":[0.3,0,0.1],"duration":1}"#);
/// assert!(Velocity { vx_mps: f32::NAN, ..walk }.parameter().is_err());
/// assert!(Velocity { vx_mps: 3.0, ..walk }.parameter().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Velocity {
    /// Forward, m/s.
    pub vx_mps: f32,
    /// Left, m/s.
    pub vy_mps: f32,
    /// Yaw rate, counter-clockwise, rad/s.
    pub yaw_radps: f32,
    /// How long the controller keeps it, s.
    pub duration_s: f32,
}

impl Velocity {
    /// The `SetVelocity` parameter (`{"velocity":[vx,vy,yaw],"duration":s}`), or why not.
    pub fn parameter(&self) -> Result<String, G1Error> {
        let vx = within("vx_mps", self.vx_mps, -VX_MAX_MPS, VX_MAX_MPS)?;
        let vy = within("vy_mps", self.vy_mps, -VY_MAX_MPS, VY_MAX_MPS)?;
        let yaw = within("yaw_radps", self.yaw_radps, -YAW_RATE_MAX_RADPS, YAW_RATE_MAX_RADPS)?;
        let duration = within("duration_s", self.duration_s, 0.0, VELOCITY_DURATION_MAX_S)?;
        // `f32`'s Display: the shortest decimal that reads back the same, never an exponent.
        Ok(format!(r#"{{"velocity":[{vx},{vy},{yaw}],"duration":{duration}}}"#))
    }
}

/// The G1's locomotion service (service `sport`, Unitree's `LocoClient`,
/// `unitree_proto::api::g1_loco`) as typed calls. Arguments are checked before anything is sent;
/// the service's documented refusals are typed ([`G1Error::LocoStateUnavailable`],
/// [`G1Error::InvalidFsmId`], [`G1Error::InvalidTaskId`]). Every call: any executor, the
/// low-level options' service timeout.
#[derive(Debug, Clone)]
pub struct Loco {
    service: ServiceHandle,
    asked: Arc<Asked>,
}

/// The velocities [`Loco::ask_velocity`] sent without waiting, and how they were answered.
#[derive(Debug, Default)]
struct Asked {
    sent: AtomicU64,
    refused: AtomicU64,
    last_refusal: Mutex<Option<String>>,
}

/// What [`Loco::ask_velocity`] sent and the robot refused (or did not answer).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct VelocityAsks {
    /// SetVelocity calls sent.
    pub sent: u64,
    /// Refused or unanswered.
    pub refused: u64,
    /// Why the last one was.
    pub last_refusal: Option<String>,
}

/// `{"data": value}`.
fn data(value: impl std::fmt::Display) -> String {
    format!(r#"{{"data":{value}}}"#)
}

impl Loco {
    pub(crate) fn new(service: ServiceHandle) -> Self {
        Self { service, asked: Arc::default() }
    }

    /// Calls `api_id` with `parameter`; the documented refusals typed (`fsm`, `task`: the ids
    /// sent, for the errors).
    async fn call(&self, api_id: i64, parameter: String, sent: Option<i64>) -> Result<Value, G1Error> {
        let answer = self.service.call(api_id, parameter).await.map_err(|e| match e {
            UnitreeError::Refused { code: error::LOCO_STATE_UNAVAILABLE, .. } => {
                G1Error::LocoStateUnavailable { api_id }
            }
            UnitreeError::Refused { code: error::INVALID_FSM_ID, .. } => {
                G1Error::InvalidFsmId { fsm: sent.unwrap_or(-1) }
            }
            UnitreeError::Refused { code: error::INVALID_TASK_ID, .. } => {
                G1Error::InvalidTaskId { task: sent.unwrap_or(-1) }
            }
            e => G1Error::from(e),
        })?;
        Ok(serde_json::from_str(&answer.data).unwrap_or(Value::Null))
    }

    /// A getter's `{"data": …}`, read by `read`.
    async fn get<T>(&self, api_id: i64, read: impl Fn(&Value) -> Option<T>) -> Result<T, G1Error> {
        let answer = self.call(api_id, "{}".into(), None).await?;
        read(&answer["data"]).ok_or_else(|| {
            G1Error::LowLevel(UnitreeError::Unexpected { service: g1_loco::SERVICE, data: answer.to_string() })
        })
    }

    /// GetFsmId: the controller's state (0 zero torque, 1 damp, 2 squat, 3 sit, 4 stand up,
    /// 500 walking, …).
    pub async fn fsm_id(&self) -> Result<i64, G1Error> {
        self.get(g1_loco::GET_FSM_ID, Value::as_i64).await
    }

    /// GetFsmMode.
    pub async fn fsm_mode(&self) -> Result<i64, G1Error> {
        self.get(g1_loco::GET_FSM_MODE, Value::as_i64).await
    }

    /// SetFsmId `id` (see `unitree_proto::api::g1_loco::fsm`); an id the controller lacks is
    /// [`G1Error::InvalidFsmId`].
    pub async fn set_fsm(&self, id: i64) -> Result<(), G1Error> {
        self.call(g1_loco::SET_FSM_ID, data(id), Some(id)).await.map(drop)
    }

    /// FSM 0: zero torque (the robot falls if not held).
    pub async fn zero_torque(&self) -> Result<(), G1Error> {
        self.set_fsm(fsm::ZERO_TORQUE).await
    }

    /// FSM 1: damping.
    pub async fn damp(&self) -> Result<(), G1Error> {
        self.set_fsm(fsm::DAMP).await
    }

    /// FSM 2: squat.
    pub async fn squat(&self) -> Result<(), G1Error> {
        self.set_fsm(fsm::SQUAT).await
    }

    /// FSM 3: sit.
    pub async fn sit(&self) -> Result<(), G1Error> {
        self.set_fsm(fsm::SIT).await
    }

    /// FSM 4: stand up (locked standing).
    pub async fn stand_up(&self) -> Result<(), G1Error> {
        self.set_fsm(fsm::STAND_UP).await
    }

    /// FSM 500: the walking controller (where `set_velocity`, arm actions and `rt/arm_sdk` work).
    pub async fn start(&self) -> Result<(), G1Error> {
        self.set_fsm(fsm::START).await
    }

    /// SetVelocity: walk at `vx_mps` forward, `vy_mps` left, `yaw_radps` for `duration_s`;
    /// checked first (see [`Velocity`]), nothing sent on a bad value.
    pub async fn set_velocity(&self, vx_mps: f32, vy_mps: f32, yaw_radps: f32, duration_s: f32) -> Result<(), G1Error> {
        let parameter = Velocity { vx_mps, vy_mps, yaw_radps, duration_s }.parameter()?;
        self.call(g1_loco::SET_VELOCITY, parameter, None).await.map(drop)
    }

    /// SetVelocity without waiting for the answer, for a thread that must not block (a
    /// bridge's `cmd_vel` listener): checked now (see [`Velocity`]; nothing sent on a bad value),
    /// the call made on the client's receive thread; refusals counted in
    /// [`velocity_asks`](Self::velocity_asks).
    pub fn ask_velocity(&self, velocity: Velocity) -> Result<(), G1Error> {
        let parameter = velocity.parameter()?;
        let asked = self.asked.clone();
        asked.sent.fetch_add(1, Ordering::Relaxed);
        self.service.call_detached(g1_loco::SET_VELOCITY, parameter, move |answer| {
            if let Err(e) = answer {
                asked.refused.fetch_add(1, Ordering::Relaxed);
                *robowire_rt::lock(&asked.last_refusal) = Some(e.to_string());
            }
        });
        Ok(())
    }

    /// After [`ask_velocity`](Self::ask_velocity) sent anything: asks zero velocity and waits
    /// up to `wait` for the answer (a closing client's last word; the controller would otherwise
    /// hold the last velocity for its duration).
    pub(crate) fn stop_asked(&self, wait: std::time::Duration) {
        if self.asked.sent.load(Ordering::Relaxed) == 0 {
            return;
        }
        let (answered, answer) = std::sync::mpsc::channel();
        let zero = Velocity { vx_mps: 0.0, vy_mps: 0.0, yaw_radps: 0.0, duration_s: 1.0 };
        if let Ok(parameter) = zero.parameter() {
            self.service.call_detached(g1_loco::SET_VELOCITY, parameter, move |a| {
                let _ = answered.send(a.is_ok());
            });
            let _ = answer.recv_timeout(wait);
        }
    }

    /// What [`ask_velocity`](Self::ask_velocity) sent and the robot refused so far.
    pub fn velocity_asks(&self) -> VelocityAsks {
        VelocityAsks {
            sent: self.asked.sent.load(Ordering::Relaxed),
            refused: self.asked.refused.load(Ordering::Relaxed),
            last_refusal: robowire_rt::lock(&self.asked.last_refusal).clone(),
        }
    }

    /// Stops walking: velocity 0 for 1 s (Unitree's `StopMove`).
    pub async fn stop_move(&self) -> Result<(), G1Error> {
        self.set_velocity(0.0, 0.0, 0.0, 1.0).await
    }

    /// SetBalanceMode.
    pub async fn set_balance_mode(&self, mode: BalanceMode) -> Result<(), G1Error> {
        self.call(g1_loco::SET_BALANCE_MODE, data(mode as u8), None).await.map(drop)
    }

    /// GetBalanceMode.
    pub async fn balance_mode(&self) -> Result<BalanceMode, G1Error> {
        self.get(g1_loco::GET_BALANCE_MODE, |v| match v.as_i64()? {
            0 => Some(BalanceMode::BalanceStand),
            1 => Some(BalanceMode::ContinuousGait),
            _ => None,
        })
        .await
    }

    /// SetStandHeight, m: finite, 0..=[`HEIGHT_MAX_M`] checked here; the controller holds what it
    /// can.
    pub async fn set_stand_height(&self, height_m: f32) -> Result<(), G1Error> {
        let height = within("stand_height_m", height_m, 0.0, HEIGHT_MAX_M)?;
        self.call(g1_loco::SET_STAND_HEIGHT, data(height), None).await.map(drop)
    }

    /// GetStandHeight, m.
    pub async fn stand_height(&self) -> Result<f32, G1Error> {
        self.get(g1_loco::GET_STAND_HEIGHT, |v| v.as_f64().map(|h| h as f32)).await
    }

    /// SetSwingHeight, m: finite, 0..=[`HEIGHT_MAX_M`] checked here.
    pub async fn set_swing_height(&self, height_m: f32) -> Result<(), G1Error> {
        let height = within("swing_height_m", height_m, 0.0, HEIGHT_MAX_M)?;
        self.call(g1_loco::SET_SWING_HEIGHT, data(height), None).await.map(drop)
    }

    /// GetSwingHeight, m.
    pub async fn swing_height(&self) -> Result<f32, G1Error> {
        self.get(g1_loco::GET_SWING_HEIGHT, |v| v.as_f64().map(|h| h as f32)).await
    }

    /// SetArmTask `task` (wave hand 0, turning wave 1, shake hand 2 and 3); a task the
    /// controller lacks is [`G1Error::InvalidTaskId`].
    pub async fn set_arm_task(&self, task: i64) -> Result<(), G1Error> {
        self.call(g1_loco::SET_ARM_TASK, data(task), Some(task)).await.map(drop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walk() -> Velocity {
        Velocity { vx_mps: 0.5, vy_mps: -0.2, yaw_radps: 0.25, duration_s: 2.0 }
    }

    #[test]
    fn a_velocity_is_checked_before_it_is_sent() {
        let parameter = walk().parameter().unwrap();
        let json: Value = serde_json::from_str(&parameter).unwrap();
        assert_eq!(json, serde_json::json!({"velocity": [0.5, -0.2, 0.25], "duration": 2}));
        for bad in [
            Velocity { vx_mps: f32::NAN, ..walk() },
            Velocity { vx_mps: -1.5, ..walk() },
            Velocity { vy_mps: f32::INFINITY, ..walk() },
            Velocity { vy_mps: 0.6, ..walk() },
            Velocity { yaw_radps: -1.01, ..walk() },
            Velocity { duration_s: -1.0, ..walk() },
            Velocity { duration_s: 1e7, ..walk() },
        ] {
            assert!(matches!(bad.parameter(), Err(G1Error::Argument { .. })), "{bad:?}");
        }
        let edge = Velocity { vx_mps: -VX_MAX_MPS, vy_mps: VY_MAX_MPS, yaw_radps: 0.0, duration_s: 864_000.0 };
        let json: Value = serde_json::from_str(&edge.parameter().unwrap()).unwrap();
        assert_eq!(json["duration"], 864_000);
        let Err(G1Error::Argument { name, .. }) = Velocity { yaw_radps: 2.0, ..walk() }.parameter() else {
            panic!("refused")
        };
        assert_eq!(name, "yaw_radps");
    }
}
