//! The controller's side (this crate) against the daemon's side (`robowire-sim`) and the IMU on a
//! heap region: the protocol without the operating system (these tests also run under Miri).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use robowire_shm::{HeapRegion, SharedRegion};
use robowire_sim::spline::{CommandUpdate, ImuWriter, SplineDaemon};
use zsl::{
    ConsumerIndex, ImuError, ImuReader, JointControl, JointIndex, Leg, SplineClient, SplineCommandBlock, SplineError,
    SplineStateBlock,
};
use zsl_proto::shm::{NavImu, NavImuSample, SPLINE_COMMAND, SPLINE_DATA_LEN};

/// The daemon's command flag.
const COMMAND_FLAG: usize = SPLINE_COMMAND.flag;

fn region() -> Arc<HeapRegion> {
    Arc::new(HeapRegion::new(10240))
}

fn command(marker: f32) -> SplineCommandBlock {
    let mut cmd = SplineCommandBlock::default();
    for leg in Leg::ALL {
        for joint in JointIndex::ALL {
            *cmd.joint_mut(leg, joint) = JointControl::new(marker, 0.0, 20.0, 1.0, 0.0);
        }
    }
    cmd
}

#[test]
fn command_and_state_round_trip() {
    let shared = region();
    let mut client = SplineClient::new(shared.clone()).unwrap();
    let mut daemon = SplineDaemon::new(shared.clone()).unwrap();
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Repeated, "nothing fresh yet");
    client.write_command(&command(0.5)).unwrap();
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Fresh);
    assert_eq!(daemon.command().joint(Leg::RearLeft, JointIndex::Knee).p_des.get(), 0.5);
    assert_eq!(daemon.command().legs[2].flags.get(), 1, "leg flags are always 1");
    assert_eq!(shared.load_u32(COMMAND_FLAG, Ordering::Acquire), Ok(0), "the daemon cleared the control flag");

    assert_eq!(client.try_read_state().unwrap(), None, "no state published yet");
    let mut state = SplineStateBlock::default();
    state.joint_mut(Leg::FrontLeft, JointIndex::Hip).p = 1.25.into();
    daemon.publish_state(&state).unwrap();
    let got = client.try_read_state().unwrap().expect("fresh state");
    assert_eq!(got.joint(Leg::FrontLeft, JointIndex::Hip).p.get(), 1.25);
    assert_eq!(client.try_read_state().unwrap(), None, "consumed");
    // A monitor reads through the other consumer flag, which the controller left set.
    let mut monitor = SplineClient::new(shared.clone()).unwrap().with_consumer(ConsumerIndex::Other);
    assert!(monitor.try_read_state().unwrap().is_some());
    assert_eq!(client.counters().commands_written, 1);
    assert_eq!(client.counters().states_read, 1);
}

#[test]
fn daemon_clears_the_command_after_ten_missed_cycles() {
    let shared = region();
    let mut client = SplineClient::new(shared.clone()).unwrap();
    let mut daemon = SplineDaemon::new(shared).unwrap();
    client.write_command(&command(0.3)).unwrap();
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Fresh);
    for cycle in 1..10 {
        assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Repeated, "cycle {cycle}");
        assert_eq!(daemon.command().joint(Leg::FrontRight, JointIndex::Abad).p_des.get(), 0.3);
    }
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Cleared);
    assert_eq!(*daemon.command(), SplineCommandBlock::default(), "limp: kp = kd = 0");
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Cleared);
    assert_eq!(daemon.counters().clears, 1);
    client.write_command(&command(0.4)).unwrap();
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Fresh, "a fresh command resumes");
}

#[test]
fn non_finite_commands_are_refused_on_both_sides() {
    let shared = region();
    let mut client = SplineClient::new(shared.clone()).unwrap();
    let mut bad = command(0.1);
    bad.joint_mut(Leg::RearRight, JointIndex::Knee).kd = f32::NAN.into();
    match client.write_command(&bad) {
        Err(SplineError::NonFinite { leg: Leg::RearRight, joint: JointIndex::Knee, field: "kd" }) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(shared.load_u32(COMMAND_FLAG, Ordering::Acquire), Ok(0), "nothing published");
    // A foreign client that writes NaN anyway: the daemon ignores the command.
    use zsl_proto::zerocopy::IntoBytes;
    shared.write(SPLINE_COMMAND.offset, bad.legs.as_bytes()).unwrap();
    shared.store_u32(COMMAND_FLAG, 1, Ordering::Release).unwrap();
    let mut daemon = SplineDaemon::new(shared).unwrap();
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Rejected);
    assert_eq!(*daemon.command(), SplineCommandBlock::default());
}

#[test]
fn a_silent_daemon_is_reported_as_stalled() {
    let shared = region();
    let mut client = SplineClient::new(shared).unwrap().with_stall_after(Duration::from_millis(5));
    match client.wait_state(Duration::from_secs(5)) {
        Err(SplineError::DaemonStalled { stalled_for }) => assert!(stalled_for >= Duration::from_millis(5)),
        other => panic!("{other:?}"),
    }
    assert!(client.is_stalled());
    assert_eq!(client.counters().stalls, 1);
    // While stalled, a call waits for its timeout before saying so again.
    let start = std::time::Instant::now();
    assert!(matches!(client.wait_state(Duration::from_millis(3)), Err(SplineError::DaemonStalled { .. })));
    assert!(start.elapsed() >= Duration::from_millis(3));
    assert_eq!(client.counters().stalls, 1, "one stall, counted once");
}

/// The stall bound on a fake clock: exactly `stall_after` of polling without fresh state.
#[test]
fn the_stall_bound_on_a_fake_clock() {
    use robowire_core::schedule::Time;
    let shared = region();
    let mut client = SplineClient::new(shared.clone()).unwrap(); // default bound: 10 ms
    let mut daemon = SplineDaemon::new(shared).unwrap();
    let t0 = Time::from_nanos(1_000_000_000);
    let us = |n: u64| t0 + Duration::from_micros(n);
    daemon.publish_state(&SplineStateBlock::default()).unwrap();
    assert!(client.poll_state(us(0)).unwrap().is_some(), "fresh");
    assert_eq!(client.poll_state(us(500)).unwrap(), None, "the stall clock starts at this poll");
    assert_eq!(client.poll_state(us(10_499)).unwrap(), None, "not yet");
    assert!(!client.is_stalled_at(us(10_499)) && client.is_stalled_at(us(10_500)));
    match client.poll_state(us(10_500)) {
        Err(SplineError::DaemonStalled { stalled_for }) => assert_eq!(stalled_for, Duration::from_millis(10)),
        other => panic!("{other:?}"),
    }
    assert_eq!(client.poll_state(us(20_000)).unwrap(), None, "reported once per stall");
    assert_eq!(client.counters().stalls, 1);
    daemon.publish_state(&SplineStateBlock::default()).unwrap();
    assert!(client.poll_state(us(30_000)).unwrap().is_some(), "the daemon is back");
    assert!(!client.is_stalled_at(us(30_000)));
    assert_eq!(client.poll_state(us(30_001)).unwrap(), None);
    assert!(matches!(client.poll_state(us(40_001)), Err(SplineError::DaemonStalled { .. })), "a second stall");
    assert_eq!(client.counters().stalls, 2);
}

#[test]
fn regions_too_small_are_refused() {
    assert!(SplineClient::new(HeapRegion::new(SPLINE_DATA_LEN - 4)).is_err());
    assert!(ImuReader::new(HeapRegion::new(40)).is_err());
}

#[test]
fn imu_writer_racing_the_reader_never_yields_a_torn_sample() {
    let shared = region();
    let mut reader = ImuReader::new(shared.clone()).unwrap().with_max_attempts(100);
    assert!(matches!(reader.read(), Err(ImuError::NoSample)));
    let stop = Arc::new(AtomicBool::new(false));
    let writer = {
        let (shared, stop) = (shared.clone(), stop.clone());
        std::thread::spawn(move || {
            let mut writer = ImuWriter::new(shared).unwrap();
            let mut k = 1u64;
            while !stop.load(Ordering::Relaxed) {
                let v = k as f32;
                let sample = NavImuSample { acc: [v.into(); 3], gyro: [v.into(); 3], q: [v.into(); 4] };
                writer.publish(&NavImu { timestamp_ns: k.into(), sample }).unwrap();
                k += 1;
            }
            k
        })
    };
    let reads = if cfg!(miri) { 50 } else { 20_000 };
    let mut consistent = 0;
    for _ in 0..reads {
        match reader.read() {
            Ok(sample) => {
                let v = sample.timestamp_ns as f32;
                assert!(
                    sample.acc_mps2.iter().chain(&sample.gyro_radps).chain(&sample.quaternion_wxyz).all(|&x| x == v),
                    "torn sample {sample:?}"
                );
                consistent += 1;
            }
            Err(ImuError::NoSample | ImuError::Torn { .. }) => {}
            Err(other) => panic!("{other}"),
        }
    }
    stop.store(true, Ordering::Relaxed);
    let written = writer.join().unwrap();
    assert!(consistent > 0 && written > 1, "the race happened: {consistent} reads, {written} writes");
}

/// Every frame in `ring`, oldest first: (direction, bytes).
fn tapped(ring: &robowire_tap::TapRing) -> Vec<(robowire_tap::Direction, Vec<u8>)> {
    std::iter::from_fn(|| ring.pop(|f| (f.direction, f.bytes().to_vec()))).collect()
}

#[test]
fn taps_record_each_side_byte_for_byte_both_ways() {
    use robowire_core::json::LinkDescription;
    use robowire_tap::{Direction, TapRing};
    use zsl_proto::description::{IMU, SPLINE_CLIENT, SPLINE_DAEMON};
    use zsl_proto::zerocopy::IntoBytes;

    let shared = region();
    let (client_ring, daemon_ring) = (TapRing::with_slots(16), TapRing::with_slots(16));
    let mut client = SplineClient::new(shared.clone()).unwrap().with_tap(client_ring.tap(0));
    let mut daemon = SplineDaemon::new(shared.clone()).unwrap().with_tap(daemon_ring.tap(0));
    let mut cmd = command(0.5);
    cmd.legs[1].flags = 7.into();
    client.write_command(&cmd).unwrap();
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Fresh);
    assert_eq!(daemon.take_command().unwrap(), CommandUpdate::Repeated, "nothing fresh: nothing recorded");
    let mut state = SplineStateBlock::default();
    state.joint_mut(Leg::RearRight, JointIndex::Knee).p = (-1.5).into();
    state.joint_mut(Leg::RearRight, JointIndex::Knee).flags = 0x0030_4101.into();
    daemon.publish_state(&state).unwrap();
    assert!(client.try_read_state().unwrap().is_some());
    assert_eq!(client.try_read_state().unwrap(), None, "nothing fresh: nothing recorded");
    // A refused command never reached the region: not recorded.
    let mut bad = command(0.1);
    bad.joint_mut(Leg::FrontRight, JointIndex::Hip).kd = f32::NAN.into();
    assert!(client.write_command(&bad).is_err());

    // What went through the region, as published (leg flags written as 1) and as taken.
    let sent = cmd.normalized().legs.as_bytes().to_vec();
    let states = state.legs.as_bytes().to_vec();
    assert_eq!(tapped(&client_ring), [(Direction::Sent, sent.clone()), (Direction::Received, states.clone())]);
    assert_eq!(tapped(&daemon_ring), [(Direction::Received, sent.clone()), (Direction::Sent, states.clone())]);
    let command_json = SPLINE_CLIENT.decode(Direction::Sent, &sent).unwrap().value;
    assert_eq!(command_json, SPLINE_DAEMON.decode(Direction::Received, &sent).unwrap().value);
    assert_eq!(command_json["FL"]["flags"], 1);
    let state_json = SPLINE_CLIENT.decode(Direction::Received, &states).unwrap().value;
    assert_eq!(
        (&state_json["RR"]["knee"]["p_rad"], &state_json["RR"]["knee"]["temperature_c"]),
        (&(-1.5).into(), &25.into())
    );

    // The IMU: the record as published and as read, timestamp first.
    let imu_region = Arc::new(HeapRegion::new(1024));
    let (writer_ring, reader_ring) = (TapRing::with_slots(4), TapRing::with_slots(4));
    let mut writer = ImuWriter::new(imu_region.clone()).unwrap().with_tap(writer_ring.tap(0));
    let mut reader = ImuReader::new(imu_region).unwrap().with_tap(reader_ring.tap(0));
    assert!(matches!(reader.read(), Err(ImuError::NoSample)), "no sample: nothing recorded");
    let record = NavImu {
        timestamp_ns: 123_456_789.into(),
        sample: NavImuSample {
            acc: [0.25, -0.5, 9.75].map(Into::into),
            gyro: [0.0; 3].map(Into::into),
            q: [1.0, 0.0, 0.0, 0.0].map(Into::into),
        },
    };
    writer.publish(&record).unwrap();
    assert_eq!(reader.read().unwrap().timestamp_ns, 123_456_789);
    assert_eq!(tapped(&writer_ring), [(Direction::Sent, record.as_bytes().to_vec())]);
    assert_eq!(tapped(&reader_ring), [(Direction::Received, record.as_bytes().to_vec())]);
    let imu_json = IMU.decode(Direction::Received, record.as_bytes()).unwrap().value;
    assert_eq!((&imu_json["timestamp_ns"], &imu_json["acc_mps2"][2]), (&123_456_789.into(), &9.75.into()));
}
