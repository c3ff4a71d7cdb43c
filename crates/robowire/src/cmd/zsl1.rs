//! `robowire zsl1 …` (alias `robowire dog`, its old name, kept one release): drive a ZSL-1 /
//! ZSL-1W over UDP through the HighLevel client.

use std::net::{IpAddr, SocketAddr};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::{Args, Subcommand, ValueEnum};
use robowire_devices::{Describe, zsl_state_line};
use zsl::udp::{CallError, ClientOptions, ControlMode, Device, HighLevel, Latched, Model, StateDecoding};
use zsl_proto::udp::{DEFAULT_LOCAL_PORT, HIGH_LEVEL_PORT};

/// The robot model, as the command line spells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ModelArg {
    /// ZSL-1 (magic 0x5AA5).
    #[value(name = "zsl-1")]
    Zsl1,
    /// ZSL-1W wheel-legged (magic 0x5AA6).
    #[value(name = "zsl-1w")]
    Zsl1W,
}

impl From<ModelArg> for Model {
    fn from(m: ModelArg) -> Self {
        match m {
            ModelArg::Zsl1 => Model::Zsl1,
            ModelArg::Zsl1W => Model::Zsl1W,
        }
    }
}

#[derive(Debug, Args)]
pub(crate) struct Zsl1Args {
    /// The robot's IP address.
    #[arg(long, default_value = "192.168.234.1")]
    dog_ip: IpAddr,
    /// The robot's HighLevel port.
    #[arg(long, default_value_t = HIGH_LEVEL_PORT)]
    dog_port: u16,
    /// Local address to bind; the robot sends state to its configured target (default port 43988).
    #[arg(long, default_value = "0.0.0.0")]
    local_ip: IpAddr,
    /// Local port (the robot's `target_port`).
    #[arg(long, default_value_t = DEFAULT_LOCAL_PORT)]
    local_port: u16,
    /// Robot model.
    #[arg(long, value_enum, default_value = "zsl-1")]
    model: ModelArg,
    /// Decode state strictly (exact length and header) instead of like the vendor.
    #[arg(long)]
    strict: bool,
    /// Seconds to wait for the robot's first state.
    #[arg(long, default_value_t = 3.0)]
    connect_timeout_s: f64,
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
    #[command(subcommand)]
    command: Zsl1Command,
}

#[derive(Debug, Subcommand)]
enum Zsl1Command {
    /// Stand up (mode 1).
    Stand,
    /// Lie down, joints locked (mode 51).
    Lie,
    /// Motors damped (mode 0).
    Passive,
    /// Walk: forward m/s, left m/s, yaw rate rad/s; stops after --duration.
    #[command(allow_negative_numbers = true)]
    Move {
        /// Forward velocity, m/s: 0 or 0.05–3.0 in magnitude.
        vx_mps: f32,
        /// Lateral velocity, m/s: 0 or 0.1–1.0 in magnitude.
        vy_mps: f32,
        /// Yaw rate, rad/s: 0 or 0.02–3.0 in magnitude.
        yaw_rate_radps: f32,
        /// Seconds to walk before stopping.
        #[arg(long, default_value_t = 2.0)]
        duration: f64,
    },
    /// Jump in place.
    Jump,
    /// Jump forward.
    FrontJump,
    /// Backflip.
    Backflip,
    /// Shake hands.
    ShakeHand,
    /// Stand on the hind legs and move: forward m/s (0 or 0.2–0.5), yaw rate rad/s (0 or 0.2–1.0).
    #[command(allow_negative_numbers = true)]
    TwoLegStand {
        /// Forward velocity, m/s.
        vx_mps: f32,
        /// Yaw rate, rad/s.
        yaw_rate_radps: f32,
    },
    /// Leave the two-leg stand.
    CancelTwoLegStand,
    /// Body attitude rates: roll, pitch, yaw (rad/s) and height (m/s), each |v| ≤ 0.6.
    #[command(allow_negative_numbers = true)]
    Attitude {
        /// Roll rate, rad/s.
        roll_radps: f32,
        /// Pitch rate, rad/s.
        pitch_radps: f32,
        /// Yaw rate, rad/s.
        yaw_radps: f32,
        /// Height rate, m/s.
        height_mps: f32,
        /// Seconds to apply the rates before zeroing them.
        #[arg(long, default_value_t = 1.0)]
        duration: f64,
    },
    /// Print one state snapshot.
    Status {
        /// As JSON.
        #[arg(long)]
        json: bool,
    },
    /// Print the state live, 10 lines a second, until Ctrl-C.
    Watch,
}

pub(crate) fn run(args: Zsl1Args) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.connect_timeout_s.is_finite() && args.connect_timeout_s > 0.0,
        "--connect-timeout-s must be positive"
    );
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(run_async(args))
}

fn options(args: &Zsl1Args) -> ClientOptions {
    let options = ClientOptions::high_level(args.local_ip, args.local_port, args.dog_ip).with_model(args.model.into());
    let options = if args.strict { options.with_state_decoding(StateDecoding::Strict) } else { options };
    ClientOptions { dog: SocketAddr::new(args.dog_ip, args.dog_port), ..options }
}

use crate::cmd::seconds as duration;

async fn run_async(args: Zsl1Args) -> anyhow::Result<ExitCode> {
    let taps = args.record.start("robowire zsl1")?;
    let mut options = options(&args);
    if let Some(tap) = taps.link("zsl1/high_level", &zsl_proto::description::HIGH_LEVEL) {
        options = options.with_tap(tap);
    }
    let dog = HighLevel::open(options).context("starting the HighLevel client")?;
    let timeout = Duration::from_secs_f64(args.connect_timeout_s);
    if !dog.wait_connected(timeout).await {
        anyhow::bail!(
            "no state from {} within {:.1} s on {}: is the robot on, and is its target_ip/target_port this \
             address? (try --local-ip with one of this host's addresses)",
            args.dog_ip,
            args.connect_timeout_s,
            dog.local_addr()
        );
    }
    let outcome = match args.command {
        Zsl1Command::Stand => call(&dog, "stand_up", dog.stand_up(), Some(ControlMode::Stand)).await,
        Zsl1Command::Lie => call(&dog, "lie_down", dog.lie_down(), Some(ControlMode::LieDown)).await,
        Zsl1Command::Passive => call(&dog, "passive", dog.passive(), Some(ControlMode::Passive)).await,
        Zsl1Command::Move { vx_mps, vy_mps, yaw_rate_radps, duration: seconds } => {
            let walk = duration("--duration", seconds)?;
            let start = dog.position();
            let result = dog.move_velocity(vx_mps, vy_mps, yaw_rate_radps);
            let ok = call(&dog, "move", result, Some(ControlMode::Move)).await;
            if ok {
                watch_for(&dog, walk).await;
                let stopped = dog.move_velocity(0.0, 0.0, 0.0);
                call(&dog, "move(0, 0, 0)", stopped, None).await;
                dog.wait_for_state(Duration::from_secs(2), move |s| {
                    s.body.body_velocity_mps[0].abs() < 0.05 && s.body.body_velocity_mps[1].abs() < 0.05
                })
                .await;
                if let (Some(a), Some(b)) = (start, dog.position()) {
                    println!("moved {:+.2} m, {:+.2} m", b[0] - a[0], b[1] - a[1]);
                }
            }
            ok
        }
        Zsl1Command::Jump => trick(&dog, "jump", dog.jump()).await,
        Zsl1Command::FrontJump => trick(&dog, "front_jump", dog.front_jump()).await,
        Zsl1Command::Backflip => trick(&dog, "backflip", dog.backflip()).await,
        Zsl1Command::ShakeHand => trick(&dog, "shake_hand", dog.shake_hand()).await,
        Zsl1Command::TwoLegStand { vx_mps, yaw_rate_radps } => {
            let result = dog.two_leg_stand(vx_mps, yaw_rate_radps);
            call(&dog, "two_leg_stand", result, Some(ControlMode::Action)).await
        }
        Zsl1Command::CancelTwoLegStand => call(&dog, "cancel_two_leg_stand", dog.cancel_two_leg_stand(), None).await,
        Zsl1Command::Attitude { roll_radps, pitch_radps, yaw_radps, height_mps, duration: seconds } => {
            let hold = duration("--duration", seconds)?;
            let result = dog.attitude_control(roll_radps, pitch_radps, yaw_radps, height_mps);
            let ok = call(&dog, "attitude_control", result, Some(ControlMode::Action)).await;
            if ok {
                watch_for(&dog, hold).await;
                let zero = dog.attitude_control(0.0, 0.0, 0.0, 0.0);
                call(&dog, "attitude_control(0, 0, 0, 0)", zero, None).await;
            }
            ok
        }
        Zsl1Command::Status { json } => {
            let missing = "the connection dropped before a state arrived";
            if json {
                // The datagram's JSON, as `robowire decode zsl --json` prints it.
                println!("{}", serde_json::to_string_pretty(&dog.status_json().context(missing)?)?);
            } else {
                println!("{}", dog.status_text().context(missing)?);
            }
            true
        }
        Zsl1Command::Watch => {
            crate::cmd::watch_loop::watch_until_ctrl_c(dog.connection_events(), || dog.status_line()).await?;
            true
        }
    };
    eprintln!("{}", dog.stats_line());
    dog.close();
    taps.finish()?;
    Ok(if outcome { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// Prints a call's return code; waits for `mode` when given. `true` when the call went out.
async fn call(dog: &HighLevel, name: &str, result: Result<Latched, CallError>, mode: Option<ControlMode>) -> bool {
    match result {
        Ok(latched) => {
            let code = latched.return_code;
            if code.raw() == 0 {
                println!("{name}: 0x0000 queued");
            } else {
                println!("{name}: 0x{:04x} sent, not acknowledged yet ({code:?})", code.raw());
            }
            if let Some(mode) = mode {
                match dog.wait_for_mode(mode, Duration::from_secs(2)).await {
                    Some(_) => println!("robot reports mode {} ({mode:?})", mode.raw()),
                    None => println!(
                        "robot has not reported mode {} within 2 s (reports {:?})",
                        mode.raw(),
                        dog.control_mode()
                    ),
                }
            }
            true
        }
        Err(e) => {
            println!("{name}: 0x{:04x} refused: {e}", e.return_code().raw());
            false
        }
    }
}

async fn trick(dog: &HighLevel, name: &str, result: Result<Latched, CallError>) -> bool {
    let ok = call(dog, name, result, Some(ControlMode::Action)).await;
    if ok {
        // Keep the client (and its stream) alive while the trick runs.
        watch_for(dog, Duration::from_secs(2)).await;
    }
    ok
}

async fn watch_for(dog: &HighLevel, how_long: Duration) {
    let end = Instant::now() + how_long;
    while Instant::now() < end {
        tokio::time::sleep(Duration::from_millis(250).min(end.saturating_duration_since(Instant::now()))).await;
        match dog.state() {
            Some(s) => println!("  {}", zsl_state_line(&s)),
            None => println!("  (no state: {:?})", dog.connection()),
        }
    }
}
