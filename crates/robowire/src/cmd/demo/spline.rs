//! The low-level scenario: a 1 kHz PD loop through shared memory that moves all legs from the
//! lying pose to a stand pose and holds it, with a hung daemon injected and detected on the way.

use robowire_record::RecordLinks;
use std::time::{Duration, Instant};

use anyhow::Context;
use robowire_core::timing::LatenessRing;
use robowire_devices::{SPLINE_IMU_LINK, SPLINE_LINK};
use robowire_sim::spline::{LYING_POSE_RAD, STANDING_POSE_RAD, SplineSim, SplineSimConfig};
use zsl::spline::{ImuReader, SplineError};
use zsl::{JointControl, JointIndex, Leg, SplineClient, SplineCommandBlock};

use super::{Check, DeviceReport, InjectedFault, Progress, Status};
use crate::output::Output;

const KP: f32 = 60.0;
const KD: f32 = 2.0;

/// The pose `fraction` of the way from lying to standing (smooth-step).
fn pose_at(fraction: f32) -> [f32; 3] {
    let s = fraction.clamp(0.0, 1.0);
    let s = s * s * (3.0 - 2.0 * s);
    [0, 1, 2].map(|j| LYING_POSE_RAD[j] + (STANDING_POSE_RAD[j] - LYING_POSE_RAD[j]) * s)
}

fn command(pose: [f32; 3]) -> SplineCommandBlock {
    let mut cmd = SplineCommandBlock::default();
    for leg in Leg::ALL {
        for (j, joint) in JointIndex::ALL.into_iter().take(3).enumerate() {
            *cmd.joint_mut(leg, joint) = JointControl::new(pose[j], 0.0, KP, KD, 0.0);
        }
    }
    cmd
}

/// The controller reads the IMU every this many cycles.
const IMU_EVERY: u64 = 10;

pub(super) fn run(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    out.line(format_args!("== ZSL-1 low level (spline daemon on shared memory, 1 kHz) =="));
    let sim = SplineSim::spawn(SplineSimConfig::private("demo")).context("starting the spline daemon simulator")?;
    let names = sim.config().clone();
    out.line(format_args!("simulator on {} and {}", names.spline_name, names.imu_name));
    let mut client = SplineClient::open(&names.spline_name)?;
    let mut imu = ImuReader::open(&names.imu_name)?;
    if let Some(record) = record {
        client = client.with_tap(record.link(SPLINE_LINK, &zsl_proto::description::SPLINE_CLIENT));
        imu = imu.with_tap(record.link(SPLINE_IMU_LINK, &zsl_proto::description::IMU));
    }

    let move_time = Duration::from_secs_f64((duration_s / 2.0).max(0.5));
    let hold_time = Duration::from_secs_f64((duration_s / 2.0).max(0.5));
    // Jitter of the loop: |interval between commands − 1 ms|.
    let mut jitter: LatenessRing<16384> = LatenessRing::new();
    let mut last_write: Option<Instant> = None;
    let mut timeouts = 0u64;
    // Stalls the client reported during the loop, before the injected one: a busy machine can
    // hold the daemon's thread past the 10 ms bound; the loop goes on, as a controller would.
    let mut stalls = 0u64;
    let mut cycles = 0u64;
    let start = Instant::now();
    let daemon_before = sim.stats().daemon;
    // The loop runs on the daemon's clock: each fresh state triggers the next command.
    let mut phase_printed = false;
    let mut progress = Progress::new("spline", out);
    let mut window_jitter_us = 0u32;
    while start.elapsed() < move_time + hold_time {
        let knee_rad = match client.wait_state(Duration::from_millis(5)) {
            Ok(state) => state.joint(Leg::FrontRight, JointIndex::Knee).p.get(),
            Err(SplineError::Timeout { .. }) => {
                timeouts += 1;
                continue;
            }
            Err(SplineError::DaemonStalled { .. }) => {
                stalls += 1;
                continue;
            }
            Err(e) => return Err(e).context("the daemon stopped answering during the PD loop"),
        };
        let now = Instant::now();
        if let Some(last) = last_write {
            let interval_us = (now - last).as_micros() as i64;
            let jitter_us = u32::try_from((interval_us - 1000).unsigned_abs()).unwrap_or(u32::MAX);
            jitter.record(jitter_us);
            window_jitter_us = window_jitter_us.max(jitter_us);
        }
        last_write = Some(now);
        let elapsed = start.elapsed();
        let fraction = elapsed.as_secs_f32() / move_time.as_secs_f32();
        client.write_command(&command(pose_at(fraction)))?;
        cycles += 1;
        if cycles.is_multiple_of(IMU_EVERY) {
            // The attitude, as a controller would read it (the demo itself only uses its age).
            let _ = imu.read();
        }
        if progress.due() {
            progress.show(&Status {
                mode: if elapsed < move_time { "stand-up" } else { "hold" },
                motion: format!("knee {knee_rad:+.3} rad"),
                loop_count: cycles,
                lateness_us: (std::mem::take(&mut window_jitter_us), "max"),
            });
        }
        if !phase_printed && elapsed >= move_time {
            out.line(format_args!(
                "  move     lying {LYING_POSE_RAD:?} -> stand {STANDING_POSE_RAD:?} rad over {:.1} s",
                move_time.as_secs_f64()
            ));
            phase_printed = true;
        }
    }
    // The state the loop left (a stall of a busy machine's daemon thread is waited out).
    let state = loop {
        match client.wait_state(Duration::from_millis(50)) {
            Ok(state) => break state,
            Err(SplineError::DaemonStalled { .. }) => stalls += 1,
            Err(e) => return Err(e).context("no state after the PD loop"),
        }
    };
    let worst = Leg::ALL
        .iter()
        .flat_map(|&leg| JointIndex::ALL.into_iter().take(3).enumerate().map(move |(j, joint)| (leg, joint, j)))
        .map(|(leg, joint, j)| (state.joint(leg, joint).p.get() - STANDING_POSE_RAD[j]).abs())
        .fold(0.0f32, f32::max);
    out.line(format_args!(
        "  hold     {:.1} s at the stand pose: largest joint error {worst:.4} rad",
        hold_time.as_secs_f64()
    ));
    let daemon = sim.stats().daemon;
    let fresh = daemon.fresh - daemon_before.fresh;
    let repeated = daemon.repeated - daemon_before.repeated;

    // Fault: the daemon hangs for 30 ms; the client must notice within its 10 ms bound.
    sim.pause(true);
    let paused_at = Instant::now();
    let noticed = loop {
        match client.wait_state(Duration::from_millis(100)) {
            Ok(_) => continue,
            Err(SplineError::DaemonStalled { .. }) => break Some(paused_at.elapsed()),
            Err(_) => break None,
        }
    };
    std::thread::sleep(Duration::from_millis(30).saturating_sub(paused_at.elapsed()));
    sim.pause(false);
    let recovered = client.wait_state(Duration::from_millis(100)).is_ok();
    out.line(format_args!(
        "  fault    daemon hung for 30 ms -> stall reported after {} ms, fresh state again: {}",
        noticed.map_or("never".into(), |d| format!("{:.1}", d.as_secs_f64() * 1e3)),
        if recovered { "yes" } else { "no" }
    ));
    let imu_age = imu.latest_age().ok();

    let loop_jitter = jitter.summary();
    let sim_stats = sim.stats();
    let elapsed = start.elapsed().as_secs_f64();
    out.line(format_args!(
        "  IMU      {} samples, latest age {}",
        sim_stats.imu_samples,
        imu_age.map_or("-".into(), |a| format!("{:.2} ms", a.as_secs_f64() * 1e3))
    ));

    let total = (move_time + hold_time).as_millis() as u64;
    let mut report = DeviceReport::new("spline");
    report.commanded = vec![
        format!("12 joints up, {:.1} s", move_time.as_secs_f64()),
        format!("hold {:.1} s, kp {KP} kd {KD}", hold_time.as_secs_f64()),
    ];
    report.observed = vec![format!("max error {worst:.4} rad"), format!("{fresh} fresh, {repeated} repeated")];
    report.rates_hz = vec![
        ("PD loop", cycles as f64 / (move_time + hold_time).as_secs_f64()),
        ("daemon", sim_stats.cycles as f64 / elapsed),
        ("IMU", sim_stats.imu_samples as f64 / elapsed),
    ];
    report.timings = vec![("loop jitter", loop_jitter), ("daemon lateness", sim_stats.lateness)];
    report.counters = vec![
        ("commands", client.counters().commands_written),
        ("states", client.counters().states_read),
        ("wait timeouts", timeouts),
        ("stalls in the loop", stalls),
        ("IMU reads", imu.counters().reads),
        ("daemon missed", sim_stats.missed_cycles),
    ];
    report.faults = vec![InjectedFault::new(
        "hang 30 ms",
        noticed.is_some() && recovered,
        format!("stall at {:.1} ms", noticed.unwrap_or_default().as_secs_f64() * 1e3),
    )];
    report.checks = vec![
        Check::new("low level: legs reach the stand pose", worst < 0.02, format!("largest error {worst:.4} rad")),
        Check::timing(
            "low level: a fresh command nearly every daemon cycle",
            fresh * 100 >= total * 95,
            format!("{fresh} fresh of ~{total} cycles, {repeated} repeated"),
        ),
        Check::new(
            "low level: hung daemon reported, then recovered",
            noticed.is_some() && recovered,
            format!("after {:.1} ms", noticed.unwrap_or_default().as_secs_f64() * 1e3),
        ),
        Check::timing(
            "low level: hung daemon reported within 10 ms (+ slack)",
            noticed.is_some_and(|d| d <= Duration::from_millis(25)),
            format!("after {:.1} ms", noticed.unwrap_or_default().as_secs_f64() * 1e3),
        ),
        Check::on_time("low level: daemon 1 kHz loop", &sim_stats.lateness),
    ];
    Ok(report)
}
