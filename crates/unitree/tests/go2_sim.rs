//! The Go2 client against the simulated Go2 over real DDS, where loopback carries multicast
//! (`robowire_dds::netns`): sport mode release, standing up, damping on a stale command, refused
//! commands, the watchdog, CRC faults on the wire. Conditions are awaited with a generous
//! timeout; nothing here measures time (the stream's timing is `unitree-proto`'s fake-clock tests).

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::wait::{one_at_a_time, until_async};
use robowire_sim::go2::{Go2Fault, Go2Sim, Go2SimConfig};
use unitree::go2::STAND_POSE_RAD;
use unitree::{Connection, Device, Go2, JointCommand, LowLevel, LowLevelOptions, UnitreeError};

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

/// `scenario` with a simulated Go2 and a connected client, in a fresh namespace.
fn with_go2<F>(scenario: impl FnOnce(Go2Sim, LowLevel<Go2>) -> F + Send)
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
            let client = LowLevel::<Go2>::open(LowLevelOptions::on(Some("lo"), 0)).expect("client");
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
