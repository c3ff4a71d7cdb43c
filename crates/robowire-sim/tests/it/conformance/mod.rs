//! The two sides of the Unitree conformance checks: each simulated robot as the checks see it
//! ([`Simulator`]: its counters in common terms, the command that holds it), and the client, the
//! robot's low-level link and `motion_switcher` as Unitree's software uses them, generic over
//! the message family (`unitree_proto::robot::Robot`).

use std::time::{Duration, Instant};

use robowire_core::cdr::CdrType;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions, Reader, TopicStats, Writer};
use robowire_sim::g1::{G1Sim, G1SimConfig};
use robowire_sim::go2::{AdvanceError, BasePose, Go2Fault as Fault, Go2Sim, Go2SimConfig, SimClock};
use unitree_proto::api::{self, motion_switcher, status};
use unitree_proto::g1::{self, G1Variant};
use unitree_proto::robot::{Go2, Hg, Robot};
use unitree_proto::{HgLowState, LowCmd, LowState, Message, MotorCmd};

use crate::unitree_wire::{ServiceClient, Unsealed, WAIT};
use robowire_fixtures::wait::until;

/// What moves the simulated robot's joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Body {
    /// The kinematic joint model.
    Kinematic,
    /// MuJoCo (the G1 hanging).
    #[cfg(feature = "mujoco")]
    Physics,
}

/// What every simulator counts, in the checks' terms.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Counts {
    /// LowCmds accepted.
    pub(crate) accepted: u64,
    /// LowCmds ignored while a mode owned the motors.
    pub(crate) ignored: u64,
    /// LowCmds dropped for a CRC mismatch.
    pub(crate) bad_crc: u64,
    /// The `rt/lowstate` writer's counters.
    pub(crate) lowstate: TopicStats,
    /// LowStates sent with a flipped bit.
    pub(crate) corrupted_states: u64,
    /// Service requests answered.
    pub(crate) requests: u64,
    /// Ticks the state stream ran.
    pub(crate) ticks_run: u64,
    /// Simulated time, s.
    pub(crate) sim_time_s: f64,
    /// The base (physics only).
    pub(crate) base: Option<BasePose>,
}

/// A simulated robot as the checks drive it.
pub(crate) trait Simulator: Sized {
    /// Its low-level messages.
    type Family: Robot;
    /// Motor slots it drives (0..MOTORS).
    const MOTORS: usize;
    /// The joint the checks move, a motor slot.
    const JOINT: usize;
    /// Where `rt/sportmodestate` says the body is, m.
    #[cfg(feature = "mujoco")]
    const BODY_HEIGHT_M: std::ops::Range<f32>;

    /// Started on `lo`, domain 0.
    fn spawn(body: Body, clock: SimClock) -> Self;
    /// Its counters now.
    fn counts(&self) -> Counts;
    /// The handle's `inject`, `clear_faults` and `advance`.
    fn inject(&self, fault: Fault);
    fn clear_faults(&self);
    fn advance(&self, by: Duration) -> Result<(), AdvanceError>;
    /// A command holding every joint where `state` has it but `joint`, sent to `target_rad`.
    fn hold(state: &State<Self>, joint: usize, target_rad: f32) -> Cmd<Self>;
    /// The `mode` the state reports for `motor`.
    fn motor_mode(state: &State<Self>, motor: usize) -> u8;
}

/// A simulator's LowCmd.
pub(crate) type Cmd<S> = <<S as Simulator>::Family as Robot>::Cmd;
/// A simulator's LowState.
pub(crate) type State<S> = <<S as Simulator>::Family as Robot>::State;

fn lo() -> ParticipantOptions {
    ParticipantOptions::new(0, Some("lo"))
}

#[cfg(feature = "mujoco")]
fn physics(body: Body, hanging: bool) -> Option<robowire_sim::physics::PhysicsOptions> {
    (body == Body::Physics).then_some(robowire_sim::physics::PhysicsOptions { model: None, hanging })
}

/// The simulator's handle methods of the same names.
macro_rules! forward {
    () => {
        fn inject(&self, fault: Fault) {
            self.inject(fault);
        }
        fn clear_faults(&self) {
            self.clear_faults();
        }
        fn advance(&self, by: Duration) -> Result<(), AdvanceError> {
            self.advance(by)
        }
    };
}

impl Simulator for Go2Sim {
    type Family = Go2;
    const MOTORS: usize = robowire_sim::go2::JOINTS;
    /// FR thigh.
    const JOINT: usize = 1;
    #[cfg(feature = "mujoco")]
    const BODY_HEIGHT_M: std::ops::Range<f32> = 0.05..0.2;

    fn spawn(body: Body, clock: SimClock) -> Self {
        #[cfg(not(feature = "mujoco"))]
        let Body::Kinematic = body;
        let config = Go2SimConfig {
            participant: lo(),
            clock,
            #[cfg(feature = "mujoco")]
            physics: physics(body, false),
            ..Go2SimConfig::default()
        };
        Go2Sim::spawn(config).expect("the Go2 simulator starts")
    }

    fn counts(&self) -> Counts {
        let s = self.snapshot();
        Counts {
            accepted: s.lowcmd.accepted,
            ignored: s.lowcmd.ignored_sport_mode,
            bad_crc: s.lowcmd.bad_crc,
            lowstate: s.lowstate,
            corrupted_states: s.corrupted_states,
            requests: s.requests,
            ticks_run: s.state_lateness.count,
            sim_time_s: s.sim_time_s,
            base: s.base,
        }
    }

    forward!();

    /// Unitree's stand example's gains (Kp 60, Kd 5) on the 12 joints.
    fn hold(state: &LowState, joint: usize, target_rad: f32) -> LowCmd {
        let mut cmd = LowCmd::default();
        for (m, motor) in cmd.motor_cmd.iter_mut().enumerate().take(Self::MOTORS) {
            let q = if m == joint { target_rad } else { state.motor_state[m].q.get() };
            *motor = MotorCmd::servo(q, 0.0, 60.0, 5.0, 0.0);
        }
        cmd
    }

    fn motor_mode(state: &LowState, motor: usize) -> u8 {
        state.motor_state[motor].mode
    }
}

impl Simulator for G1Sim {
    type Family = Hg;
    const MOTORS: usize = g1::JOINTS;
    const JOINT: usize = g1::slot::LEFT_ELBOW;
    #[cfg(feature = "mujoco")]
    const BODY_HEIGHT_M: std::ops::Range<f32> = 0.7..1.2;

    fn spawn(body: Body, clock: SimClock) -> Self {
        #[cfg(not(feature = "mujoco"))]
        let Body::Kinematic = body;
        let config = G1SimConfig {
            participant: lo(),
            clock,
            #[cfg(feature = "mujoco")]
            physics: physics(body, true),
            ..G1SimConfig::new(G1Variant::Dof29)
        };
        G1Sim::spawn(config).expect("the G1 simulator starts")
    }

    fn counts(&self) -> Counts {
        let s = self.snapshot();
        Counts {
            accepted: s.lowcmd.accepted,
            ignored: s.lowcmd.ignored_mode,
            bad_crc: s.lowcmd.bad_crc,
            lowstate: s.stream.lowstate,
            corrupted_states: s.stream.corrupted_states,
            requests: s.stream.requests,
            ticks_run: s.stream.state_lateness.count,
            sim_time_s: s.stream.sim_time_s,
            base: s.base,
        }
    }

    forward!();

    /// Unitree's example gains, the robot's `mode_machine` from `state`.
    fn hold(state: &HgLowState, joint: usize, target_rad: f32) -> unitree_proto::HgLowCmd {
        let pose = core::array::from_fn(|s| if s == joint { target_rad } else { state.motor_state[s].q.get() });
        g1::hold(&pose, state.mode_machine, G1Variant::Dof29)
    }

    fn motor_mode(state: &HgLowState, motor: usize) -> u8 {
        state.motor_state[motor].mode
    }
}

/// The next sample `reader` takes within `bound`.
pub(crate) fn recv_within<T: CdrType + 'static>(
    runtime: &tokio::runtime::Runtime,
    reader: &mut Reader<T>,
    bound: Duration,
) -> Option<T> {
    runtime.block_on(async { tokio::time::timeout(bound, reader.recv()).await.ok().map(|s| s.unwrap().value) })
}

/// The other end of the wire: Unitree's side of one simulator.
pub(crate) struct Client<S: Simulator> {
    pub(crate) runtime: tokio::runtime::Runtime,
    pub(crate) lowcmd: Writer<Cmd<S>>,
    pub(crate) unsealed: Writer<Unsealed<Cmd<S>>>,
    pub(crate) states: Reader<State<S>>,
    pub(crate) switcher: ServiceClient,
    next_id: i64,
    pub(crate) participant: Participant,
}

impl<S: Simulator> Client<S> {
    /// Its state reader keeps the last `kept` states.
    pub(crate) fn new(kept: i32) -> Self {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        let participant = Participant::new(lo()).unwrap();
        // The state reader first: a service answered means the simulator has seen it too.
        let states = participant.reader(<State<S> as Message>::TOPIC, Qos { depth: kept, ..Qos::READER }).unwrap();
        Self {
            lowcmd: participant.writer(<Cmd<S> as Message>::TOPIC, Qos::WRITER).unwrap(),
            unsealed: participant.writer(<Cmd<S> as Message>::TOPIC, Qos::WRITER).unwrap(),
            states,
            switcher: ServiceClient::new(&participant, motion_switcher::SERVICE),
            next_id: 0,
            runtime,
            participant,
        }
    }

    /// The next state the robot sends.
    pub(crate) fn state(&mut self) -> State<S> {
        self.state_within(WAIT).expect("a LowState in time")
    }

    /// The next state the robot sends within `bound`.
    pub(crate) fn state_within(&mut self, bound: Duration) -> Option<State<S>> {
        recv_within(&self.runtime, &mut self.states, bound)
    }

    /// Calls `motion_switcher`'s `api_id` with `parameter`, writing the request again until
    /// answered: the answer's code and data.
    pub(crate) fn call(&mut self, api_id: i64, parameter: &str) -> (i32, String) {
        self.next_id += 1;
        let answer = self.runtime.block_on(self.switcher.call(self.next_id, api_id, parameter));
        (answer.code, answer.data)
    }

    /// `motion_switcher` ReleaseMode; CheckMode then names no mode.
    pub(crate) fn release(&mut self) {
        assert_eq!(self.call(motion_switcher::RELEASE_MODE, "{}").0, status::OK);
        let (_, mode) = self.call(motion_switcher::CHECK_MODE, "{}");
        assert_eq!(motion_switcher::mode_name(&mode), Some(""), "{mode}");
    }

    /// Until the simulator's `rt/lowstate` writer is matched with the state reader: this
    /// participant has seen the writer, and the simulator has answered a call (it has seen
    /// the reader, announced before the answer's reader).
    pub(crate) fn wait_matched(&mut self) {
        let topic = <State<S> as Message>::TOPIC;
        until(WAIT, "the rt/lowstate writer discovered", || {
            self.participant.discovered_endpoints().iter().any(|e| e.writer && e.topic == topic)
        });
        assert_eq!(self.call(api::API_VERSION_ID, "{}").0, status::OK);
    }

    /// Sends what `command` gives once per state received, until `done` holds for the state
    /// and the simulator's counts.
    pub(crate) fn drive_until(
        &mut self,
        sim: &S,
        mut command: impl FnMut(&Self),
        mut done: impl FnMut(&State<S>, &Counts) -> bool,
    ) -> (State<S>, Counts) {
        let start = Instant::now();
        loop {
            command(self);
            let state = self.state();
            let counts = sim.counts();
            if done(&state, &counts) {
                return (state, counts);
            }
            assert!(start.elapsed() < WAIT, "not reached in {WAIT:?}; last {counts:?}");
        }
    }
}
