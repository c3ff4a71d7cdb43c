//! The LowCmd/LowState scenario: a 500 Hz loop on absolute deadlines (robowire's schedule, each
//! wait finished the runner's way) that does what a Unitree
//! low-level controller does each cycle: build a `LowCmd`, encode it (struct image with CRC, and
//! the XCDR1 payload published on `rt/lowcmd`), decode and verify it as the robot would, answer
//! with a `LowState` and verify that too. Every 50th image gets a flipped bit, which must be
//! caught by the CRC.

use std::time::{Duration, Instant};

use lowcmd_proto::{CdrEncoding, DecodeError, LowCmd, LowState, Message, MotorCmd};
use robowire_core::schedule::Periodic;
use robowire_core::timing::LatenessRing;
use robowire_rt::runner::{DEFAULT_SPIN, sleep_until};
use robowire_rt::stats::micros;

use super::{Check, DeviceReport, InjectedFault, Progress, Status};
use crate::output::Output;

const PERIOD: Duration = Duration::from_millis(2);
const STAND_RAD: [f32; 3] = [0.0, 0.67, -1.3];

pub(super) fn run(duration_s: f64, out: &Output) -> anyhow::Result<DeviceReport> {
    out.line(format_args!("== Unitree LowCmd / LowState (encode, CDR, decode, verify at 500 Hz) =="));
    let run_for = Duration::from_secs_f64(duration_s.max(1.0));
    let mut lateness: LatenessRing<4096> = LatenessRing::new();
    let mut work: LatenessRing<4096> = LatenessRing::new();
    let (mut cycles, mut mismatches, mut corrupted, mut caught) = (0u64, 0u64, 0u64, 0u64);
    let mut cdr = [0u8; 1200];
    let mut progress = Progress::new("lowcmd", out);
    let mut window_late_us = 0u32;
    let start = Instant::now();
    robowire_rt::set_fine_timer_slack();
    let mut grid = Periodic::new(robowire_rt::now() + PERIOD, PERIOD);
    while start.elapsed() < run_for {
        sleep_until(grid.deadline(), DEFAULT_SPIN);
        let woke = Instant::now();
        let Some(tick) = grid.poll(robowire_rt::now()) else { continue };
        let late_us = micros(tick.lateness);
        lateness.record(late_us);
        window_late_us = window_late_us.max(late_us);

        // The controller: a slow sway of the calves around the stand pose.
        let t = start.elapsed().as_secs_f32();
        let mut cmd = LowCmd::default();
        for (i, motor) in cmd.motor_cmd.iter_mut().take(12).enumerate() {
            let sway = if i % 3 == 2 { 0.1 * (t * std::f32::consts::TAU).sin() } else { 0.0 };
            *motor = MotorCmd::servo(STAND_RAD[i % 3] + sway, 0.0, 60.0, 5.0, 0.0);
        }
        let image = cmd.to_image();
        let n = cmd.encode_cdr(CdrEncoding::Xcdr1, &mut cdr)?;
        // The robot's side: the payload decodes and verifies to the same command.
        let received = LowCmd::decode_cdr(&cdr[..n]).map(|(c, _)| c);
        let from_image = LowCmd::decode_image(&image);
        let same = |c: &LowCmd| c.motor_cmd.iter().zip(&cmd.motor_cmd).all(|(a, b)| a.q == b.q && a.kp == b.kp);
        if !(received.as_ref().is_ok_and(same) && from_image.as_ref().is_ok_and(same)) {
            mismatches += 1;
        }
        // Its answer: the joints where they were told to be.
        let mut state = LowState::default();
        for (s, c) in state.motor_state.iter_mut().zip(&cmd.motor_cmd) {
            s.q = c.q;
        }
        state.tick = u32::try_from(cycles).unwrap_or(u32::MAX).into();
        let state_image = state.to_image();
        if !LowState::decode_image(&state_image)
            .is_ok_and(|s| s.tick == state.tick && s.motor_state[2].q == state.motor_state[2].q)
        {
            mismatches += 1;
        }
        // Fault: a flipped bit on the way.
        if cycles % 50 == 49 {
            let mut bad = image;
            bad[100 + (cycles as usize / 50) % 600] ^= 0x04;
            corrupted += 1;
            if matches!(LowCmd::decode_image(&bad), Err(DecodeError::CrcMismatch { .. })) {
                caught += 1;
            }
        }
        work.record(u32::try_from(woke.elapsed().as_micros()).unwrap_or(u32::MAX));
        cycles += 1;
        if progress.due() {
            progress.show(&Status {
                mode: "servo sway",
                motion: format!("calf {:+.3} rad", cmd.motor_cmd[2].q),
                loop_count: cycles,
                lateness_us: (std::mem::take(&mut window_late_us), "max"),
            });
        }
    }
    let elapsed = start.elapsed().as_secs_f64();
    let rate_hz = cycles as f64 / elapsed;
    let (late, busy) = (lateness.summary(), work.summary());
    out.line(format_args!(
        "  loop     {cycles} cycles in {elapsed:.1} s = {rate_hz:.0} Hz · lateness p50 {} µs p99 {} µs · work per cycle p50 {} µs p99 {} µs",
        late.p50_us,
        late.p99_us,
        busy.p50_us,
        busy.p99_us
    ));
    out.line(format_args!("  verify   {} round trips (image + XCDR1 + LowState), {mismatches} mismatches", cycles));
    out.line(format_args!("  fault    {corrupted} images with a flipped bit, {caught} caught by the CRC"));
    let mut report = DeviceReport::new("lowcmd");
    report.commanded = vec!["12 motors, sway ±0.1 rad".into(), "image, XCDR1, LowState".into()];
    report.observed = vec![format!("{cycles} round trips"), format!("{mismatches} mismatches")];
    report.rates_hz = vec![("loop", rate_hz)];
    report.timings = vec![("lateness", late), ("work per cycle", busy)];
    report.counters = vec![
        ("images decoded", 2 * cycles + corrupted),
        ("CDR decoded", cycles),
        ("mismatches", mismatches),
        ("CRC rejects", caught),
    ];
    report.faults = vec![InjectedFault::new(
        format!("{corrupted} bit flips"),
        corrupted > 0 && caught == corrupted,
        format!("{caught} caught"),
    )];
    report.checks = vec![
        Check::new(
            "lowcmd: 500 Hz encode/decode/verify loop",
            (rate_hz - 500.0).abs() < 25.0 && mismatches == 0,
            format!("{rate_hz:.0} Hz, {mismatches} mismatches, work p99 {} µs", busy.p99_us),
        ),
        Check::new(
            "lowcmd: every corrupted image caught by the CRC",
            corrupted > 0 && caught == corrupted,
            format!("{caught} of {corrupted}"),
        ),
        Check::on_time("lowcmd: 500 Hz loop", &late),
    ];
    Ok(report)
}
