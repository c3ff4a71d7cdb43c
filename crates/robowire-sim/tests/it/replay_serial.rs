//! The serial replay device from a host on its pseudo-terminal, with the KMC chassis' device
//! decoder: the recorded frames arrive exactly, in order, after the host's first frame, and the
//! host's frames are counted.

use std::fs::File;
use std::io::{Read, Write};
use std::time::{Duration, Instant};

use kmc_proto::HostFrameDecoder;
use robowire_sim::replay::{Pace, ReplayError, SerialReplay};

/// Every wait is bounded, so a broken player fails the test instead of hanging it.
const WATCHDOG: Duration = Duration::from_secs(10);

/// Vehicle speed reports (`0xB3`, f32 LE m/s), `step` apart: 0.0, 0.1, 0.2 … m/s.
fn speeds(count: u8, step: Duration) -> Vec<(Duration, Vec<u8>)> {
    (0..count)
        .map(|i| {
            let mut frame = vec![0xb3];
            frame.extend_from_slice(&(f32::from(i) / 10.0).to_le_bytes());
            (step * u32::from(i), frame)
        })
        .collect()
}

/// The host end, opened like a serial port.
fn host(device: &SerialReplay<HostFrameDecoder>) -> File {
    std::fs::OpenOptions::new().read(true).write(true).open(device.path()).unwrap()
}

/// Reads `len` bytes on a thread of its own, so that a player that never writes them fails the
/// test at the watchdog instead of hanging it.
fn read_on_a_thread(mut host: File, len: usize) -> std::sync::mpsc::Receiver<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut read = vec![0u8; len];
        if host.read_exact(&mut read).is_ok() {
            let _ = tx.send(read);
        }
    });
    rx
}

#[test]
fn the_host_reads_exactly_the_frames_in_order_at_the_recorded_pace() {
    let recorded = speeds(30, Duration::from_millis(5));
    let mut device = SerialReplay::open(HostFrameDecoder::new(), recorded.clone()).unwrap();
    assert_eq!(device.frames(), 30);
    let mut host = host(&device);
    // Noise first (skipped), then a speed request: the first frame.
    host.write_all(&[0x00, 0x42, 0xb3]).unwrap();
    assert!(device.first_command(WATCHDOG).unwrap(), "the host's first frame in time");
    let read = read_on_a_thread(host.try_clone().unwrap(), 30 * 5);
    // Frames during the playback are counted: a speed request and a control frame.
    host.write_all(&[0xb3]).unwrap();
    let mut control = [0u8; kmc_proto::PcControl::LEN];
    kmc_proto::PcControl { velocity_mps: 0.5, curvature_per_m: 0.0 }.emit(&mut control).unwrap();
    host.write_all(&control).unwrap();
    let began = Instant::now();
    let summary = device.play(Pace::Recorded { speed: 1.0 }, WATCHDOG).unwrap();
    assert!(began.elapsed() >= Duration::from_millis(29 * 5), "at the recorded pace: {:?}", began.elapsed());
    assert_eq!((summary.frames, summary.sent, summary.client), (30, 30, None));
    assert_eq!((summary.commands, summary.invalid), (3, 0));
    let bytes = read.recv_timeout(WATCHDOG).expect("every frame in time");
    assert_eq!(bytes, recorded.into_iter().flat_map(|(_, frame)| frame).collect::<Vec<_>>());
}

#[test]
fn fast_plays_every_frame_at_once_a_silent_host_is_waited_for_and_a_bad_speed_is_refused() {
    let open = || SerialReplay::open(HostFrameDecoder::new(), speeds(20, Duration::from_secs(3600))).unwrap();
    let mut device = open();
    let mut host = host(&device);
    // Nobody spoke yet: not a frame, and no error.
    assert!(!device.first_command(Duration::from_millis(20)).unwrap());
    host.write_all(&[0xb3]).unwrap();
    assert!(device.first_command(WATCHDOG).unwrap());
    let read = read_on_a_thread(host, 20 * 5);
    // An hour between frames, recorded: fast ignores it.
    let summary = device.play(Pace::Fast, WATCHDOG).unwrap();
    assert_eq!((summary.sent, summary.commands), (20, 1));
    let bytes = read.recv_timeout(WATCHDOG).expect("every frame at once");
    assert!(bytes.chunks(5).enumerate().all(|(i, f)| f[0] == 0xb3 && f[1..] == (i as f32 / 10.0).to_le_bytes()));

    for speed in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let refused = open().play(Pace::Recorded { speed }, WATCHDOG);
        assert!(matches!(refused, Err(ReplayError::Speed(_))), "{speed}: {refused:?}");
    }
}
