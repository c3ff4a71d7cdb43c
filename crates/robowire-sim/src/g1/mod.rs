//! A Unitree G1 humanoid on DDS (the HG messages) that Unitree's own software can drive.
//!
//! What is modelled, as the robot does it (see `unitree_proto::g1` for the sources):
//!
//! - It boots standing under its own controller: `motion_switcher` CheckMode names the mode
//!   [`BOOT_MODE`], the loco FSM is 500 (the walking controller), the joints are held at
//!   [`STAND_POSE_RAD`]. While a mode owns the motors, `rt/lowcmd` LowCmds are ignored and
//!   counted (said once in the log). After ReleaseMode the motors are passive until LowCmds
//!   drive them; SelectMode gives the motors back to the controller.
//! - `rt/lowcmd` (HG `LowCmd_`) once released: dropped on a bad CRC (the reader counts it) or a
//!   `mode_machine` that is not the robot's (counted, never applied); per motor applied only
//!   with `mode` 1 (a `mode` 0 motor exerts no torque: a frame with one that carries a target,
//!   gain or torque is counted in `disabled_motors`, its `mode` 1 motors still applied). Slots
//!   the variant does not drive move nothing. `mode_pr` PR and AB both drive the ankles and
//!   the waist's roll and pitch (AB mapped by `unitree_proto::g1::joint_targets`); the state
//!   echoes the last applied LowCmd's `mode_pr` and reports the parallel pairs in it. A LowCmd
//!   older than [`COMMAND_HOLD_S`] leaves the motors passive.
//! - `rt/arm_sdk` (HG `LowCmd_`) while the controller owns the motors: the arm and waist joints
//!   (`ARM_SDK_JOINTS`) follow `(1 − w)·controller + w·arm_sdk` (targets and gains), `w` slot
//!   29's `q` clamped to 0..=1; `mode` and `mode_machine` ignored (Unitree's arm examples leave
//!   them 0). After ReleaseMode it is ignored and counted.
//! - `rt/lowstate` (HG `LowState_`) at 500 Hz on robowire's runner, CRC by the encoder:
//!   `mode_pr`, `mode_machine`, `tick` (ms), the IMU at rest (identity quaternion, gravity on
//!   z), each driven joint's mode, q, dq, torque, temperatures and voltage.
//! - `rt/lf/bmsstate` (HG `BmsState_`) once a second: a 13-cell pack draining slowly
//!   ([`battery`]).
//! - Services on `rt/api/<service>/…`: `motion_switcher`, `sport` (the G1 loco API, Unitree's
//!   `LocoClient`) and `arm` (the arm actions). After ReleaseMode the loco service answers
//!   `LOCO_STATE_UNAVAILABLE` and arm actions `INVALID_FSM_ID` until SelectMode. Arm actions
//!   run in FSM 500, 501 and 801 only (`INVALID_FSM_ID`), not while `rt/arm_sdk` is blended in
//!   with a weight above 0 (`ARM_SDK_OCCUPIED`), and not while the arms hold an action's pose
//!   (`HOLDING`, until the release action 99 or the held action again).
//!
//! robowire's choices where the robot's behaviour is not public: the controller's gains
//! ([`CONTROLLER_GAINS`], unitree_rl_gym's); `rt/arm_sdk` frames are taken without a CRC check
//! (Unitree's Python example seals them, its C++ one does not; a wrong CRC is counted as
//! `unsealed`); a silent `rt/arm_sdk` (no frame for [`COMMAND_HOLD_S`]) keeps its last targets
//! while its weight decays to 0 at `ARM_SDK_WEIGHT_RATE_PER_S` (0.5/s): the controller takes
//! the arms back, never at a jump; which actions end holding their pose ([`HOLDING_ACTIONS`]);
//! the AB mapping is robowire's linearised model of the linkage (gains and torques of a pair
//! act on its pitch and roll joints slot by slot); the motors' voltage is a constant
//! [`SUPPLY_V`]; a failed motor reports `mode` 0 and `motorstate` 1; the state's `version` is
//! 0. Faults: silence, a motor fault, bit flips on the wire, a mode that withstands ReleaseMode
//! ([`G1Fault::ModeHeld`]).
//!
//! Everything runs on `robowire-dds` (the transport), never on a facade. Create it inside a
//! network namespace whose loopback has multicast when testing on one machine
//! (`robowire_dds::netns`).

pub mod battery;
mod model;
mod services;

use std::sync::atomic::{AtomicBool, AtomicI64, Ordering};
use std::time::Duration;

use robowire_core::cdr::CdrType;
use robowire_core::schedule::Time;
use robowire_core::timing::LatenessSummary;
use robowire_dds::{ParticipantOptions, StatsHandle};
use robowire_rt::stats::Counter;
use robowire_tap::Tap;
use unitree_proto::api::{g1_arm, g1_loco, motion_switcher};
use unitree_proto::g1::{ARM_SDK_TOPIC, G1Variant};
use unitree_proto::{CdrEncoding, DecodeError, HgLowCmd, HgLowState, Message};

pub use crate::unitree::{
    AdvanceError, BasePose, COMMAND_HOLD_S, Fault as G1Fault, GaitRequest, MAX_SPEED, Onboard, SimClock,
    SimError as G1SimError, StreamCounters,
};
pub use model::{CONTROLLER_GAINS, G1Body, JOINTS, LET_GO_AFTER_S, STAND_POSE_RAD, SUPPLY_V, has_disabled_motor};
pub use services::HOLDING_ACTIONS;

use crate::unitree::{CommandInbox, FlipSite, GaitAsk, Port, Report, Sim, StreamBody, StreamOptions};

/// The `motion_switcher` mode that owns the motors at boot.
pub const BOOT_MODE: &str = "ai";

/// The loco FSM at boot: the walking controller.
pub const BOOT_FSM_ID: i64 = g1_loco::fsm::START;

/// Simulator settings.
#[derive(Debug, Clone, PartialEq)]
pub struct G1SimConfig {
    /// Domain and interface (default: domain 0, the library's choice of interface).
    pub participant: ParticipantOptions,
    /// Which G1 (default the 29-dof one).
    pub variant: G1Variant,
    /// The `mode_machine` its LowState says and its LowCmds must carry (default, and with
    /// [`G1SimConfig::new`], the variant's: 5 for the 29-dof G1, 4 for the 23-dof one).
    pub mode_machine: u8,
    /// `rt/lowstate` period. Default 2 ms (500 Hz).
    pub state_period: Duration,
    /// Pin the simulator's state stream to this CPU.
    pub cpu: Option<usize>,
    /// Where each `rt/lowstate` written (the corrupted ones of a fault too) and `rt/lowcmd` and
    /// `rt/arm_sdk` frame taken goes, as its payload: a link described by
    /// `unitree_proto::description::HG_LOW_LEVEL`.
    pub low_level_tap: Option<Tap>,
    /// Where each service request taken and answer written goes
    /// (`unitree_proto::description::API_SERVER`).
    pub services_tap: Option<Tap>,
    /// Answer every applied LowCmd with a LowState at once, its `reserve` the command's, besides
    /// the 500 Hz stream (for round-trip measurements; a real G1 only streams).
    pub answer_lowcmd: bool,
    /// Real time (default, at speed 1) or lock-step.
    pub clock: SimClock,
    /// The robot's own locomotion is an onboard controller's ([`G1Sim::onboard`]): while a mode
    /// owns the motors in a standing or walking loco FSM (4, 500, 501, 702, 706, 801), its
    /// commands take the place of the controller's stand pose, and `SetVelocity` asks it a
    /// velocity. Off (default): the controller holds [`STAND_POSE_RAD`].
    pub onboard_gait: bool,
    /// MuJoCo physics instead of the kinematic joint model (`hanging`: the pelvis held, as on
    /// Unitree's elastic band; the robot's balance controller is not modelled, so a free G1
    /// stands only as long as its joints' PD holds it up).
    #[cfg(feature = "mujoco")]
    pub physics: Option<crate::physics::PhysicsOptions>,
}

impl G1SimConfig {
    /// A G1 of `variant` with its `mode_machine`, otherwise the defaults.
    pub fn new(variant: G1Variant) -> Self {
        Self {
            participant: ParticipantOptions::default(),
            variant,
            mode_machine: variant.mode_machine(),
            state_period: Duration::from_millis(2),
            cpu: None,
            low_level_tap: None,
            services_tap: None,
            answer_lowcmd: false,
            clock: SimClock::default(),
            onboard_gait: false,
            #[cfg(feature = "mujoco")]
            physics: None,
        }
    }
}

impl Default for G1SimConfig {
    fn default() -> Self {
        Self::new(G1Variant::Dof29)
    }
}

/// What happened to the `rt/lowcmd` LowCmds that arrived.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct G1LowCmdCounters {
    /// Accepted: the motors with `mode` 1 follow them.
    pub accepted: u64,
    /// Ignored because a mode owned the motors.
    pub ignored_mode: u64,
    /// Dropped for a `mode_machine` that is not the robot's.
    pub bad_mode_machine: u64,
    /// Dropped for a `mode_pr` that is neither 0 (PR) nor 1 (AB).
    pub bad_mode_pr: u64,
    /// Accepted with a driven motor at `mode` 0 that carries a target, gain or torque (that
    /// motor exerts no torque).
    pub disabled_motors: u64,
    /// Dropped for a CRC mismatch (the reader's count).
    pub bad_crc: u64,
    /// Dropped because the body did not decode.
    pub malformed: u64,
}

/// What happened to the `rt/arm_sdk` frames that arrived.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ArmSdkCounters {
    /// Taken: blended into the controller's arm and waist targets.
    pub accepted: u64,
    /// Ignored because no mode owned the motors (after ReleaseMode).
    pub ignored_released: u64,
    /// Taken with a CRC that does not match (the robot's controller does not check it here).
    pub unsealed: u64,
    /// Dropped because the body did not decode.
    pub malformed: u64,
    /// The weight it is blended in with now, 0..=1.
    pub weight: f32,
}

/// The simulator now.
#[derive(Debug, Clone, PartialEq)]
pub struct G1Snapshot {
    /// The `motion_switcher` mode owning the motors; empty once released.
    pub mode: String,
    /// The loco FSM id.
    pub fsm_id: i64,
    /// The velocity the loco service was last asked (`SetVelocity`: vx m/s, vy m/s, yaw rate
    /// rad/s), zero once its duration ran out.
    pub loco_velocity: [f32; 3],
    /// Joint positions by slot, rad (pitch and roll for the parallel joints; 0 on the slots
    /// the variant does not drive).
    pub joints_rad: [f32; JOINTS],
    /// `rt/lowcmd` in.
    pub lowcmd: G1LowCmdCounters,
    /// `rt/arm_sdk` in.
    pub arm_sdk: ArmSdkCounters,
    /// `rt/lowstate` out (its writer, bit flips, lateness) and the service requests answered.
    pub stream: StreamCounters,
    /// |interval − 2 ms| between accepted LowCmds as they arrive, µs.
    pub command_jitter: LatenessSummary,
    /// Where the pelvis is (physics only).
    pub base: Option<BasePose>,
}

/// What the G1's services thread hands its state stream, and counts.
#[derive(Debug)]
struct G1Inbox {
    lowcmd: CommandInbox<HgLowCmd>,
    arm_sdk: CommandInbox<HgLowCmd>,
    /// Whether the robot's controller owns the motors (a mode is selected).
    controller: AtomicBool,
    /// The loco FSM id (the services thread's, for the snapshot).
    fsm_id: AtomicI64,
    /// The onboard controller's commands.
    gait: CommandInbox<HgLowCmd>,
    /// What the loco service asks of the onboard controller.
    ask: GaitAsk,
    bad_mode_machine: Counter,
    bad_mode_pr: Counter,
    disabled_motors: Counter,
    arm_sdk_unsealed: Counter,
}

/// Slots published to the handle: the joints, then the `rt/arm_sdk` weight.
const PUBLISHED: usize = JOINTS + 1;

/// The body as the state stream drives it.
struct G1Robot {
    body: G1Body,
    seen_lowcmd: Option<Time>,
    seen_arm_sdk: Option<Time>,
    seen_gait: Option<Time>,
}

impl StreamBody for G1Robot {
    type State = HgLowState;
    type Inbox = G1Inbox;
    type Published = [f32; PUBLISHED];
    // `q` of the 29 joints: XCDR1 body offset 72 (motor_state) + 4 + 56·i.
    const FLIP: FlipSite = FlipSite { first_q: 76, stride: 56, motors: JOINTS };

    fn take(&mut self, inbox: &G1Inbox) {
        let controller = inbox.controller.load(Ordering::Acquire);
        if controller != self.body.controller_owns() {
            self.body.set_controller(controller);
        }
        if let Some(command) = inbox.lowcmd.newer(&mut self.seen_lowcmd) {
            self.body.command(&command);
        }
        if let Some(command) = inbox.arm_sdk.newer(&mut self.seen_arm_sdk) {
            self.body.arm_sdk(&command);
        }
        if let Some(command) = inbox.gait.newer(&mut self.seen_gait) {
            self.body.gait(&command);
        }
    }
    fn published(&self) -> [f32; PUBLISHED] {
        let q = self.body.joint_positions();
        core::array::from_fn(|i| if i < JOINTS { q[i] } else { self.body.arm_sdk_weight() })
    }
    crate::unitree::forward_to_body!();
}

/// An `rt/arm_sdk` frame as the robot takes it: decoded without the CRC check, whether its CRC
/// was right kept.
#[derive(Debug, Clone, Copy)]
struct ArmSdkFrame {
    command: HgLowCmd,
    sealed: bool,
}

impl CdrType for ArmSdkFrame {
    const TYPE_NAME: &'static str = HgLowCmd::DDS_TYPE_NAME;
    type Error = DecodeError<()>;
    fn body_len(&self) -> usize {
        self.command.body_len()
    }
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
        self.command.encode_body(out)
    }
    fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, Self::Error> {
        let (frame, _) = HgLowCmd::decode_cdr_body_unverified(encoding, body).map_err(DecodeError::without_message)?;
        Ok(Self { command: frame.message, sealed: frame.crc.is_ok() })
    }
}

/// A running simulated G1; stopped on drop.
#[derive(Debug)]
pub struct G1Sim {
    sim: Sim<G1Robot>,
    lowcmd: StatsHandle,
    arm_sdk: StatsHandle,
    onboard_gait: bool,
}

impl Port<HgLowState, HgLowCmd> for crate::unitree::Handover<G1Robot> {
    fn state(&self) -> Option<(Time, HgLowState)> {
        self.state.read()
    }
    fn base(&self) -> Option<BasePose> {
        self.base.read().map(|(_, pose)| pose)
    }
    fn drive(&self, command: &HgLowCmd, now: Time) {
        self.inbox.gait.accept(command, now);
    }
    fn ask(&self) -> &GaitAsk {
        &self.inbox.ask
    }
}

impl G1Sim {
    /// Joins the domain, starts the services, the `rt/lowcmd` and `rt/arm_sdk` readers and the
    /// 500 Hz state stream.
    pub fn spawn(config: G1SimConfig) -> Result<Self, G1SimError> {
        #[cfg(feature = "mujoco")]
        let body = match &config.physics {
            Some(physics) => G1Body::physics(config.variant, config.mode_machine, physics)?,
            None => G1Body::new(config.variant, config.mode_machine),
        };
        #[cfg(not(feature = "mujoco"))]
        let body = G1Body::new(config.variant, config.mode_machine);
        let participant = crate::unitree::join(&config.participant)?;
        let tap = &config.low_level_tap;
        let (lowcmd, lowcmd_stats) = crate::unitree::command_reader::<HgLowCmd>(&participant, HgLowCmd::TOPIC, tap)?;
        let (arm_sdk, arm_sdk_stats) = crate::unitree::command_reader::<ArmSdkFrame>(&participant, ARM_SDK_TOPIC, tap)?;
        let services_tap = config.services_tap.clone();
        let server = |service| crate::unitree::service_server(&participant, service, services_tap.clone());
        let answers = config
            .answer_lowcmd
            .then(|| {
                let mut answers =
                    participant.writer::<HgLowState>(HgLowState::TOPIC, robowire_dds::qos::Qos::WRITER)?;
                answers.set_tap(tap.clone());
                Ok::<_, robowire_dds::DdsError>(answers)
            })
            .transpose()?;
        let endpoints = services::Endpoints {
            lowcmd,
            arm_sdk,
            answers,
            switcher: server(motion_switcher::SERVICE)?,
            loco: server(g1_loco::SERVICE)?,
            arm: server(g1_arm::SERVICE)?,
            battery: participant.writer(unitree_proto::bms::BMS_TOPIC, robowire_dds::qos::Qos::STREAM_WRITER)?,
        };
        let inbox = G1Inbox {
            lowcmd: CommandInbox::new(config.state_period),
            arm_sdk: CommandInbox::new(unitree_proto::g1::ARM_SDK_PERIOD),
            controller: AtomicBool::new(true),
            fsm_id: AtomicI64::new(BOOT_FSM_ID),
            gait: CommandInbox::new(config.state_period),
            ask: GaitAsk::default(),
            bad_mode_machine: Counter::default(),
            bad_mode_pr: Counter::default(),
            disabled_motors: Counter::default(),
            arm_sdk_unsealed: Counter::default(),
        };
        let report = Report::booted(
            BOOT_MODE,
            format!(
                "booted standing ({:?}, mode_machine {}); sport mode \"{BOOT_MODE}\" owns the motors, loco FSM {BOOT_FSM_ID}",
                config.variant, config.mode_machine
            ),
        );
        let options = StreamOptions {
            period: config.state_period,
            cpu: config.cpu,
            tap: config.low_level_tap,
            name: "g1-sim",
            clock: config.clock,
        };
        let robot = G1Robot { body, seen_lowcmd: None, seen_arm_sdk: None, seen_gait: None };
        let robot_rules = services::Rules {
            variant: config.variant,
            mode_machine: config.mode_machine,
            onboard_gait: config.onboard_gait,
        };
        let sim = Sim::spawn(participant, options, robot, inbox, report, |handover, report| {
            move || services::run(handover, report, endpoints, robot_rules)
        })?;
        Ok(Self { sim, lowcmd: lowcmd_stats, arm_sdk: arm_sdk_stats, onboard_gait: config.onboard_gait })
    }

    /// The port of the robot's own locomotion, when it was asked for
    /// ([`G1SimConfig::onboard_gait`]).
    pub fn onboard(&self) -> Option<Onboard<HgLowState, HgLowCmd>> {
        self.onboard_gait.then(|| Onboard::new(self.sim.handover.clone()))
    }

    crate::unitree::handle_methods!(G1Fault);

    /// The simulator now.
    pub fn snapshot(&self) -> G1Snapshot {
        let (lowcmd, arm_sdk) = (self.lowcmd.get(), self.arm_sdk.get());
        let inbox = &self.sim.handover.inbox;
        let published = self.sim.published().unwrap_or([0.0; PUBLISHED]);
        G1Snapshot {
            mode: self.sim.mode(),
            fsm_id: inbox.fsm_id.load(Ordering::Relaxed),
            loco_velocity: inbox.ask.request(robowire_rt::now()).velocity,
            joints_rad: core::array::from_fn(|j| published[j]),
            lowcmd: G1LowCmdCounters {
                accepted: inbox.lowcmd.accepted.get(),
                ignored_mode: inbox.lowcmd.ignored.get(),
                bad_mode_machine: inbox.bad_mode_machine.get(),
                bad_mode_pr: inbox.bad_mode_pr.get(),
                disabled_motors: inbox.disabled_motors.get(),
                bad_crc: lowcmd.checksum_errors,
                malformed: lowcmd.decode_errors,
            },
            arm_sdk: ArmSdkCounters {
                accepted: inbox.arm_sdk.accepted.get(),
                ignored_released: inbox.arm_sdk.ignored.get(),
                unsealed: inbox.arm_sdk_unsealed.get(),
                malformed: arm_sdk.decode_errors,
                weight: published[JOINTS],
            },
            stream: self.sim.counters(),
            command_jitter: inbox.lowcmd.jitter(),
            base: self.sim.base(),
        }
    }
}
