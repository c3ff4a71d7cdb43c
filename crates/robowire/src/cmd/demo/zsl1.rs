//! The ZSL-1 scenario: a ZSL-1 on loopback UDP driven through the HighLevel client the way a
//! user's program would: stand, walk a square (closed loop on the reported position and
//! heading), attitude, a trick, faults (error word, silence), lie down.

use robowire_record::RecordLinks;
use std::time::{Duration, Instant};

use anyhow::Context;
use robowire_devices::{DeviceKind, OpenOptions, Simulator};
use robowire_sim::zsl1::{STANDING_HEIGHT_M, Zsl1Fault, Zsl1Sim};
use zsl::udp::{Action, CallError, Connection, ControlMode, Device, HighLevel, Latched, ReturnCode};

use super::{Check, DeviceReport, InjectedFault, Progress, Status};
use crate::output::Output;

const WAIT: Duration = Duration::from_secs(3);
/// Control period of the demo's own loops.
const TICK: Duration = Duration::from_millis(20);

/// Return codes of the calls, for the summary.
#[derive(Default)]
struct Calls(Vec<(String, u32)>);

impl Calls {
    fn record(&mut self, name: &str, result: &Result<Latched, CallError>) {
        let code = result.as_ref().map_or_else(|e| e.return_code(), |latched| latched.return_code);
        self.0.push((name.to_string(), code.raw()));
    }
}

fn wrap(angle: f32) -> f32 {
    (angle + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI
}

/// |v| clamped into the call's band `min..=max`, sign kept; 0 stays 0.
fn banded(v: f32, min: f32, max: f32) -> f32 {
    if v == 0.0 { 0.0 } else { v.signum() * v.abs().clamp(min, max) }
}

async fn settle(dog: &HighLevel) -> bool {
    dog.wait_for_state(WAIT, move |s| s.body.body_velocity_mps[0].abs() < 0.03 && s.body.imu.gyro_radps[2].abs() < 0.03)
        .await
        .is_some()
}

/// Walks `distance_m` straight ahead, closed loop on the reported position: P control on the
/// distance left, done when it is within 1.5 cm and the body has stopped.
async fn walk(dog: &HighLevel, distance_m: f32, calls: &mut Calls) -> anyhow::Result<()> {
    let start = dog.position().context("no state")?;
    let yaw = dog.rpy().context("no state")?[2];
    let deadline = Instant::now() + WAIT;
    while Instant::now() < deadline {
        let s = dog.state().context("state lost while walking")?;
        let p = s.body.position_m;
        let remaining = distance_m - ((p[0] - start[0]) * yaw.cos() + (p[1] - start[1]) * yaw.sin());
        let speed = s.body.body_velocity_mps[0];
        let vx = if remaining.abs() < 0.015 { 0.0 } else { banded(5.0 * remaining, 0.05, 0.8) };
        if vx == 0.0 && speed.abs() < 0.03 {
            break;
        }
        let result = dog.move_velocity(vx, 0.0, 0.0);
        if result.is_err() {
            calls.record("move", &result);
            result?;
        }
        tokio::time::sleep(TICK).await;
    }
    let result = dog.move_velocity(0.0, 0.0, 0.0);
    calls.record("move(0, 0, 0)", &result);
    result?;
    Ok(())
}

/// Turns to `heading_rad`, closed loop on the reported yaw and yaw rate.
async fn turn_to(dog: &HighLevel, heading_rad: f32) -> anyhow::Result<()> {
    let deadline = Instant::now() + WAIT;
    while Instant::now() < deadline {
        let s = dog.state().context("state lost while turning")?;
        let error = wrap(heading_rad - s.body.imu.rpy_rad[2]);
        let wz = if error.abs() < 0.01 { 0.0 } else { banded(5.0 * error, 0.02, 2.0) };
        if wz == 0.0 && s.body.imu.gyro_radps[2].abs() < 0.03 {
            break;
        }
        dog.move_velocity(0.0, 0.0, wz)?;
        tokio::time::sleep(TICK).await;
    }
    dog.move_velocity(0.0, 0.0, 0.0)?;
    Ok(())
}

async fn stand(dog: &HighLevel, calls: &mut Calls, name: &str) -> anyhow::Result<bool> {
    let result = dog.stand_up();
    calls.record(name, &result);
    result?;
    let up =
        |s: &zsl::udp::RobotState| s.body.mode == ControlMode::Stand && s.body.position_m[2] > STANDING_HEIGHT_M - 0.01;
    Ok(dog.wait_for_state(WAIT, up).await.is_some())
}

pub(super) fn run(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(scenario(duration_s, out, record))
}

/// The live line, until the scenario ends.
async fn show_progress(dog: &HighLevel, out: &Output) -> std::convert::Infallible {
    let mut progress = Progress::new("zsl1", out);
    loop {
        tokio::time::sleep(Duration::from_millis(50)).await;
        if progress.due() {
            let stats = dog.stats();
            let mode = dog.control_mode().map_or_else(|| format!("{:?}", dog.connection()), |m| format!("{m:?}"));
            progress.show(&Status {
                mode: &mode,
                motion: dog.state().map_or("-".into(), |s| format!("{:+.3} m/s", s.body.body_velocity_mps[0])),
                loop_count: stats.link.sent,
                lateness_us: (stats.stream_lateness.p99_us, "p99"),
            });
        }
    }
}

async fn scenario(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    out.line(format_args!("== ZSL-1 high level (simulator on loopback UDP, 500 Hz) =="));
    // The vendor's 3 s watchdog, shortened so the silence fault fits in a short demo.
    let watchdog = Duration::from_millis(500);
    let device = super::open_simulated(
        DeviceKind::Zsl1,
        &OpenOptions { state_timeout: Some(watchdog), record: record.cloned(), ..Default::default() },
    )?;
    let (Some(Simulator::Zsl1(sim)), Some(dog)) = (device.simulator(), device.zsl()) else {
        anyhow::bail!("sim:zsl1 opened something other than a simulated ZSL-1");
    };
    out.line(format_args!("simulator HighLevel {} · client {}", sim.high_level_addr(), dog.local_addr()));
    tokio::select! {
        report = steps(sim, dog, watchdog, duration_s, out) => report,
        never = show_progress(dog, out) => match never {},
    }
}

async fn steps(
    sim: &Zsl1Sim,
    dog: &HighLevel,
    watchdog: Duration,
    duration_s: f64,
    out: &Output,
) -> anyhow::Result<DeviceReport> {
    let started = Instant::now();
    let mut calls = Calls::default();
    let mut report = DeviceReport::new("zsl1");

    let mut phase = Instant::now();
    let mut lap = move || {
        let seconds = phase.elapsed().as_secs_f64();
        phase = Instant::now();
        format!("({seconds:.1} s)")
    };
    let connected = dog.wait_connected(WAIT).await;
    report.checks.push(Check::new(
        "zsl1: state arrives, client connects",
        connected,
        format!("{:?}", dog.connection()),
    ));
    anyhow::ensure!(connected, "the ZSL-1 simulator sends no state");

    // Stand up.
    let stood = stand(dog, &mut calls, "stand_up").await?;
    let height = dog.position().map_or(0.0, |p| p[2]);
    out.line(format_args!(
        "  stand    stand_up -> mode {:?}, body at {height:.2} m {}",
        dog.control_mode().unwrap_or(ControlMode::Passive),
        lap()
    ));
    report.checks.push(Check::new("zsl1: stands up (mode 1, standing height)", stood, format!("height {height:.2} m")));
    report.commanded.push("stand_up".into());
    report.observed.push(format!("standing, body {height:.2} m"));
    tokio::time::sleep(Duration::from_millis(200)).await;

    // Walk a square, closed loop on position and heading.
    let side_m = (duration_s as f32 * 0.1).clamp(0.3, 2.0);
    let origin = dog.position().context("no state")?;
    let heading0 = dog.rpy().context("no state")?[2];
    let mut corners = Vec::new();
    for corner in 1..=4 {
        walk(dog, side_m, &mut calls).await?;
        turn_to(dog, wrap(heading0 + corner as f32 * std::f32::consts::FRAC_PI_2)).await?;
        let p = dog.position().context("no state")?;
        corners.push((p[0] - origin[0], p[1] - origin[1]));
    }
    let end = dog.position().context("no state")?;
    let closure_m = (end[0] - origin[0]).hypot(end[1] - origin[1]);
    let heading_error = wrap(dog.rpy().context("no state")?[2] - heading0).abs();
    let walked = sim.snapshot().robot.distance_m();
    out.line(format_args!(
        "  square   {side_m:.2} m sides: corners {} · back within {:.3} m, heading error {:.3} rad, walked {walked:.2} m {}",
        corners.iter().map(|(x, y)| format!("({x:+.2}, {y:+.2})")).collect::<Vec<_>>().join(" "),
        closure_m,
        heading_error,
        lap()
    ));
    report.checks.push(Check::new(
        "zsl1: walks a square and returns to the start",
        closure_m < 0.05 && heading_error < 0.02 && walked > 3.5 * side_m,
        format!("closure {closure_m:.3} m, heading {heading_error:.3} rad, walked {walked:.2} m"),
    ));
    report.commanded.push(format!("square, {side_m:.2} m sides"));
    report.observed.push(format!("back within {:.0} mm", closure_m * 1e3));

    // Attitude: roll one way for 0.4 s, back, zero rates.
    let result = dog.attitude_control(0.5, 0.0, 0.0, 0.0);
    calls.record("attitude_control(0.5, 0, 0, 0)", &result);
    tokio::time::sleep(Duration::from_millis(400)).await;
    let rolled = dog.rpy().map_or(0.0, |r| r[0]);
    let result_back = dog.attitude_control(-0.5, 0.0, 0.0, 0.0);
    calls.record("attitude_control(-0.5, 0, 0, 0)", &result_back);
    tokio::time::sleep(Duration::from_millis(400)).await;
    let back = dog.rpy().map_or(1.0, |r| r[0]);
    let zero = dog.attitude_control(0.0, 0.0, 0.0, 0.0);
    calls.record("attitude_control(0, 0, 0, 0)", &zero);
    out.line(format_args!(
        "  attitude roll +0.5 rad/s for 0.4 s -> {rolled:+.2} rad, back -> {back:+.2} rad {}",
        lap()
    ));
    report.checks.push(Check::new(
        "zsl1: attitude rates roll the body and back",
        result.is_ok() && result_back.is_ok() && rolled > 0.15 && back.abs() < 0.05,
        format!("roll {rolled:+.2} rad, then {back:+.2} rad"),
    ));
    report.commanded.push("roll +0.5, -0.5 rad/s".into());
    report.observed.push(format!("roll {rolled:+.2}, {back:+.2} rad"));

    // A trick: jump, back to standing.
    let tricks_before = sim.snapshot().robot.tricks_done();
    let result = dog.jump();
    calls.record("jump", &result);
    let airborne = dog.wait_for_state(WAIT, move |s| s.body.position_m[2] > STANDING_HEIGHT_M + 0.05).await.is_some();
    let landed =
        dog.wait_for_state(WAIT, move |s| (s.body.position_m[2] - STANDING_HEIGHT_M).abs() < 0.01).await.is_some();
    let action_cleared = dog.wire_command().action_code() == Action::None;
    let tricks = sim.snapshot().robot.tricks_done() - tricks_before;
    out.line(format_args!(
        "  trick    jump -> airborne {airborne}, landed standing {landed}, action cleared after 6 datagrams {action_cleared} {}",
        lap()
    ));
    report.checks.push(Check::new(
        "zsl1: jumps and lands standing",
        result.is_ok() && airborne && landed && tricks == 1,
        format!("{tricks} trick done"),
    ));
    report.commanded.push("jump".into());
    report.observed.push(format!("{} and landed", if airborne { "airborne" } else { "not airborne" }));

    // Fault: a motor fault in the error word refuses calls with the robot's word.
    sim.inject(Zsl1Fault::ErrorWord(ReturnCode::MotorFault));
    dog.wait_for_state(WAIT, move |s| s.body.error.is_some()).await;
    let refused = dog.stand_up();
    calls.record("stand_up during motor fault", &refused);
    sim.clear_faults();
    dog.wait_for_state(WAIT, move |s| s.body.error.is_none()).await;
    let code = refused.as_ref().err().map(CallError::return_code);
    out.line(format_args!(
        "  fault    error word 0x3011 -> stand_up returns {code:?}; the stream forced passive {}",
        lap()
    ));
    report.checks.push(Check::new(
        "zsl1: motor fault reported as the call's return code",
        code == Some(ReturnCode::MotorFault),
        format!("{code:?}"),
    ));

    // Fault: the dog falls silent while walking; the client stops the walk and reconnects.
    stand(dog, &mut calls, "stand_up").await?;
    let result = dog.move_velocity(0.4, 0.0, 0.0);
    calls.record("move(0.4, 0, 0)", &result);
    if let Err(e) = &result {
        out.line(format_args!("  move(0.4, 0, 0) refused: {e}"));
    }
    dog.wait_for_state(WAIT, move |s| s.body.body_velocity_mps[0] > 0.35).await;
    let mut events = dog.connection_events();
    events.borrow_and_update();
    sim.inject(Zsl1Fault::Silence);
    let silent_at = Instant::now();
    let lost = tokio::time::timeout(WAIT, events.wait_for(|c| *c == Connection::Disconnected)).await.is_ok();
    let noticed = silent_at.elapsed();
    let latched_vx = dog.wire_command().vx.get();
    sim.clear_faults();
    let back = tokio::time::timeout(WAIT, events.wait_for(|c| *c == Connection::Connected)).await.is_ok();
    let stopped = settle(dog).await;
    out.line(format_args!(
        "  fault    robot silent -> Disconnected after {:.0} ms, latched vx {latched_vx} m/s, reconnected {back}, robot stopped {stopped} {}",
        noticed.as_secs_f64() * 1e3,
        lap()
    ));
    report.checks.push(Check::new(
        "zsl1: silence noticed, walk stopped, reconnected",
        lost && latched_vx == 0.0 && back && stopped,
        format!("after {:.0} ms (watchdog {} ms)", noticed.as_secs_f64() * 1e3, watchdog.as_millis()),
    ));
    report.checks.push(Check::timing(
        "zsl1: silence noticed within 500 ms of the watchdog",
        noticed < watchdog + Duration::from_millis(500),
        format!("after {:.0} ms (watchdog {} ms)", noticed.as_secs_f64() * 1e3, watchdog.as_millis()),
    ));

    report.faults.push(InjectedFault::new(
        "motor fault",
        code == Some(ReturnCode::MotorFault),
        code.map_or("call accepted".into(), |c| format!("{c:?} returned")),
    ));
    report.faults.push(InjectedFault::new(
        "silence",
        lost && back,
        format!("lost at {:.0} ms, back", noticed.as_secs_f64() * 1e3),
    ));

    // Lie down.
    let result = dog.lie_down();
    calls.record("lie_down", &result);
    let lying = dog.wait_for_state(WAIT, move |s| s.body.position_m[2] < 0.12).await.is_some();
    out.line(format_args!(
        "  lie      lie_down -> mode {:?} {}",
        dog.control_mode().unwrap_or(ControlMode::Passive),
        lap()
    ));
    report.checks.push(Check::new(
        "zsl1: lies down (mode 51, body low)",
        result.is_ok() && lying,
        format!("{:?}", dog.control_mode()),
    ));
    report.commanded.push("lie_down".into());
    report.observed.push(format!("{:?}", dog.control_mode().unwrap_or(ControlMode::Passive)));

    let stats = dog.stats();
    let snapshot = sim.snapshot();
    let [x, y, _] = snapshot.robot.position_m();
    out.line(format_args!(
        "  calls    {}",
        calls.0.iter().map(|(n, c)| format!("{n} 0x{c:04x}")).collect::<Vec<_>>().join(", ")
    ));
    out.line(format_args!(
        "  body     at ({x:+.2}, {y:+.2}) m, walked {:.2} m, battery {:.1} %, {} tricks",
        snapshot.robot.distance_m(),
        snapshot.robot.battery_percent(),
        snapshot.robot.tricks_done()
    ));
    let seconds = started.elapsed().as_secs_f64();
    report.rates_hz =
        vec![("commands sent", stats.link.sent as f64 / seconds), ("states in", stats.states as f64 / seconds)];
    report.timings = vec![
        ("send lateness", stats.stream_lateness),
        ("at sim |Δ-2ms|", snapshot.high_level.command_jitter),
        ("sim send lateness", snapshot.state_lateness),
        ("state gap", stats.state_gap),
    ];
    report.checks.push(Check::on_time("zsl1: client command stream", &stats.stream_lateness));
    report.checks.push(Check::on_time("zsl1: simulator state stream", &snapshot.state_lateness));
    report.counters = vec![
        ("states", stats.states),
        ("decode errors", stats.link.decode_errors),
        ("short states", stats.short_states),
        ("foreign dropped", stats.link.foreign_dropped),
        ("disconnects", stats.disconnects),
        ("sim commands", snapshot.high_level.commands),
        ("sim invalid", snapshot.high_level.invalid),
    ];
    report.checks.push(Check::new(
        "zsl1: every command decoded strictly by the simulator",
        snapshot.high_level.invalid == 0 && snapshot.high_level.commands > 0,
        format!("{} commands, {} invalid", snapshot.high_level.commands, snapshot.high_level.invalid),
    ));
    Ok(report)
}
