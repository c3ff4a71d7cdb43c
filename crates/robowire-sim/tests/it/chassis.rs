//! The chassis simulator from the host end of the serial transport, as a driver sees it:
//! requests answered, faults injected on the line, an unplugged and re-plugged adapter.

use std::time::Duration;

use kmc_proto::{AfFrame, ChassisFrame, ChassisFrameDecoder, HostFrame, MAX_FRAME_LEN, PcControl};
use robowire_fixtures::wait::runtime;
use robowire_serial::{Backoff, SerialError, SerialLink, SerialPortOptions};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig, Fault};

use crate::hammer;

/// Every wait is bounded, so a broken simulator fails the test instead of hanging it.
const WATCHDOG: Duration = Duration::from_secs(5);

async fn send(link: &mut SerialLink<ChassisFrameDecoder>, frame: HostFrame) {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = frame.emit(&mut buf).unwrap();
    link.send(&buf[..n]).await.unwrap();
}

async fn recv(link: &mut SerialLink<ChassisFrameDecoder>) -> ChassisFrame {
    tokio::time::timeout(WATCHDOG, link.recv()).await.expect("an answer in time").unwrap()
}

#[test]
fn answers_requests_and_injects_noise_and_lost_replies() {
    runtime().block_on(async {
        let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
        let mut link = SerialLink::open(sim.path(), &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
        sim.inject(Fault::Garbage { bytes: 37 });
        send(&mut link, HostFrame::VehicleSpeedRequest).await;
        send(&mut link, HostFrame::Af(AfFrame::battery_read(0))).await;
        send(&mut link, HostFrame::Af(AfFrame::all_state_read(1))).await;
        assert!(matches!(recv(&mut link).await, ChassisFrame::VehicleSpeed(_)));
        assert!(matches!(recv(&mut link).await, ChassisFrame::BatteryVoltage(b) if b.motor_id == 0 && b.volts > 20.0));
        assert!(matches!(recv(&mut link).await, ChassisFrame::AllState(s) if s.motor_id == 1 && s.id == 2));
        assert_eq!(link.counters().decoder.skipped_bytes, 37, "the garbage was skipped and counted");

        // A lost reply: the next request is answered again.
        sim.inject(Fault::DropResponses { count: 1 });
        send(&mut link, HostFrame::VehicleSpeedRequest).await;
        send(&mut link, HostFrame::Af(AfFrame::battery_read(0))).await;
        assert!(matches!(recv(&mut link).await, ChassisFrame::BatteryVoltage(_)), "the speed answer was dropped");
        let stats = sim.stats();
        assert_eq!((stats.speed_requests, stats.af_reads, stats.responses_dropped), (2, 3, 1));
        assert_eq!(stats.decoder.frames, 5, "every request decoded by the device end");
    });
}

#[test]
fn a_command_drives_the_model_and_the_watchdog_stops_it() {
    runtime().block_on(async {
        let config = ChassisSimConfig { command_watchdog: Some(Duration::from_millis(100)), ..Default::default() };
        let sim = ChassisSim::spawn(config).unwrap();
        let mut link = SerialLink::open(sim.path(), &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
        send(&mut link, HostFrame::PcControl(PcControl { velocity_mps: 0.5, curvature_per_m: 0.0 })).await;
        // No further commands: the chassis's own watchdog stops the wheels.
        let stopped = async {
            while sim.stats().watchdog_stops == 0 {
                tokio::time::sleep(Duration::from_millis(5)).await;
            }
        };
        tokio::time::timeout(WATCHDOG, stopped).await.expect("the chassis watchdog fires");
        assert_eq!(sim.state().commanded_velocity_mps, 0.0);
        assert_eq!(sim.received().len(), 1);
    });
}

#[test]
fn an_unplugged_adapter_is_seen_and_a_replug_reopened_at_the_stable_path() {
    runtime().block_on(async {
        let link_path = std::env::temp_dir().join(format!("robowire-sim-chassis-{}", std::process::id()));
        let sim = ChassisSim::spawn(ChassisSimConfig { link: Some(link_path.clone()), ..Default::default() }).unwrap();
        let mut link = SerialLink::open(&link_path, &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
        sim.inject(Fault::HangUp);
        let err = tokio::time::timeout(WATCHDOG, link.recv()).await.expect("disconnect in time").unwrap_err();
        assert!(matches!(err, SerialError::Disconnected { .. }), "{err}");
        let new_pty = sim.replug().unwrap();
        let patient = Backoff { initial: Duration::from_millis(5), ..Backoff::default() };
        tokio::time::timeout(WATCHDOG, link.reopen(&patient)).await.expect("reopened in time").unwrap();
        assert_eq!(std::fs::read_link(&link_path).unwrap(), new_pty, "the stable path follows the new line");
        send(&mut link, HostFrame::VehicleSpeedRequest).await;
        assert!(matches!(recv(&mut link).await, ChassisFrame::VehicleSpeed(_)));
        assert_eq!(sim.stats().hang_ups, 1);
        drop(sim);
        assert!(!link_path.exists(), "the simulator removes its symlink");
    });
}

#[test]
fn requests_are_answered_while_the_api_is_hammered() {
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    let api = || {
        let _ = (sim.stats(), sim.state(), sim.received().len(), sim.pty_path());
        // Faults that change nothing, through the same hand-over as any other.
        sim.inject(Fault::Garbage { bytes: 0 });
        sim.inject(Fault::DropResponses { count: 0 });
    };
    hammer::while_hammering(api, || {
        runtime().block_on(async {
            let mut link =
                SerialLink::open(sim.path(), &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
            for _ in 0..200 {
                send(&mut link, HostFrame::VehicleSpeedRequest).await;
                assert!(matches!(recv(&mut link).await, ChassisFrame::VehicleSpeed(_)));
            }
        });
    });
    let stats = sim.stats();
    assert_eq!((stats.speed_requests, stats.responses_sent, stats.responses_dropped), (200, 200, 0), "{stats:?}");
    assert_eq!(sim.received().len(), 200);
}

/// Every frame in `ring`, oldest first: (link, direction, bytes).
fn tapped(ring: &robowire_tap::TapRing) -> Vec<(u16, robowire_tap::Direction, Vec<u8>)> {
    std::iter::from_fn(|| ring.pop(|f| (f.link, f.direction, f.bytes().to_vec()))).collect()
}

#[test]
fn taps_record_the_line_at_both_ends_byte_for_byte() {
    use robowire_core::json::{LinkDescription, SKIPPED_BYTES};
    use robowire_serial::SerialTaps;
    use robowire_tap::{Direction, TapRing};
    let (host_ring, chassis_ring) = (TapRing::with_slots(64), TapRing::with_slots(64));
    let taps = |ring: &TapRing| SerialTaps { frames: Some(ring.tap(0)), skipped: Some(ring.tap(1)) };
    runtime().block_on(async {
        let sim = ChassisSim::spawn(ChassisSimConfig { taps: taps(&chassis_ring), ..Default::default() }).unwrap();
        let mut link = SerialLink::open(sim.path(), &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
        link.set_taps(taps(&host_ring));
        let requests = [
            HostFrame::PcControl(PcControl { velocity_mps: 0.25, curvature_per_m: 0.5 }),
            HostFrame::VehicleSpeedRequest,
            HostFrame::Af(AfFrame::battery_read(1)),
        ];
        let mut sent = Vec::new();
        // Line noise the chassis's decoder must skip (no frame start among it).
        let noise = [0x01, 0x02, 0x7e];
        link.send(&noise).await.unwrap();
        for request in requests {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let n = request.emit(&mut buf).unwrap();
            link.send(&buf[..n]).await.unwrap();
            sent.push(buf[..n].to_vec());
        }
        sim.inject(Fault::Garbage { bytes: 5 });
        send(&mut link, HostFrame::Af(AfFrame::all_state_read(0))).await;
        for _ in 0..3 {
            recv(&mut link).await;
        }
        drop(link);
        drop(sim);

        let host = tapped(&host_ring);
        let chassis = tapped(&chassis_ring);
        let of = |frames: &[(u16, Direction, Vec<u8>)], link, direction| -> Vec<Vec<u8>> {
            frames.iter().filter(|f| (f.0, f.1) == (link, direction)).map(|f| f.2.clone()).collect()
        };
        // What the host wrote, the chassis decoded, frame by frame; the noise it skipped.
        let host_sent = of(&host, 0, Direction::Sent);
        assert_eq!(host_sent[0], noise, "the host's own write, as it was");
        assert_eq!(of(&chassis, 0, Direction::Received), host_sent[1..].to_vec());
        assert_eq!(of(&chassis, 0, Direction::Received)[..3], sent[..]);
        assert_eq!(of(&chassis, 1, Direction::Received).concat(), noise);
        // What the chassis wrote (speed, battery, all-state), the host decoded; the garbage in
        // front of it is only the host's skipped bytes.
        let answers = of(&chassis, 0, Direction::Sent);
        assert_eq!(answers.len(), 3);
        assert_eq!(of(&host, 0, Direction::Received), answers);
        assert_eq!(of(&host, 1, Direction::Received).concat().len(), 5);
        assert!(of(&chassis, 1, Direction::Sent).is_empty() && of(&host, 1, Direction::Sent).is_empty());
        for (link, direction, bytes) in &chassis {
            let description: &dyn LinkDescription =
                if *link == 0 { &kmc_proto::description::CHASSIS } else { &SKIPPED_BYTES };
            description.decode(*direction, bytes).unwrap_or_else(|e| panic!("{direction:?} {bytes:02x?}: {e}"));
        }
        assert_eq!(host_ring.counters().dropped() + chassis_ring.counters().dropped(), 0);
    });
}
