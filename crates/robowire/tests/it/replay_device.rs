//! `robowire replay --as-device` on the demo's KMC, Go2 and spline captures: a live client (the
//! `kmc` driver on the replay's pseudo-terminal, the `go2` low-level client on DDS in a private
//! network, a spline client and IMU reader on the replay's shared memory) goes through the
//! recorded states, in order; and what it cannot play is a clear error (exit code 1), never a
//! panic.

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::wait::runtime;
use robowire_record::{Direction, RecordedFrame};

use crate::support::{Running, one_demo_at_a_time, robowire};

/// Generous: a state not seen within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(30);

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("robowire-replay-device-{}-{name}", std::process::id()))
}

/// `robowire demo --only DEVICE --duration 1 --record CAPTURE`, and the capture's frames.
fn record_demo(device: &str, capture: &Path) -> Vec<RecordedFrame> {
    let one_at_a_time = one_demo_at_a_time();
    let demo =
        robowire().args(["demo", "--only", device, "--duration", "1", "--record"]).arg(capture).output().unwrap();
    drop(one_at_a_time);
    // Only the capture matters here: a demo check that fails on a busy machine (a lateness
    // bound) still leaves a whole capture, which is what is replayed.
    let stderr = String::from_utf8_lossy(&demo.stderr);
    assert!(stderr.contains("record:") && stderr.contains(" 0 dropped"), "{stderr}");
    if !demo.status.success() {
        eprintln!("the demo's checks failed; its capture is used:\n{}", String::from_utf8_lossy(&demo.stdout));
    }
    let descriptions = [
        &kmc_proto::description::DESCRIPTIONS[..],
        &unitree_proto::description::DESCRIPTIONS,
        &zsl_proto::description::DESCRIPTIONS,
        &[&robowire_core::json::SKIPPED_BYTES],
    ]
    .concat();
    robowire_record::read_frames(&std::fs::read(capture).unwrap(), &descriptions).unwrap()
}

#[test]
fn a_live_kmc_driver_goes_through_the_recorded_chassis_frames() {
    use kmc::{ChassisFrame, Device, Driver, DriverOptions};
    let capture = temp("kmc.mcap");
    let frames = record_demo("kmc", &capture);
    // Recorded at the host: what it received is what the chassis sent.
    let recorded: Vec<ChassisFrame> = frames
        .iter()
        .filter(|f| f.link == "kmc/serial" && f.direction == Direction::Received)
        .map(|f| ChassisFrame::parse(&f.bytes).unwrap())
        .collect();
    let speeds = |frames: &[ChassisFrame]| -> Vec<f32> {
        frames
            .iter()
            .filter_map(|f| if let ChassisFrame::VehicleSpeed(v) = f { Some(v.speed_mps) } else { None })
            .collect()
    };
    let recorded_speeds = speeds(&recorded);
    assert!(
        recorded_speeds.iter().any(|v| *v > 0.3) && recorded_speeds.iter().any(|v| *v < -0.1),
        "{recorded_speeds:?}"
    );
    assert!(recorded.iter().any(|f| matches!(f, ChassisFrame::BatteryVoltage(_))));
    assert!(recorded.iter().any(|f| matches!(f, ChassisFrame::AllState(_))));

    let replay = Running::spawn(robowire().args(["replay", "--as-device"]).arg(&capture).stderr(Stdio::piped()));
    assert!(replay.first_line.starts_with("/dev/pts/"), "the pty's path first: {}", replay.first_line);
    let driver = Driver::open(&replay.first_line, DriverOptions::default()).unwrap();
    let mut every = driver.every_state();
    let seen = runtime().block_on(async {
        let mut seen = Vec::new();
        while seen.len() < recorded.len() {
            match tokio::time::timeout(WAIT, every.recv()).await {
                Ok(Ok(state)) => seen.extend(state.state.last_frame),
                other => panic!("after {} of {} frames: {other:?}", seen.len(), recorded.len()),
            }
        }
        seen
    });
    let received = driver.stats().frames_received;
    let out = replay.wait();
    drop(driver);
    assert!(out.status.success(), "{}", out.stderr);
    assert_eq!(seen, recorded, "every recorded chassis frame, in order");
    assert_eq!(speeds(&seen), recorded_speeds, "the speeds the chassis reported, in order");
    assert_eq!(received, recorded.len() as u64, "the driver counted as many frames as were recorded");
    let n = recorded.len();
    assert!(out.stderr.contains(&format!("wrote {n} of {n} chassis frames")), "{}", out.stderr);
    let _ = std::fs::remove_file(capture);
}

#[test]
fn a_live_spline_client_takes_the_recorded_daemon_states() {
    use zsl::spline::{ImuReader, SplineClient};
    use zsl_proto::shm::SplineCommandBlock;
    use zsl_proto::zerocopy::IntoBytes;
    let capture = temp("spline.mcap");
    let frames = record_demo("spline", &capture);
    // Recorded at the motion controller: the states it took, the IMU samples it read.
    let recorded: Vec<&[u8]> = frames
        .iter()
        .filter(|f| f.link == "spline/spline" && f.direction == Direction::Received)
        .map(|f| f.bytes.as_slice())
        .collect();
    let last_imu = frames.iter().rev().find(|f| f.link == "spline/imu").map(|f| f.bytes.clone()).unwrap();
    assert!(recorded.len() > 500, "{} states", recorded.len());

    let pid = std::process::id();
    let (spline, imu) = (format!("/robowire-replay-{pid}-spline"), format!("/robowire-replay-{pid}-imu"));
    let replay = Running::spawn(
        robowire()
            .args(["replay", "--as-device", "--speed", "0.5", "--spline-name", &spline, "--imu-name", &imu])
            .arg(&capture)
            .stderr(Stdio::piped()),
    );
    assert_eq!(replay.first_line, format!("{spline} {imu}"));
    let mut client = SplineClient::open(&spline).unwrap();
    // Mapped now: the objects go when the player ends.
    let mut imu_reader = ImuReader::open(&imu).unwrap();
    client.write_command(&SplineCommandBlock::default()).unwrap();
    // Every state taken until the last recorded one comes (the handshake keeps the newest: a
    // client that looks late skips states, as it would on the robot).
    let began = std::time::Instant::now();
    let mut seen: Vec<Vec<u8>> = Vec::new();
    while seen.last().map(Vec::as_slice) != recorded.last().copied() {
        assert!(began.elapsed() < WAIT, "after {} states, not the last recorded one", seen.len());
        if let Some(state) = client.try_read_state().unwrap() {
            seen.push(state.legs.as_bytes().to_vec());
            client.write_command(&SplineCommandBlock::default()).unwrap();
        }
        std::hint::spin_loop();
    }
    let out = replay.wait();
    assert!(out.status.success(), "{}", out.stderr);
    // In the recorded order: each state seen is a recorded one, after the one seen before; but
    // for a copy torn by the next state (the vendor's handshake lets the daemon write while the
    // controller copies, as a busy machine's scheduler can arrange), at most 1 % of them.
    let (mut at, mut torn) = (0, 0);
    for state in &seen {
        match recorded[at..].iter().position(|r| *r == state.as_slice()) {
            Some(i) => at += i + 1,
            None => torn += 1,
        }
    }
    assert!(torn * 100 <= seen.len(), "{torn} of {} states not recorded ones in order", seen.len());
    assert!(seen.len() * 2 > recorded.len(), "most states taken: {} of {}", seen.len(), recorded.len());
    let sample = imu_reader.read().unwrap();
    assert_eq!(sample.timestamp_ns.to_le_bytes(), last_imu[..8], "the last IMU record, as recorded");
    assert!(out.stderr.contains("published") && out.stderr.contains("commands"), "{}", out.stderr);
    let _ = std::fs::remove_file(capture);
}

#[test]
fn a_live_go2_client_receives_the_recorded_lowstates() {
    with_loopback_multicast(check_go2_replay);
}

fn check_go2_replay() {
    use robowire_dds::qos::Qos;
    use unitree::{Device, Go2, LowLevel, LowLevelOptions, LowState};
    use unitree_proto::Message;
    let capture = temp("go2.mcap");
    let frames = record_demo("go2", &capture);
    // Recorded at the client: the LowStates it received, the demo's bit flips among them.
    let payloads: Vec<&[u8]> = frames
        .iter()
        .filter(|f| f.link == "go2/low_level" && f.direction == Direction::Received)
        .map(|f| &f.bytes[..])
        .collect();
    // The ticks of those whose CRC holds, as the client will check it.
    let recorded: Vec<u32> =
        payloads.iter().filter_map(|p| LowState::decode_cdr(p).ok()).map(|(s, _)| s.tick.get()).collect();
    let broken = (payloads.len() - recorded.len()) as u64;
    assert!(recorded.len() > 100 && broken > 0, "{} good, {broken} broken", recorded.len());

    // The Go2 client (Unitree's QoS: best effort, keep last 1), at a quarter of the recorded
    // pace: its reader keeps the newest sample only, so a receive thread held up for a whole
    // period on a busy machine misses one, as it would from the robot.
    let (seen, stats) = runtime().block_on(async {
        let client = LowLevel::<Go2>::open(LowLevelOptions::on(Some("lo"), 0)).unwrap();
        let mut every = client.every_state();
        let replay = Running::spawn(
            robowire()
                .args(["replay", "--as-device", "--interface", "lo", "--speed", "0.25"])
                .arg(&capture)
                .stderr(Stdio::piped()),
        );
        assert_eq!(replay.first_line, "go2 domain 0 lo");
        let mut seen = Vec::new();
        while seen.last() != recorded.last() {
            match tokio::time::timeout(WAIT, every.recv()).await {
                Ok(Ok(state)) => seen.push(state.state.tick.get()),
                _ => break,
            }
        }
        let stats = client.stats();
        client.close();
        let out = replay.wait();
        assert!(out.status.success(), "{}", out.stderr);
        let n = payloads.len();
        assert!(out.stderr.contains(&format!("published {n} of {n} LowStates")), "{}", out.stderr);
        (seen, stats)
    });
    // Through the recorded states in order, each CRC checked, the broken ones refused; what it
    // missed is said, and may be a few.
    let mut rest = recorded.iter();
    assert!(seen.iter().all(|t| rest.any(|r| r == t)), "the recorded ticks in order: {seen:?}");
    assert_eq!(seen.last(), recorded.last(), "through to the last state");
    let missed: Vec<_> = recorded.iter().filter(|t| !seen.contains(t)).collect();
    assert!(missed.len() * 50 <= recorded.len(), "missed {missed:?} of {}: {stats:?}", recorded.len());
    assert_eq!(stats.lowstate.samples, seen.len() as u64, "{stats:?}");
    assert!(stats.lowstate.checksum_errors <= broken && stats.lowstate.checksum_errors > 0, "{stats:?}");
    assert_eq!(stats.lowstate.decode_errors, 0);

    // Played as fast as possible to a reliable reader that keeps every sample: every payload,
    // in order, byte for byte (the encapsulation header, the body, the CRC: the broken ones
    // still broken).
    let raw = runtime().block_on(async {
        let participant = robowire_dds::Participant::new(unitree::ParticipantOptions::new(0, Some("lo"))).unwrap();
        let reliable = Qos { reliable: true, depth: 1024, ..Qos::READER };
        let mut reader = participant.raw_reader(LowState::TOPIC, LowState::DDS_TYPE_NAME, reliable).unwrap();
        let replay = Running::spawn(
            robowire()
                .args(["replay", "--as-device", "--interface", "lo", "--fast"])
                .arg(&capture)
                .stderr(Stdio::null()),
        );
        let mut raw = Vec::new();
        while raw.len() < payloads.len() {
            match tokio::time::timeout(WAIT, reader.recv()).await {
                Ok(Ok(sample)) => raw.push(sample.value),
                _ => break,
            }
        }
        assert!(replay.wait().status.success());
        raw
    });
    assert_eq!(raw.len(), payloads.len(), "as many LowStates as recorded");
    for (sample, payload) in raw.iter().zip(&payloads) {
        assert_eq!((sample.encoding.header(), &sample.body[..]), (payload[..4].try_into().unwrap(), &payload[4..]));
    }
    eprintln!("the Go2 client took {} of {} LowStates; missed {missed:?}", seen.len(), recorded.len());
    let _ = std::fs::remove_file(capture);
}

/// `robowire replay --as-device ARGS FILE`: it must fail with exit code 1 and a message that
/// contains every one of `expected`.
fn refused(file: &Path, args: &[&str], expected: &[&str]) {
    let out = robowire().args(["replay", "--as-device"]).args(args).arg(file).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "a clean error: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for e in expected {
        assert!(err.contains(e), "{e:?} in {err}");
    }
    assert!(out.stdout.is_empty(), "nothing played: {}", String::from_utf8_lossy(&out.stdout));
}

#[test]
fn what_cannot_be_played_is_a_clear_error() {
    // A host's commands, the line's noise and a service call: no device frame among them.
    let capture = temp("no-device.mcap");
    let recorder = robowire_record::Recorder::create(&capture, "a test").unwrap();
    let serial = recorder.link("kmc/serial", &kmc_proto::description::HOST);
    serial.record(Direction::Sent, &[0xb3]);
    serial.record(Direction::Sent, &[0xa5, 0, 0, 0, 0, 0, 0, 0, 0]);
    recorder.link("kmc/serial_skipped", &robowire_core::json::SKIPPED_BYTES).record(Direction::Received, &[0x42]);
    recorder.link("go2/api", &unitree_proto::description::API_CLIENT).record(Direction::Sent, &[0, 1, 0, 0]);
    recorder.finish().unwrap();

    let found = ["kmc/serial (kmc.host, 2 frames)", "kmc/serial_skipped (stream.skipped, 1 frames)", "go2/api"];
    refused(&capture, &[], &[&["no device frames to play"][..], &found].concat());
    refused(
        &capture,
        &["--link", "kmc/serial"],
        &[&["link kmc/serial (kmc.host) has no device frames"][..], &found].concat(),
    );
    refused(&capture, &["--link", "zsl1/high_level"], &[&["no link \"zsl1/high_level\""][..], &found].concat());
    refused(&capture, &["--link", "go2/api"], &["link go2/api is unitree_api.client, which has no device side"]);

    let bytes = std::fs::read(&capture).unwrap();
    let cut = temp("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    refused(&cut, &[], &["corrupt capture at byte", "expected"]);
    for f in [capture, cut] {
        let _ = std::fs::remove_file(f);
    }
}
