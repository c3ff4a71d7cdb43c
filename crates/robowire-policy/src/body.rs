//! The robots a policy drives, through their facades: the G1 ([`unitree::g1::G1`]) and the Go2
//! ([`unitree::go2::LowLevel`]). Each reads its latest LowState, latches targets through the
//! facade's checks, damps, and releases the robot's own controller.

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::Duration;

use robowire_core::schedule::Time;
use robowire_dds::qos::Qos;
use robowire_rt::device::Device;
use unitree::g1::{G1, JOINTS};
use unitree::{Go2, JointCommand, LowLevel};
use unitree_proto::sport_state::SportModeState;

use crate::config::MsgType;
use crate::control::MotorTarget;

/// The topic of the base's velocity in the world frame.
pub const SPORT_STATE_TOPIC: &str = "rt/sportmodestate";

/// What the robot reported last.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// The IMU's orientation (w, x, y, z).
    pub quaternion_wxyz: [f32; 4],
    /// The IMU's angular velocity, rad/s.
    pub gyroscope_rad_s: [f32; 3],
    /// The base's velocity in the world, m/s, where the body knows it with the state (else
    /// [`Body::base_velocity`] reads it).
    pub base_velocity_world_mps: Option<[f32; 3]>,
    /// How long ago it arrived.
    pub age: Duration,
}

/// A Unitree robot's low-level client as a policy drives it.
pub trait Body: Send + Sync + 'static {
    /// Its message family.
    const MSG_TYPE: MsgType;

    /// Each joint's position range by slot, rad (a slot without a joint: `None`).
    fn joint_range(motor: usize) -> Option<(f32, f32)>;

    /// The latest state: the IMU returned, each motor's angle and velocity written into `q_rad`
    /// and `dq_rad_s` (by slot); `None` before the first.
    fn sense(&self, q_rad: &mut [f32], dq_rad_s: &mut [f32]) -> Option<Reading>;

    /// Latches `targets` (every other motor without gains) if the robot's rules allow them.
    fn command(&self, targets: &[MotorTarget]) -> Result<(), String>;

    /// Damping from the next LowCmd on.
    fn damp(&self);

    /// Waits up to `timeout` for a LowState (the latest counts); whether one came. Any executor.
    fn wait_state(&self, timeout: Duration) -> impl Future<Output = bool> + Send;

    /// Lets the robot's own controller go (Unitree's motion_switcher), from any executor.
    fn release(&self) -> impl Future<Output = Result<u32, String>> + Send;

    /// Starts reading the base's velocity for `base_lin_vel`, where [`Reading`] does not carry
    /// it.
    fn base_velocity(&self) -> Result<Option<Arc<BaseVelocity>>, robowire_dds::DdsError>;
}

fn joints<const N: usize>(targets: &[MotorTarget]) -> Result<[JointCommand; N], String> {
    let mut joints = [JointCommand::default(); N];
    for t in targets {
        let joint = joints.get_mut(t.motor).ok_or_else(|| format!("motor {} is past the robot's {N}", t.motor))?;
        *joint = JointCommand::hold(t.q_rad, t.kp, t.kd);
    }
    Ok(joints)
}

fn read<const N: usize>(q: &mut [f32], dq: &mut [f32], motors: [(f32, f32); N]) {
    for (slot, (pos, vel)) in motors.into_iter().enumerate() {
        if let (Some(q), Some(dq)) = (q.get_mut(slot), dq.get_mut(slot)) {
            (*q, *dq) = (pos, vel);
        }
    }
}

impl Body for G1 {
    const MSG_TYPE: MsgType = MsgType::Hg;

    fn joint_range(motor: usize) -> Option<(f32, f32)> {
        unitree::g1::JOINT_LIMITS.get(motor).map(|l| (l.q_min, l.q_max))
    }

    fn sense(&self, q: &mut [f32], dq: &mut [f32]) -> Option<Reading> {
        let latest = self.latest()?;
        let s = &latest.state;
        read::<JOINTS>(q, dq, core::array::from_fn(|i| (s.motor_state[i].q.get(), s.motor_state[i].dq.get())));
        Some(Reading {
            quaternion_wxyz: s.imu_state.quaternion.map(|v| v.get()),
            gyroscope_rad_s: s.imu_state.gyroscope.map(|v| v.get()),
            base_velocity_world_mps: None,
            age: latest.age(),
        })
    }

    fn command(&self, targets: &[MotorTarget]) -> Result<(), String> {
        self.set_joints(&joints::<JOINTS>(targets)?).map_err(|e| e.to_string())
    }

    fn damp(&self) {
        // Refused only before the first LowState, when nothing was sent.
        let _ = G1::damp(self);
    }

    async fn wait_state(&self, timeout: Duration) -> bool {
        G1::wait_state(self, timeout, |_| true).await.is_some()
    }

    async fn release(&self) -> Result<u32, String> {
        G1::release(self).await.map_err(|e| e.to_string())
    }

    fn base_velocity(&self) -> Result<Option<Arc<BaseVelocity>>, robowire_dds::DdsError> {
        BaseVelocity::read(self.low_level().participant(), self.receiving().runtime()).map(Some)
    }
}

impl Body for LowLevel<Go2> {
    const MSG_TYPE: MsgType = MsgType::Go;

    fn joint_range(motor: usize) -> Option<(f32, f32)> {
        unitree::GO2_JOINT_LIMITS.get(motor).map(|l| (l.q_min, l.q_max))
    }

    fn sense(&self, q: &mut [f32], dq: &mut [f32]) -> Option<Reading> {
        let latest = self.latest()?;
        let s = &latest.state;
        read::<12>(q, dq, core::array::from_fn(|i| (s.motor_state[i].q.get(), s.motor_state[i].dq.get())));
        Some(Reading {
            quaternion_wxyz: s.imu_state.quaternion.map(|v| v.get()),
            gyroscope_rad_s: s.imu_state.gyroscope.map(|v| v.get()),
            base_velocity_world_mps: None,
            age: latest.age(),
        })
    }

    fn command(&self, targets: &[MotorTarget]) -> Result<(), String> {
        self.set_joints(&joints::<12>(targets)?).map_err(|e| e.to_string())
    }

    fn damp(&self) {
        LowLevel::damp(self);
    }

    async fn wait_state(&self, timeout: Duration) -> bool {
        LowLevel::wait_state(self, timeout, |_| true).await.is_some()
    }

    async fn release(&self) -> Result<u32, String> {
        self.release_sport_mode().await.map_err(|e| e.to_string())
    }

    fn base_velocity(&self) -> Result<Option<Arc<BaseVelocity>>, robowire_dds::DdsError> {
        BaseVelocity::read(LowLevel::participant(self), self.receiving().runtime()).map(Some)
    }
}

/// The base's velocity in the world frame from `rt/sportmodestate`, the latest kept in atomics
/// by a task on the client's receive thread.
#[derive(Debug, Default)]
pub struct BaseVelocity {
    velocity: [AtomicU32; 3],
    /// When the latest arrived, ns on robowire's clock (0: none yet).
    at_ns: AtomicU64,
}

impl BaseVelocity {
    /// Starts reading `rt/sportmodestate` on `participant`, on `runtime` (a client's receive
    /// thread).
    pub fn read(
        participant: &robowire_dds::Participant,
        runtime: &tokio::runtime::Handle,
    ) -> Result<Arc<Self>, robowire_dds::DdsError> {
        let mut reader = participant.reader::<SportModeState>(SPORT_STATE_TOPIC, Qos::READER)?;
        let latest = Arc::new(Self::default());
        let weak = Arc::downgrade(&latest);
        runtime.spawn(async move {
            while let Ok(sample) = reader.recv().await {
                let Some(latest) = weak.upgrade() else { break };
                for (slot, v) in latest.velocity.iter().zip(sample.value.velocity) {
                    slot.store(v.get().to_bits(), Ordering::Relaxed);
                }
                latest.at_ns.store(robowire_rt::now().as_nanos(), Ordering::Release);
            }
        });
        Ok(latest)
    }

    /// The latest velocity, m/s, if one arrived within `max_age`.
    pub fn latest(&self, max_age: Duration) -> Option<[f32; 3]> {
        let at = self.at_ns.load(Ordering::Acquire);
        let fresh = at != 0 && robowire_rt::now().saturating_duration_since(Time::from_nanos(at)) <= max_age;
        fresh.then(|| self.velocity.each_ref().map(|v| f32::from_bits(v.load(Ordering::Relaxed))))
    }
}
