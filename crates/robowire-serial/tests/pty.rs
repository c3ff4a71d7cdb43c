//! Both ends of the serial transport on pseudo-terminals: the host's [`SerialLink`] against a
//! [`PtyDevice`] answering like a chassis, with the KMC codec (any stream codec would do).

use std::sync::mpsc;
use std::time::Duration;

use kmc_proto::{
    AfFrame, BatteryVoltage, ChassisFrame, ChassisFrameDecoder, HostFrame, HostFrameDecoder, MAX_FRAME_LEN,
    VehicleSpeed,
};
use robowire_fixtures::wait::runtime;
use robowire_serial::{Backoff, Pty, PtyDevice, SerialError, SerialLink, SerialPortOptions};

/// Every test bounds its own waiting, so a broken link fails the test instead of hanging it.
const WATCHDOG: Duration = Duration::from_secs(5);
const POLL: Duration = Duration::from_millis(5);

fn bytes_of(frame: ChassisFrame) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = frame.emit(&mut buf).unwrap();
    buf[..n].to_vec()
}

async fn send(link: &mut SerialLink<ChassisFrameDecoder>, frame: HostFrame) {
    let mut buf = [0u8; MAX_FRAME_LEN];
    let n = frame.emit(&mut buf).unwrap();
    link.send(&buf[..n]).await.unwrap();
}

/// What the test tells the device thread to do.
enum Do {
    Noise(usize),
    HangUp,
    PlugIn(Pty),
    Stop,
}

/// A device thread: answers a speed request with 1.25 m/s and a battery read with 24.5 V,
/// preceded by pending noise; reports the frames it got and its counters at the end.
fn device(
    mut device: PtyDevice<HostFrameDecoder>,
    orders: mpsc::Receiver<Do>,
) -> std::thread::JoinHandle<(Vec<HostFrame>, robowire_serial::LinkCounters)> {
    std::thread::spawn(move || {
        let mut got = Vec::new();
        let mut noise = 0;
        // Every pending order; `true` on Stop. Called again after a receive: an order sent before
        // the host wrote its request is then in the channel, so noise ordered first goes out first.
        let take_orders = |device: &mut PtyDevice<HostFrameDecoder>, noise: &mut usize| loop {
            match orders.try_recv() {
                Ok(Do::Noise(n)) => *noise += n,
                Ok(Do::HangUp) => device.hang_up(),
                Ok(Do::PlugIn(pty)) => device.plug_in(pty).unwrap(),
                Ok(Do::Stop) | Err(mpsc::TryRecvError::Disconnected) => return true,
                Err(mpsc::TryRecvError::Empty) => return false,
            }
        };
        loop {
            if take_orders(&mut device, &mut noise) {
                return (got, device.counters());
            }
            let mut answers = Vec::new();
            device
                .receive(POLL, |frame| {
                    got.push(frame);
                    match frame {
                        HostFrame::VehicleSpeedRequest => {
                            answers.extend(bytes_of(ChassisFrame::VehicleSpeed(VehicleSpeed { speed_mps: 1.25 })))
                        }
                        HostFrame::Af(af) => answers.extend(bytes_of(ChassisFrame::BatteryVoltage(BatteryVoltage {
                            motor_id: af.motor_id(),
                            volts: 24.5,
                        }))),
                        HostFrame::PcControl(_) => {}
                    }
                })
                .unwrap();
            if !answers.is_empty() {
                if take_orders(&mut device, &mut noise) {
                    return (got, device.counters());
                }
                let mut out = vec![0x11; std::mem::take(&mut noise)];
                out.extend(answers);
                device.send(&out, WATCHDOG).unwrap();
            }
        }
    })
}

type DeviceThread = std::thread::JoinHandle<(Vec<HostFrame>, robowire_serial::LinkCounters)>;

/// A device thread on a new pseudo-terminal (behind `link`, if given) and a host link to it.
fn connect(link: Option<std::path::PathBuf>) -> (SerialLink<ChassisFrameDecoder>, mpsc::Sender<Do>, DeviceThread) {
    let pty = PtyDevice::open(HostFrameDecoder::new, link).unwrap();
    let path = pty.path().to_path_buf();
    let (orders, rx) = mpsc::channel();
    let thread = device(pty, rx);
    let host = SerialLink::open(&path, &SerialPortOptions::default(), ChassisFrameDecoder::new()).unwrap();
    (host, orders, thread)
}

#[test]
fn frames_both_ways_with_noise_on_the_line() {
    runtime().block_on(async {
        let (mut link, orders, thread) = connect(None);
        orders.send(Do::Noise(37)).unwrap();
        send(&mut link, HostFrame::VehicleSpeedRequest).await;
        send(&mut link, HostFrame::Af(AfFrame::battery_read(1))).await;
        let mut got = Vec::new();
        for _ in 0..2 {
            got.push(tokio::time::timeout(WATCHDOG, link.recv()).await.expect("response").unwrap());
        }
        assert_eq!(got[0], ChassisFrame::VehicleSpeed(VehicleSpeed { speed_mps: 1.25 }));
        assert!(matches!(got[1], ChassisFrame::BatteryVoltage(b) if b.motor_id == 1 && b.volts == 24.5));
        let counters = link.counters();
        assert_eq!(counters.decoder.skipped_bytes, 37, "the noise was skipped and counted");
        assert_eq!((counters.frames_written, counters.bytes_written), (2, 1 + 5));
        assert_eq!(counters.bytes_read, 37 + 5 + 9);
        orders.send(Do::Stop).unwrap();
        let (frames, device_counters) = thread.join().unwrap();
        assert_eq!(frames, [HostFrame::VehicleSpeedRequest, HostFrame::Af(AfFrame::battery_read(1))]);
        assert_eq!((device_counters.decoder.frames, device_counters.bytes_read), (2, 6));
    });
}

#[test]
fn hang_up_is_reported_at_once_and_without_spinning() {
    runtime().block_on(async {
        let (mut link, orders, thread) = connect(None);
        orders.send(Do::HangUp).unwrap();
        let err = tokio::time::timeout(WATCHDOG, link.recv()).await.expect("recv returns before the watchdog");
        assert!(matches!(err, Err(SerialError::Disconnected { .. })), "{err:?}");
        assert!(!link.is_open());
        // Later calls fail at once instead of spinning on a dead descriptor.
        let again = tokio::time::timeout(WATCHDOG, link.recv()).await.expect("immediate");
        assert!(matches!(again, Err(SerialError::Disconnected { .. })));
        let mut buf = [0u8; 1];
        let n = HostFrame::VehicleSpeedRequest.emit(&mut buf).unwrap();
        assert!(matches!(link.send(&buf[..n]).await, Err(SerialError::Disconnected { .. })));
        orders.send(Do::Stop).unwrap();
        thread.join().unwrap();
    });
}

#[test]
fn reopen_after_replug_at_a_stable_path() {
    runtime().block_on(async {
        let link_path = std::env::temp_dir().join(format!("robowire-serial-test-{}", std::process::id()));
        let (mut link, orders, thread) = connect(Some(link_path.clone()));
        assert_eq!(link.path(), link_path);
        orders.send(Do::HangUp).unwrap();
        let err = tokio::time::timeout(WATCHDOG, link.recv()).await.expect("disconnect").unwrap_err();
        assert!(matches!(err, SerialError::Disconnected { .. }));

        // Nothing to reopen yet: a bounded backoff gives up with the open error.
        std::fs::remove_file(&link_path).unwrap();
        let quick =
            Backoff { initial: Duration::from_millis(5), max: Duration::from_millis(10), max_attempts: Some(3) };
        let gave_up = link.reopen(&quick).await.unwrap_err();
        assert!(matches!(gave_up, SerialError::ReopenFailed { attempts: 3, .. }), "{gave_up}");

        // Plugged back in while the link retries.
        let patient = Backoff { initial: Duration::from_millis(5), ..Backoff::default() };
        let reopening = link.reopen(&patient);
        orders.send(Do::PlugIn(Pty::open().unwrap())).unwrap();
        tokio::time::timeout(WATCHDOG, reopening).await.expect("reopened in time").unwrap();
        assert_eq!(link.counters().reopens, 1);
        send(&mut link, HostFrame::VehicleSpeedRequest).await;
        let frame = tokio::time::timeout(WATCHDOG, link.recv()).await.expect("response").unwrap();
        assert!(matches!(frame, ChassisFrame::VehicleSpeed(_)));
        orders.send(Do::Stop).unwrap();
        let (_, counters) = thread.join().unwrap();
        assert_eq!(counters.reopens, 1);
        assert!(!link_path.exists(), "the device removes its symlink");
    });
}

#[test]
fn open_error_names_the_path_once() {
    runtime().block_on(async {
        let err =
            SerialLink::open("/dev/robowire-no-such-port", &SerialPortOptions::default(), ChassisFrameDecoder::new())
                .unwrap_err();
        assert!(matches!(err, SerialError::Open { .. }));
        assert_eq!(err.to_string(), "cannot open serial port /dev/robowire-no-such-port");
        let cause = std::error::Error::source(&err).expect("the cause is the source").to_string();
        assert!(cause.contains("No such file"), "{cause}");
    });
}
