//! The serial link on pseudo-terminals, against the chassis simulator.

use std::time::{Duration, Instant};

use kmc_proto::{AfFrame, ChassisFrame, ChassisFrameDecoder, HostFrame, MAX_FRAME_LEN};
use robowire_serial::{Backoff, SerialError, SerialLink, SerialPortOptions};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig, Fault};

/// Every test bounds its own waiting, so a broken link fails the test instead of hanging it.
const WATCHDOG: Duration = Duration::from_secs(5);

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap()
}

async fn send(link: &mut SerialLink<ChassisFrameDecoder>, frame: HostFrame) {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = frame.emit(&mut buf).unwrap();
    link.send(&buf[..n]).await.unwrap();
}

#[test]
fn requests_and_responses_with_noise_on_the_line() {
    runtime().block_on(async {
        let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
        let mut link = SerialLink::open(sim.path(), &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
        sim.inject(Fault::Garbage { bytes: 37 });
        send(&mut link, HostFrame::VehicleSpeedRequest).await;
        send(&mut link, HostFrame::Af(AfFrame::battery_read(0))).await;
        send(&mut link, HostFrame::Af(AfFrame::all_state_read(1))).await;
        let mut got = Vec::new();
        for _ in 0..3 {
            got.push(tokio::time::timeout(WATCHDOG, link.recv()).await.expect("response").unwrap());
        }
        assert!(matches!(got[0], ChassisFrame::VehicleSpeed(_)));
        assert!(matches!(got[1], ChassisFrame::BatteryVoltage(b) if b.motor_id == 0 && b.volts > 20.0));
        assert!(matches!(got[2], ChassisFrame::AllState(s) if s.motor_id == 1 && s.id == 2));
        let counters = link.counters();
        assert_eq!(counters.decoder.skipped_bytes, 37, "the garbage was skipped and counted");
        assert_eq!(counters.frames_written, 3);
        assert_eq!(counters.bytes_written, 1 + 5 + 5);
        assert_eq!(counters.bytes_read, 37 + 5 + 9 + 49);
        assert_eq!(sim.stats().speed_requests, 1);
        assert_eq!(sim.stats().af_reads, 2);
    });
}

#[test]
fn hang_up_is_reported_promptly_and_without_spinning() {
    runtime().block_on(async {
        let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
        let mut link = SerialLink::open(sim.path(), &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
        let receiving = tokio::spawn(async move {
            let result = tokio::time::timeout(WATCHDOG, link.recv()).await;
            (result, Instant::now(), link)
        });
        tokio::time::sleep(Duration::from_millis(50)).await;
        let hung_up_at = Instant::now();
        sim.inject(Fault::HangUp);
        let (result, noticed_at, mut link) = receiving.await.unwrap();
        let err = result.expect("recv returned before the watchdog").unwrap_err();
        assert!(matches!(err, SerialError::Disconnected { .. }), "{err}");
        let latency = noticed_at - hung_up_at;
        // The simulator acts on the fault within its 5 ms poll; the link must follow at once.
        assert!(latency < Duration::from_millis(100), "disconnect noticed after {latency:?}");
        assert!(!link.is_open());
        // Later calls fail at once instead of spinning on a dead descriptor.
        let again = tokio::time::timeout(Duration::from_millis(100), link.recv()).await.expect("immediate");
        assert!(matches!(again, Err(SerialError::Disconnected { .. })));
        let mut buf = [0u8; 1];
        let n = HostFrame::VehicleSpeedRequest.emit(&mut buf).unwrap();
        assert!(matches!(link.send(&buf[..n]).await, Err(SerialError::Disconnected { .. })));
    });
}

#[test]
fn reopen_after_replug_at_a_stable_path() {
    runtime().block_on(async {
        let link_path = std::env::temp_dir().join(format!("robowire-serial-test-{}", std::process::id()));
        let sim = ChassisSim::spawn(ChassisSimConfig { link: Some(link_path.clone()), ..Default::default() }).unwrap();
        let mut link = SerialLink::open(&link_path, &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
        sim.inject(Fault::HangUp);
        let err = tokio::time::timeout(WATCHDOG, link.recv()).await.expect("disconnect").unwrap_err();
        assert!(matches!(err, SerialError::Disconnected { .. }));

        // Nothing to reopen yet: a bounded backoff gives up with the open error.
        std::fs::remove_file(&link_path).unwrap();
        let quick =
            Backoff { initial: Duration::from_millis(5), max: Duration::from_millis(10), max_attempts: Some(3) };
        let gave_up = link.reopen(&quick).await.unwrap_err();
        assert!(matches!(gave_up, SerialError::ReopenFailed { attempts: 3, .. }), "{gave_up}");

        // Plugged back in while the link retries.
        let replug = async {
            tokio::time::sleep(Duration::from_millis(30)).await;
            sim.replug().unwrap();
        };
        let patient = Backoff { initial: Duration::from_millis(5), ..Backoff::default() };
        let (reopened, ()) = tokio::join!(tokio::time::timeout(WATCHDOG, link.reopen(&patient)), replug);
        reopened.expect("reopened in time").unwrap();
        assert_eq!(link.counters().reopens, 1);
        send(&mut link, HostFrame::VehicleSpeedRequest).await;
        let frame = tokio::time::timeout(WATCHDOG, link.recv()).await.expect("response").unwrap();
        assert!(matches!(frame, ChassisFrame::VehicleSpeed(_)));
    });
}

#[test]
fn open_error_names_the_path() {
    runtime().block_on(async {
        let err =
            SerialLink::open("/dev/robowire-no-such-port", &SerialPortOptions::default(), ChassisFrameDecoder::new())
                .unwrap_err();
        let text = err.to_string();
        assert!(text.contains("/dev/robowire-no-such-port"), "{text}");
        assert!(matches!(err, SerialError::Open { .. }));
    });
}
