//! One set of checks every simulated Unitree robot passes on the wire, in a private network
//! (`robowire_dds::netns`), whatever moves its joints: the Go2 and the G1 on the kinematic joint
//! model, and with the `mujoco` feature on physics (the G1 hanging). Each check is written once
//! over [`crate::conformance::Simulator`]; each (simulator, check) pair is a test named
//! `unitree_conformance::<robot>_<body>::<check>` (`cargo test --features mujoco --test it
//! conformance::go2_physics::` runs the physics Go2's).
//!
//! The checks: LowCmds ignored and counted until `motion_switcher` ReleaseMode, then driving a
//! joint ([`release`]); every LowState sealed, a LowCmd with a wrong CRC counted and not applied
//! ([`crc`]); the writer's and the services' counters ([`counters`]); the faults and their
//! clearing ([`faults`]); `rt/sportmodestate` from the physics ([`sport_state`]); lock-step time
//! ([`lock_step`]).

use std::time::{Duration, Instant};

use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::wait::until;
use robowire_sim::g1::G1Sim;
use robowire_sim::go2::{AdvanceError, Go2Fault as Fault, Go2Sim, SimClock};
use unitree_proto::Message;
use unitree_proto::api::{self, motion_switcher, status};
use unitree_proto::robot::Robot;

use crate::conformance::{Body, Client, Simulator, State};
use crate::unitree_wire::{Unsealed, WAIT};

/// How far from where it stands a check sends its joint, rad.
const STEP_RAD: f32 = 0.4;
/// A joint within this of its target has reached it (physics included), rad.
const REACHED_RAD: f32 = 0.15;
/// Commands a check sends before it looks at what the robot did with them.
const ENOUGH: u64 = 20;

fn q<S: Simulator>(state: &State<S>) -> f32 {
    <S::Family as Robot>::joint_position(state, S::JOINT).expect("a driven joint")
}

fn reached<S: Simulator>(state: &State<S>, target_rad: f32) -> bool {
    (q::<S>(state) - target_rad).abs() < REACHED_RAD
}

/// Before ReleaseMode, LowCmds are ignored and counted and the joint stays; after it, they are
/// accepted and the joint goes to a target [`STEP_RAD`] from where it stands.
fn release<S: Simulator>(body: Body) {
    let sim = S::spawn(body, SimClock::default());
    let mut c = Client::<S>::new(1);
    let start = c.state();
    let target = q::<S>(&start) + STEP_RAD;
    let owned = S::hold(&start, S::JOINT, target);
    let (state, counts) = c.drive_until(&sim, |c| c.lowcmd.write(owned).unwrap(), |_, n| n.ignored >= ENOUGH);
    assert_eq!(counts.accepted, 0, "a mode owns the motors: {counts:?}");
    assert!(!reached::<S>(&state, target), "ignored, yet the joint went to {target}: {}", q::<S>(&state));

    c.release();
    let ignored = sim.counts().ignored;
    let now = c.state();
    let target = q::<S>(&now) + STEP_RAD;
    let cmd = S::hold(&now, S::JOINT, target);
    let (_, counts) = c.drive_until(&sim, |c| c.lowcmd.write(cmd).unwrap(), |s, _| reached::<S>(s, target));
    assert!(counts.accepted > 0, "{counts:?}");
    assert_eq!(counts.ignored, ignored, "nothing ignored once released");
}

/// Every LowState the client takes is sealed; a LowCmd with a wrong CRC is counted and not
/// applied, the same one sealed is.
fn crc<S: Simulator>(body: Body) {
    let sim = S::spawn(body, SimClock::default());
    let mut c = Client::<S>::new(1);
    for _ in 0..200 {
        let state = c.state();
        assert_eq!(state.crc(), state.computed_crc());
    }
    let taken = c.states.stats();
    assert_eq!((taken.checksum_errors, taken.decode_errors), (0, 0), "{taken:?}");
    assert!(taken.samples >= 200, "{taken:?}");

    c.release();
    let now = c.state();
    let target = q::<S>(&now) + STEP_RAD;
    let cmd = S::hold(&now, S::JOINT, target);
    let (state, counts) = c.drive_until(&sim, |c| c.unsealed.write(Unsealed(cmd)).unwrap(), |_, n| n.bad_crc >= ENOUGH);
    assert_eq!(counts.accepted, 0, "a bad CRC is never applied: {counts:?}");
    assert!(!reached::<S>(&state, target), "a bad CRC moved the joint to {target}");
    let (_, counts) = c.drive_until(&sim, |c| c.lowcmd.write(cmd).unwrap(), |s, _| reached::<S>(s, target));
    assert!(counts.accepted > 0 && counts.bad_crc >= ENOUGH, "{counts:?}");
}

/// The `rt/lowstate` writer counts at about the stream's rate; `requests` counts the calls.
fn counters<S: Simulator>(body: Body) {
    let sim = S::spawn(body, SimClock::default());
    let mut c = Client::<S>::new(1);
    c.state();
    let before = sim.counts();
    for _ in 0..200 {
        c.state();
    }
    let after = sim.counts();
    let written = after.lowstate.samples - before.lowstate.samples;
    assert!(written >= 100, "{written} LowStates written while 200 arrived");
    assert_eq!((after.lowstate.write_errors, after.lowstate.dropped), (0, 0), "{:?}", after.lowstate);
    assert_eq!(after.base.is_some(), body != Body::Kinematic, "a base only with physics");

    assert_eq!(after.requests, 0, "no call made yet");
    let calls = [api::API_VERSION_ID, motion_switcher::CHECK_MODE, motion_switcher::RELEASE_MODE];
    for api_id in calls {
        assert_eq!(c.call(api_id, "{}").0, status::OK);
    }
    c.release();
    let (made, answered) = (calls.len() as u64 + 2, sim.counts().requests);
    // A request written before the service's reader matched is lost; written again, it counts.
    assert!(made <= answered && answered <= c.switcher.written, "{made} calls, {answered} answered");
}

/// A motor fault reports mode 0; bit flips are caught by the client's CRC check; silence stops
/// the states; cleared, they flow again with every motor's mode 1.
fn faults<S: Simulator>(body: Body) {
    let sim = S::spawn(body, SimClock::default());
    let mut c = Client::<S>::new(1);
    c.state();
    sim.inject(Fault::MotorFault { motor: S::JOINT });
    let (state, _) = c.drive_until(&sim, |_| {}, |s, _| S::motor_mode(s, S::JOINT) == 0);
    assert!((0..S::MOTORS).all(|m| m == S::JOINT || S::motor_mode(&state, m) == 1), "only the failed motor");

    sim.inject(Fault::BitFlips { every: 4 });
    let caught = c.states.stats().checksum_errors;
    let start = Instant::now();
    while c.states.stats().checksum_errors < caught + 5 {
        c.state();
        assert!(start.elapsed() < WAIT, "no corrupted LowState caught");
    }
    assert!(sim.counts().corrupted_states >= 5, "{:?}", sim.counts());

    sim.inject(Fault::Silence);
    let silent = sim.counts();
    // The states on their way when it fell silent arrive at once; then none for 0.5 s.
    until(WAIT, "a 0.5 s without LowState", || c.state_within(Duration::from_millis(500)).is_none());
    until(WAIT, "the silent stream running 250 ticks", || sim.counts().ticks_run >= silent.ticks_run + 250);
    assert!(c.state_within(Duration::ZERO).is_none(), "a LowState while silent");
    let counts = sim.counts();
    assert_eq!(counts.lowstate.samples, silent.lowstate.samples, "written while silent");

    sim.clear_faults();
    let (state, _) = c.drive_until(&sim, |_| {}, |s, _| S::motor_mode(s, S::JOINT) == 1);
    assert!((0..S::MOTORS).all(|m| S::motor_mode(&state, m) == 1));
    let cleared = sim.counts();
    for _ in 0..100 {
        c.state();
    }
    let after = sim.counts();
    assert_eq!(after.corrupted_states, cleared.corrupted_states, "a bit flipped once cleared");
    assert!(after.lowstate.samples > counts.lowstate.samples);
}

/// `rt/sportmodestate` comes from the physics: the body's height, and the snapshot's base.
#[cfg(feature = "mujoco")]
fn sport_state<S: Simulator>(body: Body) {
    use robowire_dds::qos::Qos;
    use unitree_proto::sport_state::{SPORT_MODE_STATE_TOPIC, SportModeState};
    let sim = S::spawn(body, SimClock::default());
    let c = Client::<S>::new(1);
    let mut reader = c.participant.reader::<SportModeState>(SPORT_MODE_STATE_TOPIC, Qos::READER).unwrap();
    let sport = crate::conformance::recv_within(&c.runtime, &mut reader, WAIT).expect("rt/sportmodestate in time");
    let height = sport.body_height.get();
    assert!(S::BODY_HEIGHT_M.contains(&height), "body height {height} m outside {:?}", S::BODY_HEIGHT_M);
    let base = sim.counts().base.expect("a base with physics");
    assert!((base.position_m[2] - height).abs() < 0.05, "{base:?} against {height} m");
}

/// Lock-step: nothing is sent until `advance`, which sends a state per 2 ms period; a real-time
/// simulator refuses to be advanced.
fn lock_step<S: Simulator>(body: Body) {
    let real_time = S::spawn(body, SimClock::default());
    assert_eq!(real_time.advance(Duration::from_millis(100)), Err(AdvanceError::NotLockStep));
    drop(real_time);

    let sim = S::spawn(body, SimClock::LockStep);
    let mut c = Client::<S>::new(128);
    c.wait_matched();
    assert!(c.state_within(Duration::from_millis(500)).is_none(), "a LowState before advance");
    assert_eq!(sim.counts().lowstate.samples, 0);
    let mut tick_ms = 0;
    for (round, sim_time_s) in [(1, 0.1), (2, 0.2)] {
        sim.advance(Duration::from_millis(100)).unwrap();
        for _ in 0..50 {
            tick_ms += 2;
            assert_eq!(<S::Family as Robot>::tick(&c.state()), tick_ms, "round {round}: each state 2 ms on");
        }
        let counts = sim.counts();
        assert_eq!(counts.lowstate.samples, 50 * round, "{:?}", counts.lowstate);
        assert!((counts.sim_time_s - sim_time_s).abs() < 1e-3, "round {round}: {} s", counts.sim_time_s);
    }
    assert!(c.state_within(Duration::ZERO).is_none(), "no state between advances");
}

/// One test per check on a simulator: `$name::<check>`.
macro_rules! simulator {
    ($name:ident: $sim:ty, $body:expr; $($check:ident),+) => {
        mod $name {
            use super::*;
            $(
                #[test]
                fn $check() {
                    with_loopback_multicast(|| super::$check::<$sim>($body));
                }
            )+
        }
    };
}

simulator!(go2_kinematic: Go2Sim, Body::Kinematic; release, crc, counters, faults, lock_step);
simulator!(g1_kinematic: G1Sim, Body::Kinematic; release, crc, counters, faults, lock_step);
#[cfg(feature = "mujoco")]
simulator!(go2_physics: Go2Sim, Body::Physics; release, crc, counters, faults, sport_state, lock_step);
#[cfg(feature = "mujoco")]
simulator!(g1_physics_hanging: G1Sim, Body::Physics; release, crc, counters, faults, sport_state);
