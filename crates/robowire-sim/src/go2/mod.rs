//! A Unitree Go2 on DDS that Unitree's own software can drive (spec `unitree-dds.md`).
//!
//! It boots like the robot: the sport mode `normal` owns the motors, and a `LowCmd` that arrives
//! before `motion_switcher` ReleaseMode is ignored and counted (and said once in the log). The
//! `motion_switcher` and `sport` services answer on `rt/api/*`; `rt/lowstate` goes out at
//! 500 Hz on robowire's runner with a correct CRC; LowCmds with a bad CRC or a wrong head are
//! dropped and counted; the 12 joints follow accepted LowCmds through the shared PD joint model
//! ([`Go2Body`]), starting lying down. Faults: silence, a motor fault, bit flips on the wire,
//! a mode that withstands ReleaseMode ([`Go2Fault::ModeHeld`]).
//! Unlike a real Go2, its LowState's `reserve` echoes the last accepted LowCmd's `reserve`, and
//! it can answer each LowCmd at once ([`Go2SimConfig::answer_lowcmd`]): for round trips.
//!
//! Everything runs on `robowire-dds` (the transport), never on a facade. Create it inside a
//! network namespace whose loopback has multicast when testing on one machine
//! (`robowire_dds::netns`).

mod model;
mod services;

use std::time::Duration;

use robowire_core::schedule::Time;
use robowire_core::timing::LatenessSummary;
use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, ParticipantOptions, StatsHandle, TopicStats};
use robowire_rt::stats::Counter;
use robowire_tap::Tap;
use unitree_proto::api::{motion_switcher, sport};
use unitree_proto::{LowCmd, LowState, Message, go2};

pub use crate::unitree::{
    AdvanceError, BasePose, COMMAND_HOLD_S, Fault as Go2Fault, GaitRequest, MAX_SPEED, Onboard, SimClock,
    SimError as Go2SimError,
};
pub use model::{Go2Body, JOINTS, LYING_POSE_RAD, STAND_POSE_RAD};
pub use services::MOVE_HOLDS;

use crate::unitree::{CommandInbox, FlipSite, GaitAsk, Port, Report, Sim, StreamBody, StreamOptions};

/// The sport mode that owns the motors at boot.
pub const BOOT_SPORT_MODE: &str = "normal";

/// Simulator settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Go2SimConfig {
    /// Domain and interface (default: domain 0, the library's choice of interface).
    pub participant: ParticipantOptions,
    /// `rt/lowstate` period. Default 2 ms (500 Hz).
    pub state_period: Duration,
    /// Pin the simulator's state stream to this CPU.
    pub cpu: Option<usize>,
    /// Answer every accepted LowCmd with a LowState at once, besides the 500 Hz stream (for
    /// round-trip measurements; a real Go2 only streams).
    pub answer_lowcmd: bool,
    /// Where each `rt/lowstate` written (the corrupted ones of a fault too) and `rt/lowcmd`
    /// taken goes, as its payload: a link described by `unitree_proto::description::GO2_LOW_LEVEL`.
    pub low_level_tap: Option<Tap>,
    /// Where each service request taken and answer written goes
    /// (`unitree_proto::description::API_SERVER`).
    pub services_tap: Option<Tap>,
    /// Real time (default, at speed 1) or lock-step.
    pub clock: SimClock,
    /// The robot's own locomotion is an onboard controller's ([`Go2Sim::onboard`]): `sport`
    /// StandUp, BalanceStand, RecoveryStand and Move switch it on while the sport mode owns the
    /// motors (Move asks a velocity for [`MOVE_HOLDS`]), StopMove asks zero, Damp and StandDown
    /// switch it off; its commands drive the motors as a LowCmd does. Off (default): the sport
    /// mode leaves the motors passive and Move is not implemented.
    pub onboard_gait: bool,
    /// MuJoCo physics instead of the kinematic joint model: the Go2 lying on its floor.
    #[cfg(feature = "mujoco")]
    pub physics: Option<crate::physics::PhysicsOptions>,
}

impl Default for Go2SimConfig {
    fn default() -> Self {
        Self {
            participant: ParticipantOptions::default(),
            state_period: Duration::from_millis(2),
            cpu: None,
            answer_lowcmd: false,
            low_level_tap: None,
            services_tap: None,
            clock: SimClock::default(),
            onboard_gait: false,
            #[cfg(feature = "mujoco")]
            physics: None,
        }
    }
}

/// What happened to the LowCmds that arrived.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LowCmdCounters {
    /// Accepted: the motors follow them.
    pub accepted: u64,
    /// Ignored because a sport mode owned the motors.
    pub ignored_sport_mode: u64,
    /// Dropped for a wrong `head` or `level_flag`.
    pub bad_head: u64,
    /// Dropped for a CRC mismatch (the reader's count).
    pub bad_crc: u64,
    /// Dropped because the body did not decode.
    pub malformed: u64,
}

/// The simulator now.
#[derive(Debug, Clone, PartialEq)]
pub struct Go2Snapshot {
    /// The sport mode owning the motors; empty once released.
    pub sport_mode: String,
    /// Joint positions, rad, motor order.
    pub joints_rad: [f32; JOINTS],
    /// LowCmds in.
    pub lowcmd: LowCmdCounters,
    /// The `rt/lowstate` writer's counters.
    pub lowstate: TopicStats,
    /// LowStates sent with a flipped bit.
    pub corrupted_states: u64,
    /// Service requests answered.
    pub requests: u64,
    /// Lateness of the state stream against its absolute deadlines, µs.
    pub state_lateness: LatenessSummary,
    /// |interval − 2 ms| between accepted LowCmds as they arrive, µs.
    pub command_jitter: LatenessSummary,
    /// Where the base is (physics only).
    pub base: Option<BasePose>,
    /// Simulated time so far, s.
    pub sim_time_s: f64,
    /// Wall time since the simulator started, s.
    pub wall_time_s: f64,
}

/// What the Go2's services thread hands its state stream: the latest accepted LowCmd.
#[derive(Debug)]
struct Go2Inbox {
    lowcmd: CommandInbox<LowCmd>,
    bad_head: Counter,
    /// The onboard controller's commands.
    gait: CommandInbox<LowCmd>,
    /// What the sport service asks of the onboard controller.
    ask: GaitAsk,
}

/// The body as the state stream drives it.
struct Go2Robot {
    body: Go2Body,
    /// The stamp of the LowCmd the body follows.
    seen_command: Option<Time>,
    seen_gait: Option<Time>,
}

impl StreamBody for Go2Robot {
    type State = LowState;
    type Inbox = Go2Inbox;
    type Published = [f32; JOINTS];
    // `q` of the 12 joints: XCDR1 body offset 80 + 48·i (spec §6.3).
    const FLIP: FlipSite = FlipSite { first_q: 80, stride: 48, motors: JOINTS };

    fn take(&mut self, inbox: &Go2Inbox) {
        if let Some(command) = inbox.lowcmd.newer(&mut self.seen_command) {
            self.body.command(&command);
        }
        if let Some(command) = inbox.gait.newer(&mut self.seen_gait)
            && inbox.ask.request(robowire_rt::now()).on
        {
            self.body.command(&command);
        }
    }
    fn published(&self) -> [f32; JOINTS] {
        self.body.joint_positions()
    }
    crate::unitree::forward_to_body!();
}

/// A running simulated Go2; stopped on drop.
#[derive(Debug)]
pub struct Go2Sim {
    sim: Sim<Go2Robot>,
    lowcmd: StatsHandle,
    onboard_gait: bool,
}

impl Port<LowState, LowCmd> for crate::unitree::Handover<Go2Robot> {
    fn state(&self) -> Option<(Time, LowState)> {
        self.state.read()
    }
    fn base(&self) -> Option<BasePose> {
        self.base.read().map(|(_, pose)| pose)
    }
    fn drive(&self, command: &LowCmd, now: Time) {
        self.inbox.gait.accept(command, now);
    }
    fn ask(&self) -> &GaitAsk {
        &self.inbox.ask
    }
}

impl Go2Sim {
    /// Joins the domain, starts the services, the LowCmd reader and the 500 Hz state stream.
    pub fn spawn(config: Go2SimConfig) -> Result<Self, Go2SimError> {
        #[cfg(feature = "mujoco")]
        let body = match &config.physics {
            Some(physics) => Go2Body::physics(physics)?,
            None => Go2Body::new(),
        };
        #[cfg(not(feature = "mujoco"))]
        let body = Go2Body::new();
        let participant = crate::unitree::join(&config.participant)?;
        let tap = &config.low_level_tap;
        let (reader, lowcmd) = crate::unitree::command_reader::<LowCmd>(&participant, LowCmd::TOPIC, tap)?;
        let answers = config
            .answer_lowcmd
            .then(|| {
                let mut answers = participant.writer::<LowState>(LowState::TOPIC, Qos::WRITER)?;
                answers.set_tap(tap.clone());
                Ok::<_, DdsError>(answers)
            })
            .transpose()?;
        let services_tap = config.services_tap.clone();
        let switcher = crate::unitree::service_server(&participant, motion_switcher::SERVICE, services_tap.clone())?;
        let sport = crate::unitree::service_server(&participant, sport::SERVICE, services_tap)?;
        let endpoints =
            services::Endpoints { lowcmd: reader, answers, switcher, sport, onboard_gait: config.onboard_gait };
        let inbox = Go2Inbox {
            lowcmd: CommandInbox::new(config.state_period),
            bad_head: Counter::default(),
            gait: CommandInbox::new(config.state_period),
            ask: GaitAsk::default(),
        };
        let report = Report::booted(
            BOOT_SPORT_MODE,
            format!("booted lying down; sport mode \"{BOOT_SPORT_MODE}\" owns the motors"),
        );
        let options = StreamOptions {
            period: config.state_period,
            cpu: config.cpu,
            tap: config.low_level_tap,
            name: "go2-sim",
            clock: config.clock,
        };
        let robot = Go2Robot { body, seen_command: None, seen_gait: None };
        let sim = Sim::spawn(participant, options, robot, inbox, report, |handover, report| {
            move || services::run(handover, report, endpoints)
        })?;
        Ok(Self { sim, lowcmd, onboard_gait: config.onboard_gait })
    }

    /// The port of the robot's own locomotion, when it was asked for
    /// ([`Go2SimConfig::onboard_gait`]).
    pub fn onboard(&self) -> Option<Onboard<LowState, LowCmd>> {
        self.onboard_gait.then(|| Onboard::new(self.sim.handover.clone()))
    }

    crate::unitree::handle_methods!(Go2Fault);

    /// The simulator now.
    pub fn snapshot(&self) -> Go2Snapshot {
        let reader = self.lowcmd.get();
        let inbox = &self.sim.handover.inbox;
        let counters = self.sim.counters();
        Go2Snapshot {
            sport_mode: self.sim.mode(),
            joints_rad: self.sim.published().unwrap_or(LYING_POSE_RAD),
            lowcmd: LowCmdCounters {
                accepted: inbox.lowcmd.accepted.get(),
                ignored_sport_mode: inbox.lowcmd.ignored.get(),
                bad_head: inbox.bad_head.get(),
                bad_crc: reader.checksum_errors,
                malformed: reader.decode_errors,
            },
            lowstate: counters.lowstate,
            corrupted_states: counters.corrupted_states,
            requests: counters.requests,
            state_lateness: counters.state_lateness,
            command_jitter: inbox.lowcmd.jitter(),
            base: self.sim.base(),
            sim_time_s: counters.sim_time_s,
            wall_time_s: counters.wall_time_s,
        }
    }
}

/// Whether a LowCmd has the header the Go2 expects.
fn head_ok(cmd: &LowCmd) -> bool {
    cmd.head == go2::HEAD && cmd.level_flag == go2::LEVEL_LOW
}
