//! The Driver on a pseudo-terminal against the chassis simulator: order, counts and content of
//! what goes over the line. Rates, the command timeout's length and the stop burst's timing are
//! `kmc-proto`'s fake-clock tests (`kmc-proto/tests/it/stream.rs`); nothing here measures time.

use std::time::Duration;

use kmc::{
    ChassisFrame, Connection, Device, Driver, DriverOptions, KmcError, LinkState, NonFinite, Placement, RtError,
};
use kmc_proto::{HostFrame, PcControl};
use robowire_fixtures::wait::until;
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig, Fault};

/// Generous: a condition that does not hold within this is a failure, not slowness.
const WATCHDOG: Duration = Duration::from_secs(20);

fn sim() -> ChassisSim {
    ChassisSim::spawn(ChassisSimConfig::default()).expect("simulator")
}

/// A command timeout no test outlives: the latched command stays fresh however slow the machine.
fn never_stale() -> DriverOptions {
    DriverOptions { command_timeout: Duration::from_secs(3600), ..Default::default() }
}

/// The `0xA5` frames the simulator received, in order.
fn controls(sim: &ChassisSim) -> Vec<PcControl> {
    sim.received()
        .iter()
        .filter_map(|r| match r.frame {
            HostFrame::PcControl(c) => Some(c),
            _ => None,
        })
        .collect()
}

#[test]
fn streams_the_latched_command_and_speed_requests() {
    let sim = sim();
    let driver = Driver::open(sim.path(), never_stale()).unwrap();
    let command = PcControl::from_yaw_rate(0.5, 0.2).unwrap(); // curvature 0.4 1/m
    driver.set_command(0.5, 0.2).unwrap();
    until(WATCHDOG, "50 frames of the command", || controls(&sim).iter().filter(|c| **c == command).count() >= 50);
    let stats = driver.stats();
    assert!(stats.speed_requests_sent > 0);
    assert_eq!(stats.control_lateness.count, stats.control_frames_sent, "every tick measured");
    assert_eq!((stats.command_timeouts, stats.write_errors), (0, 0));
    driver.close().unwrap();
    // The stop burst is the sentinel: once it has arrived, so has everything sent before it.
    until(WATCHDOG, "the stop burst after the command", || {
        controls(&sim).ends_with(&[command, PcControl::STOP, PcControl::STOP, PcControl::STOP])
    });
    let frames = controls(&sim);
    // (0, 0) until the command was latched, then the command without a gap, then the burst.
    let first = frames.iter().position(|c| *c == command).unwrap();
    assert!(frames[..first].iter().all(|c| *c == PcControl::STOP), "{frames:?}");
    let (moving, tail) = frames[first..].split_at(frames.len() - first - 3);
    assert!(moving.iter().all(|c| *c == command), "{frames:?}");
    assert_eq!(tail, [PcControl::STOP; 3]);
    assert!(sim.stats().speed_requests > 0);
}

#[test]
fn a_stale_command_becomes_stop_without_a_call() {
    let sim = sim();
    let options = DriverOptions { command_timeout: Duration::from_millis(100), ..Default::default() };
    let driver = Driver::open(sim.path(), options).unwrap();
    let drive = PcControl { velocity_mps: 0.4, curvature_per_m: 0.0 };
    driver.set_command(0.4, 0.0).unwrap();
    // The command went out, then (0, 0) by itself, for a while.
    let stops_after_the_command = |frames: &[PcControl]| {
        frames.iter().position(|c| *c == drive).map_or(0, |first| {
            frames[first..].iter().skip_while(|c| **c == drive).take_while(|c| **c == PcControl::STOP).count()
        })
    };
    until(WATCHDOG, "20 stops after the command", || stops_after_the_command(&controls(&sim)) >= 20);
    let frames = controls(&sim);
    let first = frames.iter().position(|c| *c == drive).unwrap();
    let moving = frames[first..].iter().take_while(|c| **c == drive).count();
    assert!(frames[first + moving..].iter().all(|c| *c == PcControl::STOP), "only (0, 0) after the timeout");
    let stats = driver.stats();
    assert_eq!(stats.command_timeouts, 1);
    assert!(stats.timeout_frames_sent as usize >= frames.len() - first - moving);
    assert_eq!(sim.state().commanded_velocity_mps, 0.0);
    driver.close().unwrap();
}

#[test]
fn close_sends_the_burst_and_frees_the_port() {
    let sim = sim();
    let driver = Driver::open(sim.path(), never_stale()).unwrap();
    assert!(driver.is_running());
    assert_eq!(driver.link_state(), LinkState::Connected);
    driver.set_command(1.0, 0.0).unwrap();
    until(WATCHDOG, "the command on the line", || controls(&sim).iter().any(|c| c.velocity_mps == 1.0));
    driver.close().unwrap();
    let drive = PcControl { velocity_mps: 1.0, curvature_per_m: 0.0 };
    let burst = [drive, PcControl::STOP, PcControl::STOP, PcControl::STOP];
    until(WATCHDOG, "the burst after the command", || controls(&sim).ends_with(&burst));
    // The port is free again at once: a new driver opens it, and dropping it stops it too.
    let again = Driver::open(sim.path(), DriverOptions::default()).unwrap();
    assert_eq!(again.link_state(), LinkState::Connected);
    drop(again);
    until(WATCHDOG, "the dropped driver's burst", || controls(&sim).ends_with(&[PcControl::STOP; 6]));
}

#[test]
fn unplug_is_reported_and_the_driver_reconnects() {
    let link = std::env::temp_dir().join(format!("robowire-kmc-driver-{}", std::process::id()));
    let sim = ChassisSim::spawn(ChassisSimConfig { link: Some(link.clone()), ..Default::default() }).unwrap();
    let driver = Driver::open(&link, never_stale()).unwrap();
    driver.set_command(0.3, 0.0).unwrap();
    until(WATCHDOG, "the command on the line", || sim.state().commanded_velocity_mps == 0.3);
    sim.inject(Fault::HangUp);
    until(WATCHDOG, "the disconnect reported", || driver.link_state() == LinkState::Disconnected);
    assert_eq!(driver.stats().disconnects, 1);
    assert!(driver.is_running(), "the driver waits for the device instead of dying");

    sim.replug().unwrap();
    until(WATCHDOG, "reconnected after the re-plug", || driver.link_state() == LinkState::Connected);
    let before = sim.stats().control_frames;
    until(WATCHDOG, "the stream resumed on the new line", || sim.stats().control_frames > before + 5);
    assert_eq!(sim.state().commanded_velocity_mps, 0.3, "with the latched command");
    assert_eq!(driver.stats().link.reopens, 1);
    driver.close().unwrap();
}

#[test]
fn polls_and_one_shot_requests_deliver_messages() {
    let sim = sim();
    let options = DriverOptions { poll_battery: true, poll_allstate: true, ..never_stale() };
    let driver = Driver::open(sim.path(), options).unwrap();
    driver.set_command(0.8, 0.0).unwrap();
    let (mut speeds, mut batteries, mut states) = (Vec::new(), 0, [0; 2]);
    // First-order response: the speed rises towards 0.8 m/s.
    until(WATCHDOG, "speed near 0.8 m/s, the battery and all-state of both motors", || {
        while let Some(frame) = driver.try_pop_message() {
            match frame {
                ChassisFrame::VehicleSpeed(v) => speeds.push(v.speed_mps),
                ChassisFrame::BatteryVoltage(b) => {
                    assert!(b.volts > 24.0 && b.volts <= 25.2 && b.motor_id == 0, "{b:?}");
                    batteries += 1;
                }
                ChassisFrame::AllState(s) => states[usize::from(s.motor_id)] += 1,
                ChassisFrame::Af(raw) => panic!("unexpected raw frame {raw:?}"),
            }
        }
        speeds.last().is_some_and(|&v| (v - 0.8).abs() < 0.05) && batteries >= 1 && states.iter().all(|&n| n >= 2)
    });
    assert!(speeds.windows(2).all(|w| w[1] >= w[0] - 1e-6), "monotonic rise: {speeds:?}");
    // Polls only ever ask motor 0 for the battery: an answer from motor 1 is the one-shot's.
    driver.request_battery_once(1).unwrap();
    let mut one_shot = None;
    until(WATCHDOG, "the one-shot battery read answered", || {
        one_shot = std::iter::from_fn(|| driver.try_pop_message())
            .find(|f| matches!(f, ChassisFrame::BatteryVoltage(b) if b.motor_id == 1));
        one_shot.is_some()
    });
    assert_eq!(driver.stats().command_timeouts, 0);
    assert_eq!(driver.stats().link.decoder.skipped_bytes, 0);
    // The same reports in the driver's state, with the odometry integrated from the speed.
    let state = driver.latest().expect("a chassis state").state;
    assert!(state.battery.is_some() && state.motors.iter().all(Option::is_some), "{state:?}");
    assert!(state.odometry.x_m > 0.0 && state.odometry.y_m.abs() < 1e-9, "{:?}", state.odometry);
    driver.close().unwrap();
}

#[test]
fn full_queue_drops_the_oldest_and_counts() {
    let sim = sim();
    let options = DriverOptions { max_queue: 4, vehicle_speed_rate_hz: 200.0, ..Default::default() };
    let driver = Driver::open(sim.path(), options).unwrap();
    until(WATCHDOG, "frames dropped from the full queue", || driver.stats().queue_dropped > 10);
    // The chassis falls silent; once everything it sent has arrived, the counts stand still.
    sim.inject(Fault::DropResponses { count: u32::MAX });
    until(WATCHDOG, "a response swallowed", || sim.stats().responses_dropped > 0);
    until(WATCHDOG, "every response sent received", || driver.stats().frames_received == sim.stats().responses_sent);
    let stats = driver.stats();
    let queued = std::iter::from_fn(|| driver.try_pop_message()).count() as u64;
    assert_eq!(queued, 4, "the queue holds max_queue frames");
    assert_eq!(stats.queue_dropped + queued, stats.frames_received, "every frame is queued or counted as dropped");
}

#[test]
fn invalid_arguments_are_refused_before_anything_is_sent() {
    let sim = sim();
    let driver = Driver::open(sim.path(), never_stale()).unwrap();
    driver.set_command(0.2, 0.0).unwrap();
    for (v, w) in [(f32::NAN, 0.0), (0.0, f32::INFINITY), (f32::NEG_INFINITY, 1.0)] {
        let err = driver.set_command(v, w).unwrap_err();
        assert!(matches!(err, KmcError::Argument(NonFinite { .. })), "{err}");
    }
    assert!(driver.set_command_curvature(0.1, f32::NAN).is_err());
    // A finite yaw rate so large that omega / v overflows is refused too.
    assert!(driver.set_command(0.0011, f32::MAX).is_err());
    let after = driver.stats().control_frames_sent;
    until(WATCHDOG, "five more ticks", || controls(&sim).len() as u64 > after + 5);
    let frames = controls(&sim);
    assert!(frames.iter().all(|c| c.velocity_mps.is_finite() && c.curvature_per_m.is_finite()));
    assert_eq!(frames.last().unwrap().velocity_mps, 0.2, "the previous command stays");
    driver.close().unwrap();
}

#[test]
fn invalid_options_and_open_failures_are_typed() {
    let bad = [
        DriverOptions { control_rate_hz: 0.0, ..Default::default() },
        DriverOptions { vehicle_speed_rate_hz: f64::NAN, ..Default::default() },
        DriverOptions { control_rate_hz: 5000.0, ..Default::default() },
        DriverOptions { stop_burst_count: 0, ..Default::default() },
        DriverOptions { max_queue: 0, ..Default::default() },
        DriverOptions { command_timeout: Duration::ZERO, ..Default::default() },
        DriverOptions { command_timeout: Duration::from_secs(3601), ..Default::default() },
        DriverOptions { state_timeout: Duration::from_millis(1), ..Default::default() },
    ];
    for options in bad {
        assert!(matches!(Driver::open("/dev/null", options), Err(KmcError::Option { .. })));
    }
    let priority = DriverOptions { placement: Placement::realtime(0, None), ..Default::default() };
    assert!(matches!(Driver::open("/dev/null", priority), Err(KmcError::Thread(RtError::RealtimePriority { .. }))));
    let err = Driver::open("/dev/robowire-no-such-chassis", DriverOptions::default()).unwrap_err();
    assert!(matches!(err, KmcError::Link(_)), "{err}");

    let sim = sim();
    let on_cpu =
        |cpu| DriverOptions { placement: Placement { cpu: Some(cpu), ..Placement::default() }, ..Default::default() };
    let pinned = Driver::open(sim.path(), on_cpu(0)).unwrap();
    assert!(matches!(pinned.set_command_timeout(Duration::from_secs(3601)), Err(KmcError::Option { .. })));
    pinned.close().unwrap();
    let nowhere = Driver::open(sim.path(), on_cpu(1 << 20));
    assert!(matches!(nowhere, Err(KmcError::Thread(RtError::CpuAffinity { cpu, .. })) if cpu == 1 << 20));
    // SCHED_FIFO needs privileges this machine may or may not grant: either it works, or the
    // error says which priority failed. The failed open above left the port free.
    match Driver::open(sim.path(), DriverOptions { placement: Placement::realtime(10, None), ..Default::default() }) {
        Ok(realtime) => realtime.close().unwrap(),
        Err(KmcError::Thread(RtError::RealtimePriority { priority: 10, .. })) => {}
        Err(other) => panic!("unexpected error {other}"),
    }
}

#[test]
fn a_longer_command_timeout_keeps_a_command_alive_without_refreshes() {
    let sim = sim();
    let options = DriverOptions { command_timeout: Duration::from_millis(50), ..Default::default() };
    let driver = Driver::open(sim.path(), options).unwrap();
    // A bridge with a deadman of its own: one command, no keep-alive.
    driver.set_command_timeout(Duration::from_secs(10)).unwrap();
    driver.set_command(0.4, 0.0).unwrap();
    let drive = PcControl { velocity_mps: 0.4, curvature_per_m: 0.0 };
    until(WATCHDOG, "100 frames of the one command", || controls(&sim).iter().filter(|c| **c == drive).count() >= 100);
    assert_eq!(driver.stats().command_timeouts, 0, "never stale");
    // Shortened again: the same command goes stale, and (0, 0) follows.
    driver.set_command_timeout(Duration::from_millis(20)).unwrap();
    until(WATCHDOG, "a stop after the timeout", || driver.stats().command_timeouts == 1);
    driver.close().unwrap();
}

#[test]
fn a_silent_chassis_is_noticed_and_its_return_reconnects() {
    let sim = sim();
    let options = DriverOptions { state_timeout: Duration::from_millis(100), ..never_stale() };
    let driver = Driver::open(sim.path(), options).unwrap();
    assert!(driver.wait_state(WATCHDOG, |s| s.speed_mps.is_some()).is_some(), "speed reports arrive");
    assert_eq!(driver.connection(), Connection::Connected);
    sim.inject(Fault::DropResponses { count: 100 });
    until(WATCHDOG, "disconnected", || driver.stats().state_timeouts == 1);
    until(WATCHDOG, "reconnected when the chassis answers again", || driver.connection() == Connection::Connected);
    assert_eq!(driver.link_state(), LinkState::Connected, "the port itself never went away");
    driver.close().unwrap();
}
