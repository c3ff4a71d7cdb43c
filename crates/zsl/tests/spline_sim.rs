//! The client against the 1 kHz daemon simulator on real shared memory: fault handling and a
//! PD loop that moves the legs.

use std::time::{Duration, Instant};

use robowire_sim::spline::{STANDING_POSE_RAD, SplineSim, SplineSimConfig};
use zsl::spline::{ImuReader, SplineError};
use zsl::{JointControl, JointFlags, JointIndex, Leg, SplineClient, SplineCommandBlock};

fn sim(tag: &str) -> SplineSim {
    SplineSim::spawn(SplineSimConfig::private(tag)).expect("simulator")
}

fn hold(pose: [f32; 3], kp: f32, kd: f32) -> SplineCommandBlock {
    let mut cmd = SplineCommandBlock::default();
    for leg in Leg::ALL {
        for (j, joint) in JointIndex::ALL.into_iter().take(3).enumerate() {
            *cmd.joint_mut(leg, joint) = JointControl::new(pose[j], 0.0, kp, kd, 0.0);
        }
    }
    cmd
}

#[test]
fn missing_daemon_is_a_typed_error() {
    match SplineClient::open("/robowire-no-such-daemon") {
        Err(SplineError::DaemonNotRunning { name }) => assert_eq!(name, "/robowire-no-such-daemon"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(ImuReader::open("/robowire-no-such-imu"), Err(zsl::ImuError::ProducerNotRunning { .. })));
}

#[test]
fn a_stopped_daemon_is_reported_within_the_stall_bound() {
    let sim = sim("stall");
    let mut client = SplineClient::open(&sim.config().spline_name).unwrap();
    for _ in 0..20 {
        client.wait_state(Duration::from_millis(100)).unwrap();
    }
    sim.pause(true);
    let paused_at = Instant::now();
    let err = loop {
        match client.wait_state(Duration::from_millis(100)) {
            Ok(_) => continue, // a state published just before the pause
            Err(e) => break e,
        }
    };
    let noticed = paused_at.elapsed();
    assert!(matches!(err, SplineError::DaemonStalled { .. }), "{err}");
    // Bound: 10 ms without fresh state, plus the last cycle before the pause, plus slack.
    assert!(noticed <= Duration::from_millis(10 + 1 + 40), "stall noticed after {noticed:?}");
    assert_eq!(client.counters().stalls, 1);
    sim.pause(false);
    client.wait_state(Duration::from_millis(100)).expect("fresh state again after the daemon resumed");
    assert!(!client.is_stalled());
}

#[test]
fn a_vanished_client_makes_the_daemon_clear_the_command() {
    let sim = sim("vanish");
    let mut client = SplineClient::open(&sim.config().spline_name).unwrap();
    client.write_command(&hold(STANDING_POSE_RAD, 40.0, 1.0)).unwrap();
    drop(client);
    let start = Instant::now();
    while sim.stats().daemon.clears == 0 && start.elapsed() < Duration::from_secs(2) {
        std::thread::sleep(Duration::from_millis(1));
    }
    let stats = sim.stats();
    assert_eq!(stats.daemon.clears, 1, "{stats:?}");
    assert!(stats.daemon.fresh >= 1);
    // About 10 cycles after the last command: the motors are limp (kp = kd = 0: disabled).
    std::thread::sleep(Duration::from_millis(5));
    let state = sim.state();
    assert!(Leg::ALL.iter().all(|&leg| !JointFlags(state.joint(leg, JointIndex::Hip).flags.get()).enabled()));
}

#[test]
fn a_pd_loop_moves_the_legs_to_the_stand_pose() {
    let sim = sim("stand");
    let mut client = SplineClient::open(&sim.config().spline_name).unwrap();
    let mut imu = ImuReader::open(&sim.config().imu_name).unwrap();
    let target = hold(STANDING_POSE_RAD, 60.0, 2.0);
    let mut last = None;
    for _ in 0..800 {
        let state = client.wait_state(Duration::from_millis(50)).unwrap();
        client.write_command(&target).unwrap();
        last = Some(state);
    }
    let state = last.unwrap();
    for leg in Leg::ALL {
        for (j, joint) in JointIndex::ALL.into_iter().take(3).enumerate() {
            let p = state.joint(leg, joint).p.get();
            assert!((p - STANDING_POSE_RAD[j]).abs() < 0.02, "{leg:?} {joint:?} at {p}");
        }
    }
    let sample = imu.read().unwrap();
    assert_eq!(sample.acc_mps2[2], 9.81);
    assert!(imu.latest_age().unwrap() < Duration::from_millis(100));
    assert!(sim.stats().cycles >= 800);
}

#[test]
fn fault_bits_reach_the_client() {
    let sim = sim("fault");
    sim.inject_fault(Leg::FrontLeft, JointIndex::Knee, JointFlags::OVER_TEMPERATURE);
    let mut client = SplineClient::open(&sim.config().spline_name).unwrap();
    client.wait_state(Duration::from_millis(100)).unwrap();
    let state = client.wait_state(Duration::from_millis(100)).unwrap();
    let flags = JointFlags(state.joint(Leg::FrontLeft, JointIndex::Knee).flags.get());
    assert!(flags.faults().over_temperature);
    assert!(!JointFlags(state.joint(Leg::FrontLeft, JointIndex::Hip).flags.get()).faults().any());
}
