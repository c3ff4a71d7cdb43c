//! The HighLevel client: the vendor's calls and getters under Rust names.

use std::sync::Mutex;
use std::time::Duration;

use zsl_proto::rules::{
    ATTITUDE_RANGES, AckCounter, ArgumentError, TWO_LEG_STAND_RANGES, check_all, is_running, mode_gate_passes,
    move_ranges,
};
use zsl_proto::stream::{Connection, HighLevelInterface};
use zsl_proto::udp::{Action, ControlMode, HighLevelCommand, HighLevelState, Model, ReturnCode};
use zsl_proto::zerocopy::little_endian::F32;

use super::session::{ClientStats, Running, Session, client_accessors};
use super::snapshot::{BodyState, Imu, LegJoints, RobotState};
use super::{CallError, ClientOptions, ConnectError};

/// When the "robot is running" check refuses a call (spec §9.1 step 4).
#[derive(Clone, Copy)]
enum WhileRunning {
    Allowed,
    RefusedInMode18Or21,
    Refused,
    RefusedUnlessMode21,
}

/// The calls that keep an acknowledgement counter (spec §9.1 step 7).
#[derive(Clone, Copy)]
enum Call {
    StandUp,
    LieDown,
    Passive,
    Move,
    Jump,
    FrontJump,
    Backflip,
    ShakeHand,
    TwoLegStand,
    Attitude,
    Crawl,
    Climb,
}

impl Call {
    const COUNT: usize = 12;

    fn checks(self) -> (bool, WhileRunning) {
        use WhileRunning::*;
        match self {
            Self::StandUp | Self::LieDown => (false, RefusedInMode18Or21),
            Self::Passive => (false, Allowed),
            Self::ShakeHand => (false, Refused),
            Self::Jump | Self::FrontJump | Self::Backflip => (true, Refused),
            Self::TwoLegStand | Self::Attitude => (true, RefusedUnlessMode21),
            Self::Move | Self::Crawl | Self::Climb => (true, Allowed),
        }
    }
}

/// The ZSL-1 HighLevel client (the vendor's `HighLevel`). Needs a tokio runtime with the time
/// and I/O drivers for the receive task; the stream runs on its own thread. Both stop on drop.
///
/// Every motion call validates first (the vendor's checks in the vendor's order, plus NaN and
/// infinities), then latches the command, which the stream thread sends at once. `Ok(())` is
/// the vendor's 0, "queued": whether the robot obeys shows in [`control_mode`](Self::control_mode).
///
/// ```no_run
/// # async fn demo() -> Result<(), Box<dyn std::error::Error>> {
/// use zsl::udp::{ClientOptions, HighLevel};
/// let dog = HighLevel::connect(ClientOptions::default()).await?; // 0.0.0.0:43988 → 192.168.234.1
/// dog.wait_connected(std::time::Duration::from_secs(3)).await;
/// dog.stand_up().await?;
/// dog.move_velocity(0.5, 0.0, 0.0).await?;
/// # Ok(()) }
/// ```
pub struct HighLevel {
    running: Running<HighLevelInterface>,
    acks: Mutex<[AckCounter; Call::COUNT]>,
}

impl std::fmt::Debug for HighLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HighLevel")
            .field("local", &self.session().local_addr())
            .field("dog", &self.session().options.dog)
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
            self.session().read(|$s| $e)
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
    pub async fn connect(options: ClientOptions) -> Result<Self, ConnectError> {
        Ok(Self { running: Running::start(options).await?, acks: Mutex::new([AckCounter::default(); Call::COUNT]) })
    }

    /// Stops streaming and closes the socket: when this returns, the local port can be bound
    /// again. (Dropping the client stops it too, but its socket closes a moment later, on the
    /// runtime's thread.)
    pub async fn close(self) {
        self.running.shut_down().await;
    }

    fn session(&self) -> &Session<HighLevelInterface> {
        &self.running.session
    }

    /// The vendor's checks (spec §9.1, in its order), then latch, send, acknowledge.
    async fn call(
        &self,
        call: Call,
        command: impl FnOnce(Model) -> Result<HighLevelCommand, ArgumentError>,
    ) -> Result<(), CallError> {
        // Without state the vendor reads zeros (mode 0, error 0); so does robowire's rule check.
        let state = self.session().read(|s| *s).unwrap_or_default();
        if let Some(error) = state.error() {
            return Err(CallError::SelfCheck(error));
        }
        let mode = state.mode();
        let (gated, while_running) = call.checks();
        if gated && !mode_gate_passes(mode) {
            return Err(CallError::LyingDown(mode));
        }
        if matches!(call, Call::Move) && self.session().latched().action_code() == Action::TwoLegStand {
            return Err(CallError::TwoLegStandActive);
        }
        let running = is_running(state.body_velocity[0].get(), state.body_velocity[1].get(), state.gyro[2].get());
        let refused = match while_running {
            WhileRunning::Allowed => false,
            WhileRunning::RefusedInMode18Or21 => matches!(mode, ControlMode::Move | ControlMode::Action),
            WhileRunning::Refused => true,
            WhileRunning::RefusedUnlessMode21 => mode != ControlMode::Action,
        };
        if running && refused {
            return Err(CallError::Running(mode));
        }
        if matches!(call, Call::Attitude) && state.rpy[0].get().abs() > 1.0 {
            return Err(CallError::Unbalanced(state.rpy[0].get()));
        }
        let command = command(self.session().options.model)?;
        self.session().submit(command)?;
        let target = command.control_mode();
        let acknowledged = self.acks.lock().map(|mut acks| acks[call as usize].on_call(mode, target));
        match acknowledged {
            Ok(ReturnCode::SwitchFailed) => Err(CallError::NotAcknowledged { target, reported: mode }),
            _ => Ok(()),
        }
    }

    fn require(&self, call: &'static str, needs: Model) -> Result<(), CallError> {
        let model = self.session().options.model;
        if model == needs { Ok(()) } else { Err(CallError::WrongModel { call, needs, model }) }
    }

    /// `standUp()`: mode 1.
    pub async fn stand_up(&self) -> Result<(), CallError> {
        self.call(Call::StandUp, |_| Ok(HighLevelCommand::stand_up())).await
    }

    /// `lieDown()`: mode 51 (joints locked).
    pub async fn lie_down(&self) -> Result<(), CallError> {
        self.call(Call::LieDown, |_| Ok(HighLevelCommand::lie_down())).await
    }

    /// `passive()`: mode 0 (motors damped). Refused only by a non-zero error word.
    pub async fn passive(&self) -> Result<(), CallError> {
        self.call(Call::Passive, |_| Ok(HighLevelCommand::passive())).await
    }

    /// `move(vx, vy, yaw_rate)`: walk at `vx_mps` forward, `vy_mps` left, `yaw_rate_radps`.
    /// Each |value| must be 0 (within 1e-6) or in its band: vx 0.05–3.0 m/s (ZSL-1W 3.7),
    /// vy 0.1–1.0 m/s, yaw rate 0.02–3.0 rad/s (ZSL-1W 0.1–3.0). Latched until replaced:
    /// `move_velocity(0.0, 0.0, 0.0)` stops.
    pub async fn move_velocity(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<(), CallError> {
        self.walk(Call::Move, HighLevelCommand::move_velocity, [vx_mps, vy_mps, yaw_rate_radps]).await
    }

    /// `move`, `crawl`, `climb`: the `move` ranges of the model, then the call's datagram.
    async fn walk(
        &self,
        call: Call,
        build: fn(f32, f32, f32) -> HighLevelCommand,
        args: [f32; 3],
    ) -> Result<(), CallError> {
        self.call(call, |model| {
            let [vx, vy, wz] = check_all(&move_ranges(model), args)?;
            Ok(build(vx, vy, wz))
        })
        .await
    }

    /// `jump()`: mode 21, action 5 (sent in 6 datagrams, then cleared).
    pub async fn jump(&self) -> Result<(), CallError> {
        self.call(Call::Jump, |_| Ok(HighLevelCommand::jump())).await
    }

    /// `frontJump()`: mode 21, action 6.
    pub async fn front_jump(&self) -> Result<(), CallError> {
        self.call(Call::FrontJump, |_| Ok(HighLevelCommand::front_jump())).await
    }

    /// `backflip()`: mode 21, action 2.
    pub async fn backflip(&self) -> Result<(), CallError> {
        self.call(Call::Backflip, |_| Ok(HighLevelCommand::backflip())).await
    }

    /// `shakeHand()`: mode 1, action 11.
    pub async fn shake_hand(&self) -> Result<(), CallError> {
        self.call(Call::ShakeHand, |_| Ok(HighLevelCommand::shake_hand())).await
    }

    /// `twoLegStand(vx, yaw_rate)`: stand on the hind legs (sticky until cancelled) and move at
    /// |vx| 0 or 0.2–0.5 m/s, |yaw rate| 0 or 0.2–1.0 rad/s.
    pub async fn two_leg_stand(&self, vx_mps: f32, yaw_rate_radps: f32) -> Result<(), CallError> {
        self.call(Call::TwoLegStand, |_| {
            let [vx, wz] = check_all(&TWO_LEG_STAND_RANGES, [vx_mps, yaw_rate_radps])?;
            Ok(HighLevelCommand::two_leg_stand(vx, wz))
        })
        .await
    }

    /// `cancelTwoLegStand()`: mode 21, action 0, flag 0. No checks, like the vendor's.
    pub async fn cancel_two_leg_stand(&self) -> Result<(), CallError> {
        self.session().submit(HighLevelCommand::cancel_two_leg_stand())
    }

    /// `attitudeControl(roll, pitch, yaw, height)`: body attitude rates, each |v| ≤ 0.6
    /// (rad/s, rad/s, rad/s, m/s; the vendor docs say 0.5).
    pub async fn attitude_control(
        &self,
        roll_rate_radps: f32,
        pitch_rate_radps: f32,
        yaw_rate_radps: f32,
        height_rate_mps: f32,
    ) -> Result<(), CallError> {
        self.call(Call::Attitude, |_| {
            let [r, p, y, h] =
                check_all(&ATTITUDE_RANGES, [roll_rate_radps, pitch_rate_radps, yaw_rate_radps, height_rate_mps])?;
            Ok(HighLevelCommand::attitude(r, p, y, h))
        })
        .await
    }

    /// ZSL-1W `crawl(vx, vy, yaw_rate)`: mode 18, action 17 (sticky); `move` ranges.
    pub async fn crawl(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<(), CallError> {
        self.require("crawl", Model::Zsl1W)?;
        self.walk(Call::Crawl, HighLevelCommand::crawl, [vx_mps, vy_mps, yaw_rate_radps]).await
    }

    /// ZSL-1W `climb(vx, vy, yaw_rate)`: mode 18, action 16 (sticky); `move` ranges.
    pub async fn climb(&self, vx_mps: f32, vy_mps: f32, yaw_rate_radps: f32) -> Result<(), CallError> {
        self.require("climb", Model::Zsl1W)?;
        self.walk(Call::Climb, HighLevelCommand::climb, [vx_mps, vy_mps, yaw_rate_radps]).await
    }

    /// ZSL-1W `cancelCrawl()`: mode 18, action 0, flag 0.
    pub async fn cancel_crawl(&self) -> Result<(), CallError> {
        self.require("cancel_crawl", Model::Zsl1W)?;
        self.session().submit(HighLevelCommand::cancel_crawl_or_climb())
    }

    /// ZSL-1W `cancelClimb()`: the same datagram as `cancelCrawl()`.
    pub async fn cancel_climb(&self) -> Result<(), CallError> {
        self.require("cancel_climb", Model::Zsl1W)?;
        self.session().submit(HighLevelCommand::cancel_crawl_or_climb())
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

    client_accessors!(HighLevelState, RobotState, HighLevelCommand);

    /// Waits until the robot reports `mode`, up to `timeout`.
    pub async fn wait_for_mode(&self, mode: ControlMode, timeout: Duration) -> Option<RobotState> {
        self.wait_for_state(timeout, |s| s.body.mode == mode).await
    }

    /// The robot raised "SDK mismatch" and the stream stopped for good.
    pub fn halted(&self) -> bool {
        self.session().halted()
    }
}
