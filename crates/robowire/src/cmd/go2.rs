//! `robowire go2 …`: a Unitree Go2's low-level interface over DDS through the `unitree` facade.

use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Subcommand};
use robowire_devices::Describe;
use unitree::trajectory::JointTrajectory;
use unitree::{Device, Go2, LowLevel};

use crate::cmd::seconds;
use crate::cmd::unitree::{DAMP_FOR, RobotArgs, follow_then_hold};

#[derive(Debug, Args)]
pub(crate) struct Go2Args {
    #[command(flatten)]
    robot: RobotArgs,
    #[command(subcommand)]
    command: Go2Command,
}

#[derive(Debug, Subcommand)]
enum Go2Command {
    /// Print one LowState.
    Status {
        /// As one JSON object with the IDL field names (as `robowire decode lowstate --json`).
        #[arg(long)]
        json: bool,
    },
    /// Print the state live, 10 lines a second, until Ctrl-C.
    Watch,
    /// Release the sport mode (motion_switcher), so that LowCmds drive the motors.
    Release,
    /// Release the sport mode, move the 12 leg joints from where they are to the stand pose, hold,
    /// then damp.
    Stand {
        /// Seconds to move to the stand pose.
        #[arg(long, default_value_t = 2.0)]
        duration: f64,
        /// Seconds to hold it.
        #[arg(long, default_value_t = 2.0)]
        hold: f64,
    },
    /// Damp every joint (kp 0, small kd) for a moment.
    Damp,
}

pub(crate) fn run(args: Go2Args) -> anyhow::Result<ExitCode> {
    let robot_args = &args.robot;
    robot_args.run("go2", |options, links, connect| async move {
        let options = options.recorded(links.as_ref(), "go2", &unitree_proto::description::GO2_LOW_LEVEL);
        let robot = LowLevel::<Go2>::open(options).context("joining DDS")?;
        let state = robot.wait_state(connect, |_| true).await.with_context(|| robot_args.silent(connect))?;
        let code = match args.command {
            Go2Command::Status { json } => {
                if json {
                    println!("{}", serde_json::to_string(&crate::cmd::decode::json_value(&state)?)?);
                } else {
                    println!("{}", robot.status_text().context("no state")?);
                }
                ExitCode::SUCCESS
            }
            Go2Command::Watch => {
                watch(&robot).await?;
                ExitCode::SUCCESS
            }
            Go2Command::Release => {
                release(&robot).await?;
                ExitCode::SUCCESS
            }
            Go2Command::Stand { duration, hold } => {
                stand(&robot, seconds("--duration", duration)?, seconds("--hold", hold)?).await?
            }
            Go2Command::Damp => {
                if let Ok(mode) = robot.sport_mode().await
                    && !mode.is_empty()
                {
                    eprintln!(
                        "warning: sport mode {mode:?} owns the motors; the robot ignores LowCmds until `release`"
                    );
                }
                robot.damp();
                tokio::time::sleep(DAMP_FOR).await;
                println!("damped for {:.1} s", DAMP_FOR.as_secs_f64());
                ExitCode::SUCCESS
            }
        };
        eprintln!("{}", robot.stats_line());
        robot.close();
        Ok(code)
    })
}

async fn release(robot: &LowLevel<Go2>) -> anyhow::Result<()> {
    match robot.release_sport_mode().await.context("releasing the sport mode")? {
        0 => println!("no sport mode owns the motors"),
        n => println!("sport mode released ({n} ReleaseMode call{})", if n == 1 { "" } else { "s" }),
    }
    Ok(())
}

/// Moves from the current pose to the stand pose over `duration` (Unitree's stand trajectory,
/// followed by the LowCmd stream), holds for `hold`, damps.
async fn stand(robot: &LowLevel<Go2>, duration: Duration, hold: Duration) -> anyhow::Result<ExitCode> {
    release(robot).await?;
    let start = robot.joint_positions().context("no state")?;
    let stand = JointTrajectory::stand_up(start, duration);
    println!("moving from {} to the stand pose over {:.1} s", pose(&start), duration.as_secs_f64());
    // The LowCmd stream steps the move on its own deadlines, then holds the stand pose.
    let following = robot.follow(stand).context("the stand command")?;
    follow_then_hold(robot, following, hold, "standing up").await.inspect_err(|_| robot.damp())?;
    let reached = robot.joint_positions().context("no state")?;
    let worst = stand.largest_error_rad(&reached);
    println!("held the stand pose {:.1} s: {} (largest error {worst:.3} rad)", hold.as_secs_f64(), pose(&reached));
    robot.damp();
    tokio::time::sleep(DAMP_FOR).await;
    println!("damped; done");
    Ok(ExitCode::SUCCESS)
}

fn pose(q: &[f32; 12]) -> String {
    q.chunks(3).map(|leg| format!("[{:+.2} {:+.2} {:+.2}]", leg[0], leg[1], leg[2])).collect::<Vec<_>>().join(" ")
}

async fn watch(robot: &LowLevel<Go2>) -> anyhow::Result<()> {
    crate::cmd::watch_loop::watch_until_ctrl_c(robot.connection_events(), || robot.status_line()).await
}
