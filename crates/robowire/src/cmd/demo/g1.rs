//! The G1 scenario: a Unitree G1 humanoid on DDS, the simulated 29-dof G1 and the `g1` client in
//! one process over real DDS participants on loopback (as the Go2 scenario, see `lowcmd`): an arm
//! lifted through `rt/arm_sdk` while the robot's controller balances (the weight ramped in and
//! out), ReleaseMode, the zero posture, an ankle swing in PR then in AB mode, and the two frames
//! G1 users stumble on (a wrong `mode_machine`, a motor left at `mode` 0): refused by the client
//! before anything is sent, and, sent anyway by a raw writer, counted by the robot and not
//! applied.

use std::time::{Duration, Instant};

use anyhow::Context;
use robowire_dds::qos::Qos;
use robowire_record::RecordLinks;
use robowire_rt::device::Device as _;
use robowire_sim::g1::G1Sim;
use unitree::g1::{G1, G1Error, JointCommand, Motion, from_fn};
use unitree_proto::g1::{self as rules, ARM_SDK_JOINTS, JOINTS, ModePr, slot};
use unitree_proto::robot::CommandError;
use unitree_proto::{HgLowCmd, Message};

use super::{Check, DeviceReport, Progress, Status};
use crate::output::Output;

/// The arm pose lifted through `rt/arm_sdk`: both shoulders pitched forward, elbows bent, rad
/// (in `ARM_SDK_JOINTS` order: left arm, right arm, waist).
const ARM_LIFTED: [f32; 17] = [-1.0, 0.3, 0.0, 1.2, 0.0, 0.0, 0.0, -1.0, -0.3, 0.0, 1.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
/// Gains of Unitree's arm examples.
const ARM_KP: f32 = 60.0;
const ARM_KD: f32 = 1.5;
/// The ankle swing: pitch and roll amplitudes, rad, at 1 Hz (Unitree's example: 30° and 10°).
const SWING_PITCH_RAD: f32 = 0.3;
const SWING_ROLL_RAD: f32 = 0.1;
/// Frames of each refused kind sent anyway by a raw writer.
const RAW_FRAMES: u64 = 5;

pub(super) fn run(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    out.line(format_args!(
        "== Unitree G1 over DDS (rt/lowcmd, rt/arm_sdk, rt/lowstate, motion_switcher; simulated 29-dof G1) =="
    ));
    super::on_dds_loopback(out, || scenario(duration_s, out, record))
}

/// `sim:g1`: the simulator and the client on DDS domain 0, interface lo.
fn open(record: Option<&RecordLinks>) -> anyhow::Result<robowire_devices::AnyDevice> {
    let options = robowire_devices::OpenOptions { record: record.cloned(), ..robowire_devices::OpenOptions::default() };
    super::open_simulated(robowire_devices::DeviceKind::G1, &options)
}

/// A command that holds `q` with the ankles' pitch and roll given as A and B motor angles (AB
/// mode).
fn hold_ab(mode_machine: u8, q: &[f32; JOINTS]) -> HgLowCmd {
    let mut cmd = rules::hold(q, mode_machine, rules::G1Variant::Dof29);
    cmd.mode_pr = ModePr::Ab as u8;
    for (pitch, roll) in rules::PARALLEL_PAIRS {
        let (a, b) = rules::pr_to_ab(q[pitch], q[roll]);
        cmd.motor_cmd[roll].q = a.into();
        cmd.motor_cmd[pitch].q = b.into();
    }
    cmd
}

/// The zero posture with the ankles swung at `t_s` seconds into the swing.
fn swing(t_s: f32) -> [f32; JOINTS] {
    let phase = (2.0 * std::f32::consts::PI * t_s).sin();
    let mut q = [0.0; JOINTS];
    q[slot::LEFT_ANKLE_PITCH] = SWING_PITCH_RAD * phase;
    q[slot::LEFT_ANKLE_ROLL] = SWING_ROLL_RAD * phase;
    q[slot::RIGHT_ANKLE_PITCH] = SWING_PITCH_RAD * phase;
    q[slot::RIGHT_ANKLE_ROLL] = -SWING_ROLL_RAD * phase;
    q
}

/// Waits (2 ms steps, at most `limit`) until `done` holds; whether it did.
async fn until(limit: Duration, mut done: impl FnMut() -> bool) -> bool {
    let began = Instant::now();
    while !done() {
        if began.elapsed() > limit {
            return false;
        }
        tokio::time::sleep(Duration::from_millis(2)).await;
    }
    true
}

/// Refreshes the arm command toward weight `target` every 20 ms until `done` holds (at most
/// `limit`); whether it did.
async fn arm_until(robot: &G1, target: f32, limit: Duration, mut done: impl FnMut() -> bool) -> anyhow::Result<bool> {
    let began = Instant::now();
    let mut ticker = tokio::time::interval(Duration::from_millis(20));
    while !done() {
        if began.elapsed() > limit {
            return Ok(false);
        }
        robot.set_arm_weight(target)?;
        ticker.tick().await;
    }
    Ok(true)
}

/// What one phase of the 500 Hz loop observed of the simulator's left ankle pitch.
#[derive(Debug, Default, Clone, Copy)]
struct Swing {
    min: f32,
    max: f32,
}

/// Hands `motion` to the 500 Hz LowCmd stream, which steps it on its own deadlines, and waits
/// for its end; the left ankle pitch's range as the simulator reports it, looked at with each
/// LowState.
async fn follow(
    sim: &G1Sim,
    robot: &G1,
    motion: impl Motion<HgLowCmd> + Send + 'static,
    progress: &mut Progress<'_>,
    mode: &str,
) -> anyhow::Result<Swing> {
    let end = robot.follow(motion)?.wait();
    tokio::pin!(end);
    let mut states = robot.states();
    let mut seen = Swing { min: f32::INFINITY, max: f32::NEG_INFINITY };
    loop {
        tokio::select! {
            end = &mut end => {
                end?;
                return Ok(seen);
            }
            changed = states.changed() => {
                if changed.is_err() {
                    (&mut end).await?;
                    return Ok(seen);
                }
            }
        }
        let pitch = sim.snapshot().joints_rad[slot::LEFT_ANKLE_PITCH];
        seen = Swing { min: seen.min.min(pitch), max: seen.max.max(pitch) };
        if progress.due() {
            // The rate shown is the LowCmd stream's (its own 500 Hz thread), across phases.
            let stream = robot.stats().low_level;
            progress.show(&Status {
                mode,
                motion: format!("L ankle pitch {pitch:+.3} rad"),
                loop_count: stream.commands_sent,
                lateness_us: (stream.send_lateness.p99_us, "p99"),
            });
        }
    }
}

fn scenario(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        let started = Instant::now();
        let device = open(record)?;
        let (Some(robowire_devices::Simulator::G1(sim)), Some(robot)) = (device.simulator(), device.g1()) else {
            anyhow::bail!("sim:g1 opened something other than a simulated G1");
        };
        let first = robot.wait_state(Duration::from_secs(10), |_| true).await.context("no rt/lowstate")?;
        let mode_machine = first.mode_machine;
        out.line(format_args!(
            "simulator and client on DDS domain 0, interface lo; LowState tick {}, mode_machine {mode_machine} ({:?})",
            first.tick.get(),
            robot.variant()
        ));
        let phase = Duration::from_secs_f64((duration_s / 3.0).max(0.8));
        let mut progress = Progress::new("g1", out);

        // 1. The arm through rt/arm_sdk while the controller owns the motors: weight in, out.
        let arm: [JointCommand; 17] = std::array::from_fn(|i| JointCommand::hold(ARM_LIFTED[i], ARM_KP, ARM_KD));
        robot.set_arm_joints(&arm)?;
        // The arm command is refreshed at 50 Hz, as a controller does (it goes stale in 500 ms).
        let ramp_limit = Duration::from_secs(6);
        let weight_in = arm_until(robot, 1.0, ramp_limit, || {
            let s = sim.snapshot();
            s.arm_sdk.weight >= 0.999 && (s.joints_rad[slot::LEFT_ELBOW] - ARM_LIFTED[3]).abs() < 0.02
        })
        .await?;
        let lifted = sim.snapshot().joints_rad;
        let arm_error = ARM_SDK_JOINTS
            .iter()
            .zip(ARM_LIFTED)
            .map(|(&slot, q)| (lifted[slot] - q).abs())
            .fold(0.0f32, f32::max);
        let weight_out =
            arm_until(robot, 0.0, ramp_limit, || robot.arm_weight() == 0.0 && sim.snapshot().arm_sdk.weight < 0.01)
                .await?;
        let arm_frames = sim.snapshot().arm_sdk.accepted;
        out.line(format_args!(
            "  arm      rt/arm_sdk while the controller balances: weight 0 -> 1 -> 0 at {}/s, {arm_frames} frames; \
             arm and waist within {arm_error:.3} rad of the lifted pose at weight 1",
            robot.options().arm_sdk.weight_rate_per_s
        ));

        // 2. Release: before it the robot ignores LowCmds.
        let start = robot.joint_positions().context("no state")?;
        // The LowCmd stream runs from this first command on: its rate is taken from here.
        let streaming = Instant::now();
        robot.hold(&start)?;
        progress.loop_started(robot.stats().low_level.commands_sent);
        let ignored = until(Duration::from_secs(5), || sim.snapshot().lowcmd.ignored_mode > 0).await;
        let ignored = if ignored { sim.snapshot().lowcmd.ignored_mode } else { 0 };
        let released = robot.release().await.context("releasing the controller")?;
        let mode_after = robot.mode().await?;
        let loco_refused = matches!(robot.loco().fsm_id().await, Err(G1Error::LocoStateUnavailable { .. }));
        out.line(format_args!(
            "  release  {ignored} LowCmds ignored while mode \"ai\" owned the motors; ReleaseMode × {released} -> {mode_after:?}; \
             loco service {}",
            if loco_refused { "refuses until a mode is selected" } else { "still answers" }
        ));

        // 3. The zero posture, from where the joints are, over a phase; held a moment.
        let from = robot.joint_positions().context("no state")?;
        let to_zero = from_fn(phase, move |elapsed| {
            let ratio = (elapsed.as_secs_f32() / phase.as_secs_f32()).clamp(0.0, 1.0);
            rules::hold(&std::array::from_fn(|i| (1.0 - ratio) * from[i]), mode_machine, rules::G1Variant::Dof29)
        });
        follow(sim, robot, to_zero, &mut progress, "zero").await?;
        let zero = rules::hold(&[0.0; JOINTS], mode_machine, rules::G1Variant::Dof29);
        follow(sim, robot, from_fn(Duration::from_millis(300), move |_| zero), &mut progress, "hold").await?;
        let zero_error = sim.snapshot().joints_rad.iter().fold(0.0f32, |m, q| m.max(q.abs()));
        out.line(format_args!(
            "  zero     every joint from where it stood to 0 rad over {:.1} s: largest |q| {zero_error:.4} rad",
            phase.as_secs_f64()
        ));

        // 4. The ankles swing at 1 Hz, first as pitch/roll joints (PR), then as their A/B motors.
        let swing_pr = from_fn(phase, move |elapsed| {
            rules::hold(&swing(elapsed.as_secs_f32()), mode_machine, rules::G1Variant::Dof29)
        });
        let pr = follow(sim, robot, swing_pr, &mut progress, "swing PR").await?;
        let swing_ab = from_fn(phase, move |elapsed| hold_ab(mode_machine, &swing(elapsed.as_secs_f32())));
        let ab = follow(sim, robot, swing_ab, &mut progress, "swing AB").await?;
        out.line(format_args!(
            "  ankles   ±{SWING_PITCH_RAD} rad pitch at 1 Hz: PR {:+.3}..{:+.3} rad, AB (motors A/B) {:+.3}..{:+.3} rad",
            pr.min, pr.max, ab.min, ab.max
        ));
        follow(sim, robot, from_fn(Duration::from_millis(200), move |_| zero), &mut progress, "hold").await?;

        // 5. The two frames the robot accepts and ignores: refused by the client; sent anyway.
        let mut wrong_machine = rules::hold(&[0.0; JOINTS], mode_machine, rules::G1Variant::Dof29);
        wrong_machine.mode_machine = mode_machine.wrapping_add(1);
        let mut disabled = rules::hold(&[0.0; JOINTS], mode_machine, rules::G1Variant::Dof29);
        disabled.motor_cmd[slot::LEFT_KNEE].mode = 0;
        let refused_machine = matches!(
            robot.set_command(wrong_machine),
            Err(G1Error::Command(CommandError::ModeMachine { .. }))
        );
        let refused_disabled = matches!(
            robot.set_command(disabled),
            Err(G1Error::Command(CommandError::DisabledMotor { motor: slot::LEFT_KNEE }))
        );
        let before = sim.snapshot().lowcmd;
        let raw = robot.low_level().participant().writer::<HgLowCmd>(HgLowCmd::TOPIC, Qos::WRITER)?;
        let _ = until(Duration::from_secs(5), || raw.matched_readers() > 0).await;
        for _ in 0..RAW_FRAMES {
            robot.hold(&[0.0; JOINTS])?;
            raw.write(wrong_machine)?;
            tokio::time::sleep(Duration::from_millis(10)).await;
            robot.hold(&[0.0; JOINTS])?;
            raw.write(disabled)?;
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
        // The robot reads rt/lowcmd with a history of one: a raw frame the 500 Hz stream's next one
        // overwrites before it is read is never seen, so at least one of each is what must arrive.
        let counted = until(Duration::from_secs(2), || {
            let now = sim.snapshot().lowcmd;
            now.bad_mode_machine >= before.bad_mode_machine + RAW_FRAMES
                && now.disabled_motors >= before.disabled_motors + RAW_FRAMES
        })
        .await;
        let after = sim.snapshot().lowcmd;
        let (bad_machine, bad_disabled) =
            (after.bad_mode_machine - before.bad_mode_machine, after.disabled_motors - before.disabled_motors);
        out.line(format_args!(
            "  refused  a wrong mode_machine and a knee at mode 0: refused by the client ({}, {}); sent anyway by a raw \
             writer × {RAW_FRAMES}: the robot counted {bad_machine} wrong mode_machine, {bad_disabled} with a disabled motor",
            if refused_machine { "ModeMachine" } else { "not refused" },
            if refused_disabled { "DisabledMotor" } else { "not refused" },
        ));
        drop(raw);

        robot.damp()?;
        tokio::time::sleep(Duration::from_millis(100)).await;
        let (stats, snapshot) = (robot.stats(), sim.snapshot());
        let low = &stats.low_level;

        let mut report = DeviceReport::new("g1");
        report.commanded = vec![
            "arm lifted via rt/arm_sdk, weight 0 -> 1 -> 0".into(),
            "ReleaseMode (motion_switcher)".into(),
            format!("29 joints to zero, {:.1} s", phase.as_secs_f64()),
            format!("ankle swing PR then AB, {:.1} s each", phase.as_secs_f64()),
            "a wrong mode_machine and a mode-0 motor".into(),
        ];
        report.observed = vec![
            format!("arm error {arm_error:.3} rad"),
            format!("{ignored} LowCmds ignored before release"),
            format!("zero |q| ≤ {zero_error:.4} rad"),
            format!("ankle PR {:+.2}..{:+.2}, AB {:+.2}..{:+.2} rad", pr.min, pr.max, ab.min, ab.max),
            format!("{bad_machine} + {bad_disabled} counted by the robot"),
        ];
        let elapsed = started.elapsed().as_secs_f64();
        report.rates_hz = vec![
            ("LowCmd", low.commands_sent as f64 / streaming.elapsed().as_secs_f64()),
            ("LowState", low.lowstate.samples as f64 / elapsed),
        ];
        report.timings = vec![
            ("send lateness", low.send_lateness),
            ("arm_sdk lateness", stats.arm_sdk_send_lateness),
            ("sim send lateness", snapshot.stream.state_lateness),
            ("state gap", low.state_gap),
        ];
        report.counters = vec![
            ("LowCmd sent", low.commands_sent),
            ("LowCmd accepted", snapshot.lowcmd.accepted),
            ("LowCmd ignored", snapshot.lowcmd.ignored_mode),
            ("bad mode_machine", snapshot.lowcmd.bad_mode_machine),
            ("disabled motors", snapshot.lowcmd.disabled_motors),
            ("arm_sdk frames", snapshot.arm_sdk.accepted),
            ("LowState in", low.lowstate.samples),
            ("CRC errors", low.lowstate.checksum_errors),
        ];
        let in_swing = |s: &Swing| s.max > 0.8 * SWING_PITCH_RAD && s.min < -0.8 * SWING_PITCH_RAD;
        report.checks = vec![
            Check::new(
                "g1: an arm lifted through rt/arm_sdk, weight ramped in and out",
                weight_in && weight_out && arm_error < 0.05,
                format!("weight in {weight_in}, out {weight_out}, largest arm error {arm_error:.3} rad"),
            ),
            Check::new(
                "g1: LowCmds ignored until ReleaseMode; loco refuses after",
                ignored > 0 && released >= 1 && mode_after.is_empty() && loco_refused,
                format!("{ignored} ignored, {released} ReleaseMode, mode now {mode_after:?}, loco refused {loco_refused}"),
            ),
            Check::new("g1: every joint reaches zero", zero_error < 0.05, format!("largest |q| {zero_error:.4} rad")),
            Check::new(
                "g1: the ankles swing in PR and in AB mode",
                in_swing(&pr) && in_swing(&ab),
                format!("PR {:+.3}..{:+.3}, AB {:+.3}..{:+.3} rad", pr.min, pr.max, ab.min, ab.max),
            ),
            Check::new(
                "g1: wrong mode_machine and mode 0 refused before sending",
                refused_machine && refused_disabled,
                format!("ModeMachine {refused_machine}, DisabledMotor {refused_disabled}"),
            ),
            Check::new(
                "g1: the same frames sent raw are counted, not applied",
                bad_machine >= 1 && bad_disabled >= 1 && bad_machine <= RAW_FRAMES && bad_disabled <= RAW_FRAMES,
                if counted {
                    format!("all {RAW_FRAMES} of each counted")
                } else {
                    format!(
                        "{bad_machine} wrong mode_machine, {bad_disabled} disabled motor of {RAW_FRAMES} each (the rest \
                         overwritten in the robot's 1-deep reader history by the 500 Hz stream)"
                    )
                },
            ),
            Check::new(
                "g1: every LowState with a good CRC",
                low.lowstate.samples > 0 && low.lowstate.checksum_errors == 0 && snapshot.lowcmd.bad_crc == 0,
                format!("{} LowStates, {} CRC errors", low.lowstate.samples, low.lowstate.checksum_errors),
            ),
            Check::on_time("g1: client LowCmd stream", &low.send_lateness),
            Check::on_time("g1: client arm_sdk stream", &stats.arm_sdk_send_lateness),
            Check::on_time("g1: simulator LowState stream", &snapshot.stream.state_lateness),
        ];
        Ok(report)
    })
}
