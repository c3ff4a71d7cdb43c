//! The HighLevel client: the vendor's calls and getters under Rust names.

use std::sync::Mutex;
use std::time::Duration;

use robowire_rt::device::Device;
use zsl_proto::gate::{HighLevelCall, gate};
use zsl_proto::rules::AckCounter;
use zsl_proto::stream::{Connection, HighLevelInterface};
use zsl_proto::udp::{ControlMode, HighLevelCommand, HighLevelState, ReturnCode};
use zsl_proto::zerocopy::little_endian::F32;

use super::session::{ClientStats, Session, client_accessors};
use super::snapshot::{BodyState, Imu, LegJoints, RobotState};
use super::{CallError, ClientOptions, ConnectError, Latched};

/// The ZSL-1 HighLevel client (the vendor's `HighLevel`): a stream thread sends the latched
/// command every 2 ms, a receive thread keeps the latest state and the watchdog. No runtime
/// needed: calls only latch a command and return. Closing (or dropping) sends the stop burst.
///
/// Every motion call goes through the vendor's checks first (`zsl_proto::gate`: the vendor's
/// order, plus NaN and infinities); a refused call changes nothing. A call that passes latches
/// its command, which the stream thread sends at once: `Ok(Latched)` says so, with the vendor's
/// return code and whether the robot already reports the mode the call asks for (whether it
/// obeys shows in [`control_mode`](Self::control_mode)).
///
/// ```no_run
/// use zsl::udp::{ClientOptions, HighLevel};
/// let dog = HighLevel::open(ClientOptions::default())?; // 0.0.0.0:43988 → 192.168.234.1
/// dog.stand_up()?;
/// dog.move_velocity(0.5, 0.0, 0.0)?;
/// dog.close();
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct HighLevel {
    session: Session<HighLevelInterface>,
    acks: Mutex<[AckCounter; HighLevelCall::ACKNOWLEDGED]>,
}

impl std::fmt::Debug for HighLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HighLevel")
            .field("local", &self.session.local_addr())
            .field("dog", &self.session.options.dog)
            .field("connection", &self.connection())
            .finish_non_exhaustive()
    }
}

macro_rules! getters {
    ($($(#[$doc:meta])* $name:ident -> $ty:ty = |$s:ident| $e:expr;)*) => {$(
        $(#[$doc])*
        ///
        /// `None` before the first state and after a watchdog timeout.
        pub fn $name(&self) -> Option<$ty> {
            self.session.read(|$s| $e)
        }
    )*};
}

fn floats<const N: usize>(v: &[F32; N]) -> [f32; N] {
    v.map(F32::get)
}

impl HighLevel {
    /// Binds `options.local` and starts streaming the idle command to `options.dog` at once
    /// (the vendor's `initRobot`). A bind failure names the address and lists this host's
    /// IPv4 addresses.
    pub fn open(options: ClientOptions) -> Result<Self, ConnectError> {
        Ok(Self {
            session: Session::open(options, "zsl-high")?,
            acks: Mutex::new([AckCounter::default(); HighLevelCall::ACKNOWLEDGED]),
        })
    }

    /// The vendor's checks on `call` (`zsl_proto::gate`), then latch and acknowledge.
    pub fn call(&self, call: HighLevelCall) -> Result<Latched, CallError> {
        // Without state the vendor reads zeros (mode 0, error 0); so does the gate.
        let state = self.session.read(|s| *s).unwrap_or_default();
        let command = gate(call, &state, &self.session.latched(), self.session.options.model)?;
        self.session.submit(command)?;
        let (target, reported) = (command.control_mode(), state.mode());
        let return_code = match call.ack_slot() {
            Some(slot) => robowire_rt::lock(&self.acks)[slot].on_call(reported, target),
            None => ReturnCode::Queued,
        };
        Ok(Latched { target, reported, return_code })
    }

    /// `standUp()`: mode 1.
    pub fn stand_up(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::StandUp)
    }

    /// `lieDown()`: mode 51 (joints locked).
    pub fn lie_down(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::LieDown)
    }

    /// `passive()`: mode 0 (motors damped). Refused only by a non-zero error word.
    pub fn passive(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::Passive)
    }

    /// `move(vx, vy, yaw_rate)`: walk at `vx_mps` forward, `vy_mps` left, `yaw_rate_radps`.
    /// Each |value| must be 0 (within 1e-6) or in its band: vx 0.05–3.0 m/s (ZSL-1W 3.7),
    /// vy 0.1–1.0 m/s, yaw rate 0.02–3.0 rad/s (ZSL-1W 0.1–3.0). Latched until replaced:
    /// `move_velocity(0.0, 0.0, 0.0)` stops.
    pub fn move_velocity(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<Latched, CallError> {
        self.call(HighLevelCall::Move { vx_mps, vy_mps, yaw_rate_radps })
    }

    /// `jump()`: mode 21, action 5 (sent in 6 datagrams, then cleared).
    pub fn jump(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::Jump)
    }

    /// `frontJump()`: mode 21, action 6.
    pub fn front_jump(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::FrontJump)
    }

    /// `backflip()`: mode 21, action 2.
    pub fn backflip(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::Backflip)
    }

    /// `shakeHand()`: mode 1, action 11.
    pub fn shake_hand(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::ShakeHand)
    }

    /// `twoLegStand(vx, yaw_rate)`: stand on the hind legs (sticky until cancelled) and move at
    /// |vx| 0 or 0.2–0.5 m/s, |yaw rate| 0 or 0.2–1.0 rad/s.
    pub fn two_leg_stand(&self, vx_mps: f32, yaw_rate_radps: f32) -> Result<Latched, CallError> {
        self.call(HighLevelCall::TwoLegStand { vx_mps, yaw_rate_radps })
    }

    /// `cancelTwoLegStand()`: mode 21, action 0, flag 0. No checks, like the vendor's.
    pub fn cancel_two_leg_stand(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::CancelTwoLegStand)
    }

    /// `attitudeControl(roll, pitch, yaw, height)`: body attitude rates, each |v| ≤ 0.6
    /// (rad/s, rad/s, rad/s, m/s; the vendor docs say 0.5).
    pub fn attitude_control(
        &self,
        roll_rate_radps: f32,
        pitch_rate_radps: f32,
        yaw_rate_radps: f32,
        height_rate_mps: f32,
    ) -> Result<Latched, CallError> {
        self.call(HighLevelCall::Attitude {
            roll_radps: roll_rate_radps,
            pitch_radps: pitch_rate_radps,
            yaw_radps: yaw_rate_radps,
            height_mps: height_rate_mps,
        })
    }

    /// ZSL-1W `crawl(vx, vy, yaw_rate)`: mode 18, action 17 (sticky); `move` ranges.
    pub fn crawl(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<Latched, CallError> {
        self.call(HighLevelCall::Crawl { vx_mps, vy_mps, yaw_rate_radps })
    }

    /// ZSL-1W `climb(vx, vy, yaw_rate)`: mode 18, action 16 (sticky); `move` ranges.
    pub fn climb(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<Latched, CallError> {
        self.call(HighLevelCall::Climb { vx_mps, vy_mps, yaw_rate_radps })
    }

    /// ZSL-1W `cancelCrawl()`: mode 18, action 0, flag 0.
    pub fn cancel_crawl(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::CancelCrawlOrClimb)
    }

    /// ZSL-1W `cancelClimb()`: the same datagram as `cancelCrawl()`.
    pub fn cancel_climb(&self) -> Result<Latched, CallError> {
        self.call(HighLevelCall::CancelCrawlOrClimb)
    }

    getters! {
        /// `getQuaternion()`: w, x, y, z.
        quaternion -> [f32; 4] = |s| floats(&s.quaternion);
        /// `getRPY()`: roll, pitch, yaw, rad.
        rpy -> [f32; 3] = |s| floats(&s.rpy);
        /// `getBodyAcc()`: m/s².
        body_acc -> [f32; 3] = |s| floats(&s.acc);
        /// `getBodyGyro()`: rad/s.
        body_gyro -> [f32; 3] = |s| floats(&s.gyro);
        /// `getPosition()`: x, y, z, m.
        position -> [f32; 3] = |s| floats(&s.position);
        /// `getWorldVelocity()`: m/s.
        world_velocity -> [f32; 3] = |s| floats(&s.world_velocity);
        /// `getBodyVelocity()`: m/s.
        body_velocity -> [f32; 3] = |s| floats(&s.body_velocity);
        /// `getLegAbadJoint()`: rad, legs FR, FL, RR, RL.
        leg_abad_joint -> [f32; 4] = |s| floats(&s.joint_angle[0]);
        /// `getLegHipJoint()`: rad.
        leg_hip_joint -> [f32; 4] = |s| floats(&s.joint_angle[1]);
        /// `getLegKneeJoint()`: rad.
        leg_knee_joint -> [f32; 4] = |s| floats(&s.joint_angle[2]);
        /// ZSL-1W `getLegFootJoint()`.
        leg_foot_joint -> [f32; 4] = |s| floats(&s.joint_angle[3]);
        /// `getLegAbadJointVel()`: rad/s.
        leg_abad_joint_vel -> [f32; 4] = |s| floats(&s.joint_velocity[0]);
        /// `getLegHipJointVel()`: rad/s.
        leg_hip_joint_vel -> [f32; 4] = |s| floats(&s.joint_velocity[1]);
        /// `getLegKneeJointVel()`: rad/s.
        leg_knee_joint_vel -> [f32; 4] = |s| floats(&s.joint_velocity[2]);
        /// ZSL-1W `getLegFootJointVel()`.
        leg_foot_joint_vel -> [f32; 4] = |s| floats(&s.joint_velocity[3]);
        /// `getLegAbadJointTorque()`: N·m.
        leg_abad_joint_torque -> [f32; 4] = |s| floats(&s.joint_torque[0]);
        /// `getLegHipJointTorque()`: N·m.
        leg_hip_joint_torque -> [f32; 4] = |s| floats(&s.joint_torque[1]);
        /// `getLegKneeJointTorque()`: N·m.
        leg_knee_joint_torque -> [f32; 4] = |s| floats(&s.joint_torque[2]);
        /// ZSL-1W `getLegFootJointTorque()`.
        leg_foot_joint_torque -> [f32; 4] = |s| floats(&s.joint_torque[3]);
        /// `getCurrentCtrlmode()`.
        control_mode -> ControlMode = |s| s.mode();
        /// `getBatteryPower()`: %.
        battery_percent -> u32 = |s| s.battery_percent.get();
        /// The robot's error word; `Some(None)` when it reports none.
        error -> Option<ReturnCode> = |s| s.error();
        /// The IMU, typed.
        imu -> Imu = |s| s.into();
        /// Body velocity, position, mode, battery and error, typed.
        body -> BodyState = |s| s.into();
        /// Joint angles, velocities and torques, typed.
        joints -> LegJoints = |s| s.into();
    }

    /// Waits until the robot reports `mode`, up to `timeout` (any executor).
    pub async fn wait_for_mode(&self, mode: ControlMode, timeout: Duration) -> Option<RobotState> {
        self.wait_for_state(timeout, move |s| s.body.mode == mode).await
    }

    /// The robot raised "SDK mismatch" and the stream stopped for good.
    pub fn halted(&self) -> bool {
        self.session.halted()
    }
}

client_accessors!(HighLevel, HighLevelInterface, HighLevelState, RobotState, HighLevelCommand);
