//! The chassis scenario: straight, turn, reverse, command timeout, stop, with a burst of line
//! noise and a dropped response on the way.

use robowire_record::RecordLinks;
use std::time::{Duration, Instant};

use anyhow::Context;
use kmc::{ChassisFrame, Device, DriverOptions};
use kmc_proto::{HostFrame, PcControl};
use robowire_core::timing::LatenessRing;
use robowire_devices::{DeviceKind, OpenOptions, Simulator};
use robowire_sim::kmc::Fault;

use super::{Check, DeviceReport, InjectedFault, Progress, Status};
use crate::output::Output;

/// Shortest motion phase: a 0.2 s first-order response settles within 2 % in 0.8 s.
const MIN_PHASE: Duration = Duration::from_millis(800);
/// How often the scenario refreshes `set_command`.
const COMMAND_REFRESH: Duration = Duration::from_millis(20);
/// Garbage bytes injected before a response.
const GARBAGE_BYTES: usize = 64;

struct Phase {
    name: &'static str,
    velocity_mps: f32,
    yaw_rate_radps: f32,
}

const PHASES: [Phase; 3] = [
    Phase { name: "straight", velocity_mps: 0.5, yaw_rate_radps: 0.0 },
    Phase { name: "turn", velocity_mps: 0.5, yaw_rate_radps: 0.3 },
    Phase { name: "reverse", velocity_mps: -0.3, yaw_rate_radps: 0.0 },
];

pub(super) fn run(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    out.line("== KMC chassis (UART on a pseudo-terminal) ==");
    // sim:kmc's driver: the defaults, with the battery and all-state polls.
    let device = super::open_simulated(
        DeviceKind::Kmc,
        &OpenOptions { kmc_polls: true, record: record.cloned(), ..OpenOptions::default() },
    )?;
    let (Some(Simulator::Kmc(sim)), Some(driver)) = (device.simulator(), device.kmc()) else {
        anyhow::bail!("sim:kmc opened something other than a simulated KMC chassis");
    };
    let options = DriverOptions::default();
    out.line(format_args!(
        "simulator on {}; Driver at {} Hz control, {} Hz speed, battery and all-state polls",
        sim.path().display(),
        options.control_rate_hz,
        options.vehicle_speed_rate_hz
    ));
    let control_rate_hz = options.control_rate_hz;
    let started = Instant::now();
    let phase_time = Duration::from_secs_f64(duration_s / PHASES.len() as f64).max(MIN_PHASE);
    let mut report = DeviceReport::new("kmc");
    let mut progress = Progress::new("kmc", out);
    let mut speed_reports = [0u64; PHASES.len()];
    let mut last_speed = 0.0f32;
    let mut battery_volts = None;
    let mut all_state_seen = [0u32; 2];
    let mut last_command_at = Instant::now();

    for (i, phase) in PHASES.iter().enumerate() {
        if i == 1 {
            sim.inject(Fault::Garbage { bytes: GARBAGE_BYTES });
            sim.inject(Fault::DropResponses { count: 1 });
        }
        let heading_before = sim.state().heading_rad;
        let speed_before = last_speed;
        let end = Instant::now() + phase_time;
        while Instant::now() < end {
            // Refresh the command every 20 ms, well inside the 300 ms timeout; read what
            // arrives in between.
            driver.set_command(phase.velocity_mps, phase.yaw_rate_radps)?;
            last_command_at = Instant::now();
            for frame in driver.messages_until((Instant::now() + COMMAND_REFRESH).min(end)) {
                match frame {
                    ChassisFrame::VehicleSpeed(v) => {
                        last_speed = v.speed_mps;
                        speed_reports[i] += 1;
                    }
                    ChassisFrame::BatteryVoltage(b) => battery_volts = Some(b.volts),
                    ChassisFrame::AllState(s) => all_state_seen[usize::from(s.motor_id.min(1))] += 1,
                    ChassisFrame::Af(_) => {}
                }
            }
            if progress.due() {
                let stats = driver.stats();
                progress.show(&Status {
                    mode: phase.name,
                    motion: format!("{last_speed:+.3} m/s"),
                    loop_count: stats.control_frames_sent,
                    lateness_us: (stats.control_lateness.p99_us, "p99"),
                });
            }
        }
        let state = sim.state();
        let turned = state.heading_rad - heading_before;
        out.line(format_args!(
            "  {:<8} set_command({:+.2} m/s, {:+.2} rad/s) -> reported speed {:+.3} m/s, heading change {:+.3} rad",
            phase.name, phase.velocity_mps, phase.yaw_rate_radps, last_speed, turned
        ));
        // Settled: within 10 % of the step (plus 2 cm/s for the report's age).
        let tolerance = 0.1 * (phase.velocity_mps - speed_before).abs() + 0.02;
        report.commanded.push(format!(
            "{} {:+.2} m/s{}",
            phase.name,
            phase.velocity_mps,
            if phase.yaw_rate_radps == 0.0 { String::new() } else { format!(" {:+.2} rad/s", phase.yaw_rate_radps) }
        ));
        report.observed.push(format!(
            "{} {last_speed:+.3} m/s{}",
            phase.name,
            if phase.yaw_rate_radps == 0.0 { String::new() } else { format!(" {turned:+.2} rad") }
        ));
        report.checks.push(Check::new(
            format!("{}: speed reaches {:+.2} m/s", phase.name, phase.velocity_mps),
            (last_speed - phase.velocity_mps).abs() <= tolerance,
            format!("{last_speed:+.3} m/s"),
        ));
        if phase.yaw_rate_radps != 0.0 {
            let expected = phase.yaw_rate_radps * phase_time.as_secs_f32();
            report.checks.push(Check::new(
                format!("{}: heading turns by ~{expected:+.2} rad", phase.name),
                turned > 0.5 * expected && turned < 1.2 * expected,
                format!("{turned:+.3} rad"),
            ));
        }
    }

    // Command timeout: stop calling set_command; the Driver must switch to (0, 0) after 300 ms.
    std::thread::sleep(Duration::from_millis(600));
    let timeout_stop = sim
        .received()
        .into_iter()
        .find(|r| r.at > last_command_at && r.frame == HostFrame::PcControl(PcControl::STOP))
        .map(|r| r.at - last_command_at);
    let timeouts = driver.stats().command_timeouts;
    out.line(format_args!(
        "  timeout  no set_command for 600 ms -> (0, 0) streamed after {} ms, chassis commanded {:+.2} m/s",
        timeout_stop.map_or("never".into(), |d| d.as_millis().to_string()),
        sim.state().commanded_velocity_mps
    ));
    report.checks.push(Check::new(
        "timeout: (0, 0) streamed after the 300 ms timeout",
        timeouts == 1 && timeout_stop.is_some_and(|d| d >= Duration::from_millis(300)),
        format!("after {} ms, {timeouts} timeout(s)", timeout_stop.unwrap_or_default().as_millis()),
    ));
    report.checks.push(Check::timing(
        "kmc: the timeout's stop within 100 ms of its due time",
        timeout_stop.is_some_and(|d| d <= Duration::from_millis(400)),
        format!("after {} ms", timeout_stop.unwrap_or_default().as_millis()),
    ));

    // Stop: the burst of three (0, 0).
    driver.set_command(0.2, 0.0)?;
    std::thread::sleep(Duration::from_millis(50));
    let before_stop = sim.received().len();
    let stats = driver.stats();
    let (closed, simulator) = device.close_keeping_simulator();
    closed.context("closing the driver")?;
    let Some(Simulator::Kmc(sim)) = simulator else { anyhow::bail!("sim:kmc's simulator is gone") };
    let elapsed = started.elapsed();
    // The burst is the sentinel: once three (0, 0) end the line after the command, everything
    // the driver wrote has arrived (or 2 s pass).
    let burst_at_end = |received: &[robowire_sim::kmc::Received]| {
        let controls: Vec<_> =
            received.iter().skip(before_stop).filter(|r| matches!(r.frame, HostFrame::PcControl(_))).collect();
        controls.iter().rev().take_while(|r| r.frame == HostFrame::PcControl(PcControl::STOP)).count()
    };
    let waited = Instant::now();
    while burst_at_end(&sim.received()) < 3 && waited.elapsed() < Duration::from_secs(2) {
        std::thread::sleep(Duration::from_millis(1));
    }
    let received = sim.received();
    let burst = burst_at_end(&received);
    out.line(format_args!("  stop     driver.close() -> {} × (0, 0) at the end of the stream", burst));
    report.checks.push(Check::new("stop: burst of 3 × (0, 0)", burst >= 3, format!("{burst} stop frames")));
    report.checks.push(Check::new(
        "battery and all-state polls answered",
        battery_volts.is_some() && all_state_seen.iter().all(|&n| n > 0),
        format!(
            "battery {:.2} V, all-state {}/{}",
            battery_volts.unwrap_or(f32::NAN),
            all_state_seen[0],
            all_state_seen[1]
        ),
    ));
    report.checks.push(Check::new(
        format!("line noise: {GARBAGE_BYTES} garbage bytes skipped by the decoder"),
        stats.link.decoder.skipped_bytes == GARBAGE_BYTES as u64,
        format!("skipped {} rejected {}", stats.link.decoder.skipped_bytes, stats.link.decoder.rejected_candidates),
    ));

    // Rates and jitter as the chassis saw them: |interval between 0xA5 frames − period|.
    // The stop burst is sent back to back by design: the stream is measured up to it.
    let arrivals: Vec<Instant> = received
        .iter()
        .take(before_stop)
        .filter(|r| matches!(r.frame, HostFrame::PcControl(_)))
        .map(|r| r.at)
        .collect();
    let rate = arrivals.len().saturating_sub(1) as f64
        / arrivals.last().zip(arrivals.first()).map_or(1.0, |(l, f)| (*l - *f).as_secs_f64().max(1e-9));
    let period_us = 1e6 / control_rate_hz;
    let mut jitter: LatenessRing<4096> = LatenessRing::new();
    for w in arrivals.windows(2) {
        jitter.record(((w[1] - w[0]).as_micros() as f64 - period_us).abs() as u32);
    }
    let sim_stats = sim.stats();
    report.checks.push(Check::timing(
        "kmc: control stream at ~100 Hz",
        (90.0..=110.0).contains(&rate),
        format!("{rate:.1} Hz"),
    ));

    report.commanded.push("silence 600 ms, then close()".into());
    report.observed.push(format!(
        "(0, 0) after {} ms, {burst} × stop",
        timeout_stop.map_or("never".into(), |d| d.as_millis().to_string())
    ));
    let seconds = elapsed.as_secs_f64();
    report.rates_hz = vec![
        ("0xA5 at chassis", rate),
        ("speed reports", speed_reports.iter().sum::<u64>() as f64 / (phase_time.as_secs_f64() * PHASES.len() as f64)),
        ("frames in", stats.frames_received as f64 / seconds),
    ];
    report.timings = vec![("send lateness", stats.control_lateness), ("0xA5 jitter", jitter.summary())];
    report.checks.push(Check::on_time("kmc 0xA5 stream", &stats.control_lateness));
    report.counters = vec![
        ("host frames", stats.link.decoder.frames),
        ("host skipped B", stats.link.decoder.skipped_bytes),
        ("host rejected", stats.link.decoder.rejected_candidates),
        ("chassis frames", sim_stats.decoder.frames),
        ("chassis skipped B", sim_stats.decoder.skipped_bytes),
        ("queue dropped", stats.queue_dropped),
    ];
    report.faults = vec![
        InjectedFault::new(
            format!("noise {GARBAGE_BYTES} B"),
            stats.link.decoder.skipped_bytes == GARBAGE_BYTES as u64,
            format!("skipped {} B", stats.link.decoder.skipped_bytes),
        ),
        InjectedFault::new(
            format!("{} reply lost", sim_stats.responses_dropped),
            speed_reports[1] > 0,
            format!("next used ({})", speed_reports[1]),
        ),
        InjectedFault::new(
            "stale command",
            timeouts == 1 && timeout_stop.is_some(),
            format!("(0, 0) at {} ms", timeout_stop.unwrap_or_default().as_millis()),
        ),
    ];
    Ok(report)
}
