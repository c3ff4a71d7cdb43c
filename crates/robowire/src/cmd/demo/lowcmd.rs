//! The Unitree scenario: a Go2 on DDS. The simulated Go2 and the `go2` client in one process,
//! over real DDS participants on loopback (where it has no multicast: in the user + network
//! namespace the demo runs in, or, as root, on a thread in a network namespace of its own; see
//! `robowire_dds::netns`): release the sport mode, stand up from lying, hold, with bit flips
//! injected on `rt/lowstate` and caught by the CRC.

use robowire_record::RecordLinks;
use std::time::{Duration, Instant};

use anyhow::Context;
use robowire_core::timing::LatenessRing;
use robowire_devices::{DeviceKind, OpenOptions, Simulator};
use robowire_rt::stats::micros;
use robowire_sim::go2::Go2Fault;
use unitree::trajectory::{JointTrajectory, STAND_KD, STAND_KP, from_fn};
use unitree::{Device, LowCmd, MotorCmd};

use super::{Check, DeviceReport, InjectedFault, Progress, Status};
use crate::output::Output;

/// Every this many LowStates one goes out with a flipped bit, during the fault phase.
const FLIP_EVERY: u32 = 25;

pub(super) fn run(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    out.line(format_args!("== Unitree Go2 over DDS (rt/lowcmd, rt/lowstate, motion_switcher; simulated Go2) =="));
    super::on_dds_loopback(out, || scenario(duration_s, out, record))
}

/// A command for the 12 joints at `pose`, tagged with `tag` (the simulator echoes it).
fn command(pose: &[f32; 12], tag: u32) -> LowCmd {
    let mut cmd = LowCmd::default();
    for (m, q) in cmd.motor_cmd.iter_mut().zip(pose) {
        *m = MotorCmd::servo(*q, 0.0, STAND_KP, STAND_KD, 0.0);
    }
    cmd.reserve = tag.into();
    cmd
}

fn scenario(duration_s: f64, out: &Output, record: Option<&RecordLinks>) -> anyhow::Result<DeviceReport> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        // sim:go2: the simulator and the client on DDS domain 0, interface lo.
        let device = super::open_simulated(DeviceKind::Go2, &OpenOptions { record: record.cloned(), ..OpenOptions::default() })?;
        let (Some(Simulator::Go2(sim)), Some(robot)) = (device.simulator(), device.go2()) else {
            anyhow::bail!("sim:go2 opened something other than a simulated Go2");
        };
        let first = robot.wait_state(Duration::from_secs(10), |_| true).await.context("no rt/lowstate")?;
        out.line(format_args!("simulator and client on DDS domain 0, interface lo; LowState tick {}", first.tick.get()));

        // Before the release the robot ignores LowCmds.
        let start: [f32; 12] = std::array::from_fn(|i| first.motor_state[i].q.get());
        robot.set_command(command(&start, 0))?;
        let began = Instant::now();
        while sim.snapshot().lowcmd.ignored_sport_mode == 0 && began.elapsed() < Duration::from_secs(5) {
            tokio::time::sleep(Duration::from_millis(2)).await;
        }
        let ignored = sim.snapshot().lowcmd.ignored_sport_mode;
        let released = robot.release_sport_mode().await.context("releasing the sport mode")?;
        let mode_after = robot.sport_mode().await?;
        out.line(format_args!(
            "  release  {ignored} LowCmds ignored while sport mode \"normal\" owned the motors; ReleaseMode × {released} -> {:?}",
            mode_after
        ));

        // Stand up, then hold with bit flips on the wire for a while: one motion, stepped by the
        // LowCmd stream on its own deadlines, each step tagged with its slot (the simulator echoes
        // the tag in its LowState, which times command -> state).
        let move_time = Duration::from_secs_f64((duration_s / 2.0).max(0.5));
        let hold_time = Duration::from_secs_f64((duration_s / 2.0).max(0.5));
        let stand = JointTrajectory::stand_up(start, move_time);
        let period = robot.options().stream.period;
        let tag_of = move |elapsed: Duration| u32::try_from(elapsed.as_nanos() / period.as_nanos() + 1).unwrap_or(u32::MAX);
        let motion = from_fn(move_time + hold_time, move |elapsed| command(&stand.positions_at(elapsed), tag_of(elapsed)));
        let mut echo: LatenessRing<4096> = LatenessRing::new();
        let mut progress = Progress::new("lowcmd", out);
        let (mut echoed, mut flips_on, mut flips_off) = (0u32, false, false);
        let following = robot.follow(motion)?;
        let started = Instant::now();
        let end = following.wait();
        tokio::pin!(end);
        let mut states = robot.states();
        loop {
            tokio::select! {
                end = &mut end => {
                    end?;
                    break;
                }
                changed = states.changed() => {
                    if changed.is_err() {
                        (&mut end).await?;
                        break;
                    }
                }
            }
            // The step tagged `seen` was due at `began + (seen - 1) · period`.
            let state = *states.borrow_and_update();
            if let (Some(state), Some(began)) = (state, following.began()) {
                let seen = state.state.reserve.get();
                if seen > echoed {
                    echoed = seen;
                    let due = began + period.saturating_mul(seen - 1);
                    echo.record(micros(state.at.saturating_duration_since(due)));
                }
            }
            let elapsed = started.elapsed();
            if !flips_on && elapsed >= move_time {
                sim.inject(Go2Fault::BitFlips { every: FLIP_EVERY });
                flips_on = true;
            }
            if !flips_off && elapsed >= move_time + hold_time / 2 {
                sim.clear_faults();
                flips_off = true;
            }
            if progress.due() {
                let knee = robot.joint_positions().map_or(f32::NAN, |q| q[2]);
                let stats = robot.stats();
                progress.show(&Status {
                    mode: if elapsed < move_time { "stand-up" } else { "hold" },
                    motion: format!("FR calf {knee:+.3} rad"),
                    loop_count: stats.commands_sent,
                    lateness_us: (stats.send_lateness.p99_us, "p99"),
                });
            }
        }
        let reached = robot.joint_positions().context("no state")?;
        let worst = stand.largest_error_rad(&reached);
        robot.damp();
        tokio::time::sleep(Duration::from_millis(100)).await;
        let (stats, snapshot) = (robot.stats(), sim.snapshot());
        let elapsed = started.elapsed().as_secs_f64();
        out.line(format_args!(
            "  stand    lying -> stand pose over {:.1} s, held {:.1} s: largest joint error {worst:.4} rad",
            move_time.as_secs_f64(),
            hold_time.as_secs_f64()
        ));
        let (injected, caught) = (snapshot.corrupted_states, stats.lowstate.checksum_errors);
        out.line(format_args!(
            "  fault    {injected} LowStates with a flipped bit on the wire, {caught} caught by the CRC, {} decoded as garbage",
            stats.lowstate.decode_errors
        ));
        let echo = echo.summary();
        out.line(format_args!(
            "  loop     LowCmd sent {} ({} damping), accepted {}; LowState in {}; send lateness p50 {} µs p99 {} µs; \
             command -> state p50 {} µs p99 {} µs",
            stats.commands_sent,
            stats.damping_sent,
            snapshot.lowcmd.accepted,
            stats.lowstate.samples,
            stats.send_lateness.p50_us,
            stats.send_lateness.p99_us,
            echo.p50_us,
            echo.p99_us
        ));

        let mut report = DeviceReport::new("lowcmd");
        report.commanded = vec![
            "ReleaseMode (motion_switcher)".into(),
            format!("12 joints up, {:.1} s, kp {STAND_KP} kd {STAND_KD}", move_time.as_secs_f64()),
            format!("hold {:.1} s, then damp", hold_time.as_secs_f64()),
        ];
        report.observed = vec![
            format!("{ignored} LowCmds ignored before release"),
            format!("max error {worst:.4} rad"),
            format!("{caught} of {injected} flips caught"),
        ];
        report.rates_hz = vec![
            ("LowCmd", stats.commands_sent as f64 / elapsed),
            ("LowState", stats.lowstate.samples as f64 / elapsed),
        ];
        report.timings = vec![
            ("send lateness", stats.send_lateness),
            ("sim send lateness", snapshot.state_lateness),
            ("cmd -> state echo", echo),
            ("state gap", stats.state_gap),
        ];
        report.counters = vec![
            ("LowCmd sent", stats.commands_sent),
            ("LowCmd accepted", snapshot.lowcmd.accepted),
            ("LowCmd ignored", snapshot.lowcmd.ignored_sport_mode),
            ("LowState in", stats.lowstate.samples),
            ("CRC errors", caught),
            ("lost by tick", stats.lost_by_tick),
            ("requests", snapshot.requests),
        ];
        report.faults =
            vec![InjectedFault::new(format!("{injected} bit flips"), injected > 0 && caught > 0, format!("{caught} caught"))];
        report.checks = vec![
            Check::new(
                "go2: LowCmds ignored until the sport mode is released",
                ignored > 0 && released >= 1 && mode_after.is_empty(),
                format!("{ignored} ignored, {released} ReleaseMode, mode now {mode_after:?}"),
            ),
            Check::new("go2: legs reach the stand pose", worst < 0.02, format!("largest error {worst:.4} rad")),
            Check::new(
                "go2: every LowCmd after the release accepted",
                snapshot.lowcmd.accepted > 0 && snapshot.lowcmd.bad_crc == 0 && snapshot.lowcmd.bad_head == 0,
                format!(
                    "{} accepted, {} bad CRC, {} bad head",
                    snapshot.lowcmd.accepted, snapshot.lowcmd.bad_crc, snapshot.lowcmd.bad_head
                ),
            ),
            Check::new(
                "go2: bit flips on the wire caught by the CRC",
                caught > 0 && caught <= injected && stats.lowstate.decode_errors == 0,
                if caught == injected {
                    format!("all {injected} caught")
                } else {
                    format!("{caught} of {injected} caught (the rest overwritten in the 1-deep reader history)")
                },
            ),
            Check::on_time("go2: client LowCmd stream", &stats.send_lateness),
            Check::on_time("go2: simulator LowState stream", &snapshot.state_lateness),
        ];
        Ok(report)
    })
}
