//! The Driver on a pseudo-terminal against the chassis simulator.

use std::time::{Duration, Instant};

use kmc::{ChassisFrame, Driver, DriverOptions, KmcError, LinkState, NonFinite, RtError};
use kmc_proto::{HostFrame, PcControl};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig, Fault, Received};

fn sim() -> ChassisSim {
    ChassisSim::spawn(ChassisSimConfig::default()).expect("simulator")
}

/// The `0xA5` frames the simulator received, with arrival times.
fn controls(received: &[Received]) -> Vec<(Instant, PcControl)> {
    received
        .iter()
        .filter_map(|r| match r.frame {
            HostFrame::PcControl(c) => Some((r.at, c)),
            _ => None,
        })
        .collect()
}

/// Polls `condition` every millisecond for up to `limit`; the time it took, if it became true.
fn wait_until(limit: Duration, mut condition: impl FnMut() -> bool) -> Option<Duration> {
    let start = Instant::now();
    while start.elapsed() < limit {
        if condition() {
            return Some(start.elapsed());
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    None
}

#[test]
fn streams_at_100_hz_on_absolute_deadlines() {
    let sim = sim();
    let mut driver = Driver::new(sim.path(), DriverOptions::default()).unwrap();
    driver.start().unwrap();
    let begin = Instant::now();
    while begin.elapsed() < Duration::from_secs(2) {
        driver.set_command(0.5, 0.2).unwrap();
        std::thread::sleep(Duration::from_millis(20));
    }
    let window_end = Instant::now();
    driver.stop().unwrap();

    let frames: Vec<_> =
        controls(&sim.received()).into_iter().filter(|(at, _)| *at >= begin && *at <= window_end).collect();
    let seconds = (window_end - begin).as_secs_f64();
    let rate = frames.len() as f64 / seconds;
    assert!((90.0..=110.0).contains(&rate), "{} frames in {seconds:.3} s = {rate:.1} Hz", frames.len());
    // After the first tick every frame carries the command: 0.5 m/s on curvature 0.4 1/m.
    let expected = PcControl::from_yaw_rate(0.5, 0.2).unwrap();
    assert!(frames.iter().skip(1).all(|(_, c)| *c == expected));
    // Intervals: absolute deadlines keep the median on 10 ms.
    let mut intervals: Vec<f64> = frames.windows(2).map(|w| (w[1].0 - w[0].0).as_secs_f64() * 1e3).collect();
    intervals.sort_by(f64::total_cmp);
    let median = intervals[intervals.len() / 2];
    assert!((8.0..=12.0).contains(&median), "median interval {median:.2} ms");
    let stats = driver.stats();
    assert!(stats.control_frames_sent >= frames.len() as u64);
    assert!(stats.speed_requests_sent > 80, "0xB3 at 50 Hz: {}", stats.speed_requests_sent);
    assert!(stats.control_lateness.count > 0);
    assert_eq!(stats.command_timeouts, 0, "the command was refreshed every 20 ms");
}

#[test]
fn stale_command_becomes_stop_after_the_timeout() {
    let sim = sim();
    let mut driver = Driver::new(sim.path(), DriverOptions::default()).unwrap();
    driver.start().unwrap();
    std::thread::sleep(Duration::from_millis(50));
    let set_at = Instant::now();
    driver.set_command(0.4, 0.0).unwrap();
    std::thread::sleep(Duration::from_millis(700));
    let frames = controls(&sim.received());
    let moving: Vec<_> = frames.iter().filter(|(_, c)| c.velocity_mps == 0.4).collect();
    assert!(!moving.is_empty(), "the command was streamed");
    let last_moving = moving.last().unwrap().0;
    // 300 ms timeout, one 10 ms tick of slack, and scheduling noise.
    let streamed_for = last_moving - set_at;
    assert!(streamed_for <= Duration::from_millis(300 + 10 + 40), "streamed for {streamed_for:?}");
    assert!(streamed_for >= Duration::from_millis(250), "stopped early, after {streamed_for:?}");
    let after: Vec<_> = frames.iter().filter(|(at, _)| *at > last_moving).collect();
    assert!(after.len() >= 20, "the stream goes on after the timeout");
    assert!(after.iter().all(|(_, c)| *c == PcControl::STOP), "only (0, 0) after the timeout");
    let stats = driver.stats();
    assert_eq!(stats.command_timeouts, 1);
    assert!(stats.timeout_frames_sent >= after.len() as u64);
    assert!(sim.state().commanded_velocity_mps == 0.0);
    driver.stop().unwrap();
}

#[test]
fn stop_sends_the_burst_and_ends_the_stream() {
    let sim = sim();
    let mut driver = Driver::new(sim.path(), DriverOptions::default()).unwrap();
    driver.start().unwrap();
    assert!(driver.is_running());
    assert_eq!(driver.link_state(), LinkState::Connected);
    for _ in 0..10 {
        driver.set_command(1.0, 0.0).unwrap();
        std::thread::sleep(Duration::from_millis(10));
    }
    driver.stop().unwrap();
    assert!(!driver.is_running());
    assert_eq!(driver.link_state(), LinkState::Stopped);
    driver.stop().unwrap(); // idempotent
    std::thread::sleep(Duration::from_millis(50));
    let frames = controls(&sim.received());
    let tail: Vec<_> = frames.iter().rev().take(3).collect();
    assert!(tail.iter().all(|(_, c)| *c == PcControl::STOP), "the last three frames are (0, 0)");
    assert!(frames.iter().rev().nth(3).is_some_and(|(_, c)| c.velocity_mps == 1.0), "the burst follows the command");
    assert_eq!(driver.stats().stop_frames_sent, 3);
    // Nothing is sent after stop.
    let count = sim.stats().control_frames;
    std::thread::sleep(Duration::from_millis(50));
    assert_eq!(sim.stats().control_frames, count);
    assert!(matches!(driver.request_battery_once(0), Err(KmcError::NotRunning)));
}

#[test]
fn unplug_is_reported_within_100_ms_and_the_driver_reconnects() {
    let link = std::env::temp_dir().join(format!("robowire-kmc-driver-{}", std::process::id()));
    let sim = ChassisSim::spawn(ChassisSimConfig { link: Some(link.clone()), ..Default::default() }).unwrap();
    let mut driver = Driver::new(&link, DriverOptions::default()).unwrap();
    driver.start().unwrap();
    driver.set_command(0.3, 0.0).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    sim.inject(Fault::HangUp);
    let noticed = wait_until(Duration::from_secs(2), || driver.link_state() == LinkState::Disconnected);
    let noticed = noticed.expect("the disconnect was reported");
    // The simulator acts within its 5 ms poll; the rest is the driver.
    assert!(noticed < Duration::from_millis(100), "reported after {noticed:?}");
    assert_eq!(driver.stats().disconnects, 1);
    assert!(driver.is_running(), "the driver waits for the device instead of dying");

    sim.replug().unwrap();
    let back = wait_until(Duration::from_secs(3), || driver.link_state() == LinkState::Connected);
    assert!(back.is_some(), "reconnected after the re-plug");
    let before = sim.stats().control_frames;
    driver.set_command(0.3, 0.0).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    assert!(sim.stats().control_frames > before + 5, "the stream resumed on the new line");
    assert_eq!(driver.stats().link.reopens, 1);
    driver.stop().unwrap();
}

#[test]
fn polls_and_one_shot_requests_deliver_messages() {
    let sim = sim();
    let options = DriverOptions { poll_battery: true, poll_allstate: true, ..Default::default() };
    let mut driver = Driver::new(sim.path(), options).unwrap();
    driver.start().unwrap();
    driver.set_command(0.8, 0.0).unwrap();
    let (mut speeds, mut batteries, mut states) = (Vec::new(), 0, [0; 2]);
    let begin = Instant::now();
    while begin.elapsed() < Duration::from_millis(1200) {
        driver.set_command(0.8, 0.0).unwrap();
        for frame in driver.messages_until(Instant::now() + Duration::from_millis(20)) {
            match frame {
                ChassisFrame::VehicleSpeed(v) => speeds.push(v.speed_mps),
                ChassisFrame::BatteryVoltage(b) => {
                    assert!(b.volts > 24.0 && b.volts <= 25.2);
                    batteries += 1;
                }
                ChassisFrame::AllState(s) => states[usize::from(s.motor_id)] += 1,
                ChassisFrame::Af(raw) => panic!("unexpected raw frame {raw:?}"),
            }
        }
    }
    // Polls only ever ask motor 0 for the battery: an answer from motor 1 is the one-shot's.
    driver.request_battery_once(1).unwrap();
    let one_shot = driver
        .messages_until(Instant::now() + Duration::from_secs(1))
        .find(|f| matches!(f, ChassisFrame::BatteryVoltage(b) if b.motor_id == 1));
    driver.stop().unwrap();
    assert!(speeds.len() > 40, "speed responses at 50 Hz: {}", speeds.len());
    // First-order response: the speed rises towards 0.8 m/s.
    assert!(speeds.last().is_some_and(|&v| (v - 0.8).abs() < 0.05), "final speed {:?}", speeds.last());
    assert!(batteries >= 1, "battery polled at 1 Hz");
    assert!(states[0] >= 8 && states[1] >= 8, "all-state polled at 10 Hz for both motors: {states:?}");
    assert!(one_shot.is_some(), "the one-shot battery read was answered");
    assert_eq!(driver.stats().command_timeouts, 0);
    assert_eq!(driver.stats().link.decoder.skipped_bytes, 0);
}

#[test]
fn full_queue_drops_the_oldest_and_counts() {
    let sim = sim();
    let options = DriverOptions { max_queue: 4, vehicle_speed_rate_hz: 200.0, ..Default::default() };
    let mut driver = Driver::new(sim.path(), options).unwrap();
    driver.start().unwrap();
    std::thread::sleep(Duration::from_millis(300));
    driver.stop().unwrap();
    let stats = driver.stats();
    assert!(stats.frames_received > 20, "{stats:?}");
    let mut queued = 0;
    while driver.try_pop_message().is_some() {
        queued += 1;
    }
    assert_eq!(queued, 4, "the queue holds max_queue frames");
    assert_eq!(stats.queue_dropped + queued, stats.frames_received, "every frame is queued or counted as dropped");
}

#[test]
fn invalid_arguments_are_refused_before_anything_is_sent() {
    let sim = sim();
    let mut driver = Driver::new(sim.path(), DriverOptions::default()).unwrap();
    driver.start().unwrap();
    driver.set_command(0.2, 0.0).unwrap();
    for (v, w) in [(f32::NAN, 0.0), (0.0, f32::INFINITY), (f32::NEG_INFINITY, 1.0)] {
        let err = driver.set_command(v, w).unwrap_err();
        assert!(matches!(err, KmcError::Argument(NonFinite { .. })), "{err}");
    }
    assert!(driver.set_command_curvature(0.1, f32::NAN).is_err());
    // A finite yaw rate so large that omega / v overflows is refused too.
    assert!(driver.set_command(0.0011, f32::MAX).is_err());
    std::thread::sleep(Duration::from_millis(50));
    let frames = controls(&sim.received());
    assert!(frames.iter().all(|(_, c)| c.velocity_mps.is_finite() && c.curvature_per_m.is_finite()));
    assert_eq!(frames.last().unwrap().1.velocity_mps, 0.2, "the previous command stays");
    driver.stop().unwrap();
}

#[test]
fn invalid_options_and_start_failures_are_typed() {
    let bad = [
        DriverOptions { control_rate_hz: 0.0, ..Default::default() },
        DriverOptions { vehicle_speed_rate_hz: f64::NAN, ..Default::default() },
        DriverOptions { control_rate_hz: 5000.0, ..Default::default() },
        DriverOptions { stop_burst_count: 0, ..Default::default() },
        DriverOptions { max_queue: 0, ..Default::default() },
        DriverOptions { realtime_priority: Some(0), ..Default::default() },
    ];
    for options in bad {
        assert!(matches!(Driver::new("/dev/null", options), Err(KmcError::Option { .. })));
    }
    let mut missing = Driver::new("/dev/robowire-no-such-chassis", DriverOptions::default()).unwrap();
    let err = missing.start().unwrap_err();
    assert!(matches!(err, KmcError::Link(_)), "{err}");
    assert!(!missing.is_running());

    let sim = sim();
    let mut pinned = Driver::new(sim.path(), DriverOptions { cpu_affinity: Some(0), ..Default::default() }).unwrap();
    pinned.start().unwrap();
    assert!(matches!(pinned.start(), Err(KmcError::AlreadyRunning)));
    pinned.stop().unwrap();
    let mut nowhere =
        Driver::new(sim.path(), DriverOptions { cpu_affinity: Some(1 << 20), ..Default::default() }).unwrap();
    assert!(matches!(nowhere.start(), Err(KmcError::Placement(RtError::CpuAffinity { cpu, .. })) if cpu == 1 << 20));
    // SCHED_FIFO needs privileges this machine may or may not grant: either it works, or the
    // error says which priority failed.
    let mut realtime =
        Driver::new(sim.path(), DriverOptions { realtime_priority: Some(10), ..Default::default() }).unwrap();
    match realtime.start() {
        Ok(()) => realtime.stop().unwrap(),
        Err(KmcError::Placement(RtError::RealtimePriority { priority: 10, .. })) => {}
        Err(other) => panic!("unexpected error {other}"),
    }
}
