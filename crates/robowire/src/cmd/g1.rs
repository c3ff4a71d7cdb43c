//! `robowire g1 …`: a Unitree G1 humanoid over DDS through `unitree::g1`.

use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Subcommand};
use robowire_devices::Describe;
use unitree::g1::{Device, G1, G1Options, G1Variant, JOINT_NAMES, JOINTS, from_fn};

use crate::cmd::seconds;
use crate::cmd::unitree::{DAMP_FOR, RobotArgs, follow_then_hold};

#[derive(Debug, Args)]
pub(crate) struct G1Args {
    #[command(flatten)]
    robot: RobotArgs,
    #[command(subcommand)]
    command: G1Command,
}

#[derive(Debug, Subcommand)]
enum G1Command {
    /// Print one LowState: mode_machine and the variant it names, mode_pr, the joints by name, the
    /// IMU, the battery (rt/lf/bmsstate).
    Status {
        /// As one JSON object with the IDL field names (as `robowire decode lowstate --json`).
        #[arg(long)]
        json: bool,
    },
    /// Print the state live, 10 lines a second, until Ctrl-C.
    Watch,
    /// Release the robot's controller (motion_switcher ReleaseMode), so that LowCmds drive the
    /// motors. The robot goes limp: hang it or lay it down first.
    Release,
    /// Damp every joint the variant drives (kp 0, small kd) for a moment.
    Damp,
    /// Release the controller, move every joint the variant drives from where it is to 0 rad
    /// (Unitree's low-level example, stage 1, with its gains), hold, then damp. Hang the robot
    /// first.
    Zero {
        /// Seconds to move to 0 rad.
        #[arg(long, default_value_t = 3.0)]
        duration: f64,
        /// Seconds to hold it.
        #[arg(long, default_value_t = 2.0)]
        hold: f64,
    },
}

pub(crate) fn run(args: G1Args) -> anyhow::Result<ExitCode> {
    let robot_args = &args.robot;
    robot_args.run("g1", |low_level, links, connect| async move {
        let options = G1Options { low_level, ..G1Options::default() }.recorded(links.as_ref());
        let robot = G1::open(options).context("joining DDS")?;
        let state = robot.wait_state(connect, |_| true).await.with_context(|| robot_args.silent(connect))?;
        let code = match args.command {
            G1Command::Status { json } => {
                if json {
                    println!("{}", serde_json::to_string(&crate::cmd::decode::json_value(&state)?)?);
                } else {
                    wait_battery(&robot).await;
                    println!("{}", robot.status_text().context("no state")?);
                }
                ExitCode::SUCCESS
            }
            G1Command::Watch => {
                crate::cmd::watch_loop::watch_until_ctrl_c(robot.connection_events(), || robot.status_line()).await?;
                ExitCode::SUCCESS
            }
            G1Command::Release => {
                release(&robot).await?;
                ExitCode::SUCCESS
            }
            G1Command::Damp => {
                if let Ok(mode) = robot.mode().await
                    && !mode.is_empty()
                {
                    eprintln!("warning: mode {mode:?} owns the motors; the robot ignores LowCmds until `release`");
                }
                robot.damp().context("damping was refused")?;
                tokio::time::sleep(DAMP_FOR).await;
                println!("damped for {:.1} s", DAMP_FOR.as_secs_f64());
                ExitCode::SUCCESS
            }
            G1Command::Zero { duration, hold } => {
                zero(&robot, seconds("--duration", duration)?, seconds("--hold", hold)?).await?;
                ExitCode::SUCCESS
            }
        };
        eprintln!("{}", robot.stats_line());
        robot.close();
        Ok(code)
    })
}

/// How long `status` waits for `rt/lf/bmsstate` after the first LowState (the robot sends it
/// less often).
const BATTERY_WAIT: Duration = Duration::from_millis(1500);

/// Waits up to [`BATTERY_WAIT`] for the first battery state (looking every 10 ms).
async fn wait_battery(robot: &G1) {
    let deadline = tokio::time::Instant::now() + BATTERY_WAIT;
    while robot.battery().is_none() && tokio::time::Instant::now() < deadline {
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
}

async fn release(robot: &G1) -> anyhow::Result<()> {
    let mode = robot.mode().await.context("asking motion_switcher which mode owns the motors")?;
    match robot.release().await.context("releasing the robot's controller (motion_switcher)")? {
        0 => println!("no mode owns the motors"),
        n => println!("mode {mode:?} released ({n} ReleaseMode call{})", if n == 1 { "" } else { "s" }),
    }
    Ok(())
}

/// The driven slots of `variant`.
fn driven(variant: G1Variant) -> impl Iterator<Item = usize> {
    (0..JOINTS).filter(move |&slot| variant.drives(slot))
}

/// Releases the controller, moves every driven joint linearly from where it is to 0 rad over
/// `duration` with Unitree's example gains ([`G1::hold`]), followed by the LowCmd stream, holds
/// for `hold`, damps.
async fn zero(robot: &G1, duration: Duration, hold: Duration) -> anyhow::Result<()> {
    release(robot).await?;
    let variant = robot.variant().context("no state")?;
    let mode_machine = robot.mode_machine().context("no state")?;
    let from = robot.joint_positions().context("no state")?;
    println!(
        "moving the {} joints of a {variant:?} G1 to 0 rad over {:.1} s (largest |q| {})",
        variant.joint_count(),
        duration.as_secs_f64(),
        largest(&from, variant)
    );
    let to_zero = from_fn(duration, move |elapsed| {
        let remaining =
            if duration.is_zero() { 0.0 } else { 1.0 - (elapsed.as_secs_f32() / duration.as_secs_f32()).min(1.0) };
        unitree::g1::hold(&from.map(|q| q * remaining), mode_machine, variant)
    });
    let following = robot.follow(to_zero).context("the robot refused the command to 0 rad")?;
    follow_then_hold(robot, following, hold, "moving to 0 rad").await?;
    let reached = robot.joint_positions().context("no state")?;
    println!("held 0 rad {:.1} s: largest |q| {}", hold.as_secs_f64(), largest(&reached, variant));
    robot.damp().context("damping was refused")?;
    tokio::time::sleep(DAMP_FOR).await;
    println!("damped; done");
    Ok(())
}

/// The largest |q| of the driven joints, and which: `0.123 rad (left_knee_joint)`.
fn largest(q: &[f32; JOINTS], variant: G1Variant) -> String {
    let worst = driven(variant).max_by(|&a, &b| q[a].abs().total_cmp(&q[b].abs())).unwrap_or(0);
    format!("{:.3} rad ({})", q[worst].abs(), JOINT_NAMES[worst])
}
