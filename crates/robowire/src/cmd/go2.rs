//! `robowire go2 …`: a Unitree Go2's low-level interface over DDS through the `go2` facade.

use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::{Args, Subcommand};
use go2::{Connection, Go2, JointCommand, LowLevel, LowLevelOptions, LowState, STAND_POSE_RAD};

/// Where the robot is on DDS, shared by `go2`, `dds` and `sim go2`.
#[derive(Debug, Clone, Args)]
pub(crate) struct DdsArgs {
    /// The network interface by name (the Go2's network is 192.168.123.x: e.g. eth0, enp3s0).
    #[arg(long)]
    pub(crate) interface: Option<String>,
    /// DDS domain.
    #[arg(long, default_value_t = 0)]
    pub(crate) domain: u16,
}

impl DdsArgs {
    pub(crate) fn participant(&self) -> go2::ParticipantOptions {
        go2::ParticipantOptions::new(self.domain, self.interface.as_deref())
    }
}

#[derive(Debug, Args)]
pub(crate) struct Go2Args {
    #[command(flatten)]
    dds: DdsArgs,
    /// Seconds to wait for the robot's first LowState.
    #[arg(long, default_value_t = 5.0)]
    connect_timeout_s: f64,
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

/// Damping sent before exiting, after `stand` and by `damp`.
const DAMP_FOR: Duration = Duration::from_millis(500);
/// Stand gains of Unitree's example.
const STAND_KP: f32 = 60.0;
const STAND_KD: f32 = 5.0;

fn seconds(name: &str, value: f64) -> anyhow::Result<Duration> {
    anyhow::ensure!(value.is_finite() && (0.0..=3600.0).contains(&value), "{name} must be 0–3600 s, got {value}");
    Ok(Duration::from_secs_f64(value))
}

pub(crate) fn run(args: Go2Args) -> anyhow::Result<ExitCode> {
    let connect = seconds("--connect-timeout-s", args.connect_timeout_s)?;
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        let options = LowLevelOptions { participant: args.dds.participant(), ..LowLevelOptions::default() };
        let robot = LowLevel::<Go2>::connect(options).await.context("joining DDS")?;
        let state = robot.wait_state(connect, |_| true).await.with_context(|| {
            format!(
                "no rt/lowstate within {:.1} s on domain {} ({}): is the robot on, and is this the interface \
                 of its network (192.168.123.x)?",
                connect.as_secs_f64(),
                args.dds.domain,
                args.dds.interface.as_deref().map_or("the default interface".into(), |i| format!("interface {i}"))
            )
        })?;
        let code = match args.command {
            Go2Command::Status { json } => {
                if json {
                    println!("{}", serde_json::to_string(&crate::cmd::decode::json_value(&state)?)?);
                } else {
                    print_status(&state);
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
                    eprintln!("warning: sport mode {mode:?} owns the motors; the robot ignores LowCmds until `release`");
                }
                robot.damp();
                tokio::time::sleep(DAMP_FOR).await;
                println!("damped for {:.1} s", DAMP_FOR.as_secs_f64());
                ExitCode::SUCCESS
            }
        };
        let s = robot.stats();
        eprintln!(
            "lowcmd sent {} (damping {}) | lowstate received {} decode errors {} CRC errors {} lost by tick {} | send lateness p50 {} µs p99 {} µs",
            s.commands_sent,
            s.damping_sent,
            s.lowstate.samples,
            s.lowstate.decode_errors,
            s.lowstate.checksum_errors,
            s.lost_by_tick,
            s.send_lateness.p50_us,
            s.send_lateness.p99_us
        );
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

/// Moves from the current pose to the stand pose over `duration`, holds for `hold`, damps.
async fn stand(robot: &LowLevel<Go2>, duration: Duration, hold: Duration) -> anyhow::Result<ExitCode> {
    release(robot).await?;
    let start = robot.joint_positions().context("no state")?;
    let target: [f32; 12] = std::array::from_fn(|i| STAND_POSE_RAD[i % 3]);
    println!("moving from {} to the stand pose over {:.1} s", pose(&start), duration.as_secs_f64());
    let began = Instant::now();
    let mut ticker = tokio::time::interval(Duration::from_millis(2));
    loop {
        ticker.tick().await;
        let elapsed = began.elapsed();
        let fraction = if duration.is_zero() { 1.0 } else { (elapsed.as_secs_f32() / duration.as_secs_f32()).min(1.0) };
        let joints: [JointCommand; 12] = std::array::from_fn(|i| {
            JointCommand::hold(start[i] + (target[i] - start[i]) * fraction, STAND_KP, STAND_KD)
        });
        robot.set_joints(&joints).context("the stand command")?;
        if elapsed >= duration + hold {
            break;
        }
        if robot.connection() == Connection::Disconnected {
            robot.damp();
            anyhow::bail!("rt/lowstate stopped while standing up; damping");
        }
    }
    let reached = robot.joint_positions().context("no state")?;
    let worst = reached.iter().zip(target).map(|(q, t)| (q - t).abs()).fold(0.0f32, f32::max);
    println!("held the stand pose {:.1} s: {} (largest error {worst:.3} rad)", hold.as_secs_f64(), pose(&reached));
    robot.damp();
    tokio::time::sleep(DAMP_FOR).await;
    println!("damped; done");
    Ok(ExitCode::SUCCESS)
}

fn pose(q: &[f32; 12]) -> String {
    q.chunks(3).map(|leg| format!("[{:+.2} {:+.2} {:+.2}]", leg[0], leg[1], leg[2])).collect::<Vec<_>>().join(" ")
}

fn line(state: &LowState) -> String {
    let q: [f32; 12] = std::array::from_fn(|i| state.motor_state[i].q.get());
    let rpy = state.imu_state.rpy.map(|v| v.get());
    format!(
        "tick {:>8} | q {} | rpy {:+.2} {:+.2} {:+.2} | {:.1} V {:.1} A soc {} %",
        state.tick.get(),
        pose(&q),
        rpy[0],
        rpy[1],
        rpy[2],
        state.power_v.get(),
        state.power_a.get(),
        state.bms_state.soc
    )
}

fn print_status(state: &LowState) {
    println!("{}", line(state));
    for (i, name) in go2::GO2_JOINT_NAMES.iter().enumerate() {
        let m = &state.motor_state[i];
        println!(
            "  {name:<9} q {:+.3} rad  dq {:+.3} rad/s  tau {:+.2} N·m  mode {}  {} °C",
            m.q.get(),
            m.dq.get(),
            m.tau_est.get(),
            m.mode,
            m.temperature
        );
    }
    let ff = state.foot_force.map(|f| f.get());
    println!("  foot force FR FL RR RL: {ff:?}");
}

async fn watch(robot: &LowLevel<Go2>) -> anyhow::Result<()> {
    crate::cmd::live::watch_until_ctrl_c(robot.connection_events(), || {
        robot.state().map(|s| format!("{} | age {} ms", line(&s.state), s.age.as_millis()))
    })
    .await
}
