//! The Go2 client against the simulated Go2 over real DDS, where loopback carries multicast
//! (`robowire_dds::netns`): sport mode release, standing up, damping on a stale command, refused
//! commands, a motion followed by the stream, the watchdog, CRC faults on the wire. Conditions
//! are awaited with a generous timeout; nothing here measures time (the stream's timing is
//! `unitree-proto`'s fake-clock tests).

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::wait::{one_at_a_time, until_async};
use robowire_sim::go2::{Go2Fault, Go2Sim, Go2SimConfig};
use robowire_tap::{Direction, TapRing};
use unitree::go2::STAND_POSE_RAD;
use unitree::trajectory::{JointTrajectory, Motion, from_fn, stand_pose};
use unitree::{Connection, Device, Go2, JointCommand, LowCmd, LowLevel, LowLevelOptions, MotionState, UnitreeError};
use unitree_proto::Message;

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

/// `scenario` with a simulated Go2 and a connected client, in a fresh namespace.
fn with_go2<F>(scenario: impl FnOnce(Go2Sim, LowLevel<Go2>) -> F + Send)
where
    F: Future<Output = ()>,
{
    with_go2_options(LowLevelOptions::on(Some("lo"), 0), scenario);
}

/// [`with_go2`], the client opened with `options`.
fn with_go2_options<F>(options: LowLevelOptions, scenario: impl FnOnce(Go2Sim, LowLevel<Go2>) -> F + Send)
where
    F: Future<Output = ()>,
{
    let _turn = one_at_a_time();
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let sim = Go2Sim::spawn(Go2SimConfig {
                participant: unitree::ParticipantOptions::new(0, Some("lo")),
                ..Default::default()
            })
            .expect("simulator");
            let client = LowLevel::<Go2>::open(options).expect("client");
            scenario(sim, client).await;
        })
    });
}

fn stand() -> [JointCommand; 12] {
    std::array::from_fn(|i| JointCommand::hold(STAND_POSE_RAD[i % 3], 60.0, 5.0))
}

#[test]
fn release_then_stand_up_then_damping_when_the_command_goes_stale() {
    with_go2(|sim, robot| async move {
        assert!(robot.wait_state(WAIT, move |_| true).await.is_some(), "state arrives");
        assert_eq!(robot.connection(), Connection::Connected);
        // Before the release the robot ignores LowCmds, and says so.
        robot.set_joints(&stand()).unwrap();
        until_async(WAIT, "a LowCmd ignored", || sim.snapshot().lowcmd.ignored_sport_mode > 0).await;
        assert!(sim.take_log().iter().any(|l| l.contains("LowCmd ignored")));
        assert_eq!(robot.sport_mode().await.unwrap(), "normal");
        assert_eq!(robot.release_sport_mode().await.unwrap(), 1, "one ReleaseMode");
        assert_eq!(robot.sport_mode().await.unwrap(), "");
        assert_eq!(robot.release_sport_mode().await.unwrap(), 0, "nothing left to release");

        // Stand up: keep the command fresh until every joint is at the stand pose.
        until_async(WAIT, "standing", || {
            robot.set_joints(&stand()).unwrap();
            robot
                .joint_positions()
                .is_some_and(|q| q.iter().enumerate().all(|(i, q)| (q - STAND_POSE_RAD[i % 3]).abs() < 0.02))
        })
        .await;
        let s = robot.stats();
        assert!(s.commands_sent > 0 && s.damping_sent == 0 && s.command_timeouts == 0, "{s:?}");
        assert_eq!((s.lowstate.checksum_errors, s.lowstate.decode_errors), (0, 0));
        assert!(sim.snapshot().lowcmd.accepted > 0 && sim.snapshot().lowcmd.bad_crc == 0);

        // Silence from the controller: damping takes over (kp 0): the joints are no longer held.
        until_async(WAIT, "damping after the timeout", || robot.stats().damping_sent > 10).await;
        assert_eq!(robot.stats().command_timeouts, 1);
    });
}

#[test]
fn bad_commands_are_refused_before_anything_is_sent() {
    with_go2(|_sim, robot| async move {
        let mut nan = stand();
        nan[3].kd = f32::NAN;
        assert!(matches!(robot.set_joints(&nan), Err(UnitreeError::Command(_))));
        let mut knee = stand();
        knee[2].q_rad = 0.5; // a calf cannot bend forward
        assert!(matches!(robot.set_joints(&knee), Err(UnitreeError::Command(_))));
        let mut torque = stand();
        torque[0].tau_nm = 100.0;
        assert!(matches!(robot.set_joints(&torque), Err(UnitreeError::Command(_))));
        assert_eq!(robot.stats().commands_sent, 0, "nothing was latched, nothing is streamed");
    });
}

/// Whether every leg joint is within 0.02 rad of the stand pose.
fn standing(q: Option<[f32; 12]>) -> bool {
    q.is_some_and(|q| q.iter().zip(stand_pose()).all(|(q, s)| (q - s).abs() < 0.02))
}

#[test]
fn a_followed_stand_up_is_stepped_on_the_streams_deadlines_and_held() {
    let ring = TapRing::with_slots(8192);
    let options = LowLevelOptions { low_level_tap: Some(ring.tap(0)), ..LowLevelOptions::on(Some("lo"), 0) };
    with_go2_options(options, |sim, robot| async move {
        assert!(robot.wait_state(WAIT, move |_| true).await.is_some(), "state arrives");
        robot.release_sport_mode().await.unwrap();
        let from = robot.joint_positions().unwrap();
        let stand = JointTrajectory::stand_up(from, Duration::from_millis(400));
        // Each step carries its slot, in periods from the first, in `reserve`.
        let period = robot.options().stream.period;
        let tagged = from_fn(stand.duration(), move |elapsed: Duration| {
            let mut cmd = stand.command_at(elapsed).unwrap();
            cmd.reserve = u32::try_from(elapsed.as_nanos() / period.as_nanos()).unwrap().into();
            cmd
        });
        let following = robot.follow(tagged).unwrap();
        tokio::time::timeout(WAIT, following.wait()).await.expect("the motion's end").unwrap();
        assert_eq!(following.state(), MotionState::Reached);
        let began = following.began().expect("its first step went out");
        until_async(WAIT, "standing", || standing(robot.joint_positions())).await;
        // Held by the stream, fresh, past the command timeout (50 periods) with no command.
        let sent = robot.stats().commands_sent;
        until_async(WAIT, "a hold of 100 periods", || robot.stats().commands_sent > sent + 100).await;
        assert!(standing(robot.joint_positions()));
        let stats = robot.stats();
        assert_eq!((stats.damping_sent, stats.command_timeouts), (0, 0), "{stats:?}");

        // Every LowCmd the stream wrote during the move: the trajectory at its slot, one per
        // tick, in order, none written before its slot was due.
        let mut steps = Vec::new();
        while let Some(frame) = ring.pop(|f| {
            (f.direction == Direction::Sent).then(|| (f.monotonic_ns, LowCmd::decode_cdr(f.bytes()).unwrap().0))
        }) {
            steps.extend(frame);
        }
        assert_eq!(ring.counters().dropped(), 0);
        let last = u32::try_from(stand.duration().as_nanos() / period.as_nanos()).unwrap();
        let moving: Vec<_> = steps.iter().filter(|(_, c)| c.reserve.get() < last).collect();
        assert_eq!(moving[0].1.reserve.get(), 0, "the first step at 0");
        let mut skipped = 0;
        for pair in moving.windows(2) {
            let (a, b) = (pair[0].1.reserve.get(), pair[1].1.reserve.get());
            assert!(b > a, "one step per tick, in order: {a} then {b}");
            skipped += u64::from(b - a - 1);
        }
        assert!(skipped <= stats.missed_ticks, "a step is skipped only with a missed tick");
        assert!(moving.len() as u64 + stats.missed_ticks >= u64::from(last), "{} steps of {last}", moving.len());
        for (written_ns, cmd) in &moving {
            let slot = period * cmd.reserve.get();
            let mut expected = stand.command_at(slot).unwrap();
            expected.reserve = cmd.reserve;
            assert_eq!(cmd.motor_cmd, expected.motor_cmd, "the trajectory at {slot:?}");
            assert!(*written_ns >= (began + slot).as_nanos(), "written at or after its slot");
        }
        assert!(steps.iter().any(|(_, c)| c.reserve.get() == last), "its end, then held");
        let lowcmd = sim.snapshot().lowcmd;
        assert!(lowcmd.accepted > 0 && lowcmd.bad_crc == 0, "{lowcmd:?}");
    });
}

#[test]
fn a_motion_is_refused_replaced_damped_and_closed() {
    with_go2(|sim, robot| async move {
        assert!(robot.wait_state(WAIT, move |_| true).await.is_some(), "state arrives");
        // A target the robot's rules refuse (a calf bent forward): nothing sent, nothing changed.
        let mut reckless = stand_pose();
        reckless[2] = 0.5;
        let refused = JointTrajectory::new(stand_pose(), reckless, Duration::from_secs(1), 60.0, 5.0);
        assert!(matches!(robot.follow(refused), Err(UnitreeError::Command(_))));
        assert_eq!(robot.stats().commands_sent, 0, "nothing is streamed");

        let long = || JointTrajectory::new(stand_pose(), stand_pose(), Duration::from_secs(60), 60.0, 5.0);
        let first = robot.follow(long()).unwrap();
        // A newer command replaces it.
        until_async(WAIT, "moving", || matches!(first.state(), MotionState::Moving { .. })).await;
        robot.set_joints(&stand()).unwrap();
        let end = tokio::time::timeout(WAIT, first.wait()).await.unwrap();
        assert!(matches!(end, Err(UnitreeError::MotionEnded(MotionState::Replaced))), "{end:?}");
        // Damping ends one.
        let second = robot.follow(long()).unwrap();
        until_async(WAIT, "moving", || matches!(second.state(), MotionState::Moving { .. })).await;
        robot.damp();
        let end = tokio::time::timeout(WAIT, second.wait()).await.unwrap();
        assert!(matches!(end, Err(UnitreeError::MotionEnded(MotionState::Damped))), "{end:?}");
        // Closing ends one (in damping, as always).
        let third = robot.follow(long()).unwrap();
        until_async(WAIT, "moving", || matches!(third.state(), MotionState::Moving { .. })).await;
        let waiting = tokio::spawn(third.wait());
        robot.close();
        assert!(third.is_done());
        assert!(matches!(tokio::time::timeout(WAIT, waiting).await.unwrap().unwrap(), Err(UnitreeError::Closed)));
        assert!(matches!(third.wait().await, Err(UnitreeError::Closed)));
        assert_eq!(third.state(), MotionState::Damped);
        drop(sim);
    });
}

#[test]
fn the_watchdog_and_faults_on_the_wire() {
    with_go2(|sim, robot| async move {
        assert!(robot.wait_state(WAIT, move |_| true).await.is_some());
        let mut events = robot.connection_events();
        sim.inject(Go2Fault::Silence);
        tokio::time::timeout(WAIT, events.wait_for(|c| *c == Connection::Disconnected)).await.unwrap().unwrap();
        let age = robot.latest().unwrap().age();
        assert!(age >= robot.options().state_timeout, "the last state is kept with its age: {age:?}");
        sim.clear_faults();
        tokio::time::timeout(WAIT, events.wait_for(|c| *c == Connection::Connected)).await.unwrap().unwrap();
        assert_eq!((robot.stats().disconnects, robot.stats().reconnects), (1, 1));

        sim.inject(Go2Fault::BitFlips { every: 5 });
        until_async(WAIT, "CRC errors counted", || robot.stats().lowstate.checksum_errors >= 5).await;
        assert_eq!(robot.stats().lowstate.decode_errors, 0, "a flipped bit is a CRC error, not garbage");
        sim.clear_faults();

        sim.inject(Go2Fault::MotorFault { motor: 7 });
        assert!(
            robot
                .wait_state(WAIT, move |s| s.motor_state[7].mode == 0 && s.motor_state[7].lost.get() > 0)
                .await
                .is_some()
        );
        assert!(robot.latest().unwrap().state.motor_state[6].mode == 1, "the others are fine");
    });
}
