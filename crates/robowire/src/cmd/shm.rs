//! `robowire shm status|watch`: look at a spline daemon's shared memory without disturbing it.
//!
//! Reads state through `consumer_flags[OTHER]`, so the motion controller's fresh-state flag is
//! never consumed; opens objects only if they exist, never creates or resizes them.

use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Subcommand};
use robowire_rt::monotonic_ns;
use zsl::{ConsumerIndex, ImuReader, JointFlags, JointIndex, Leg, SplineClient};
use zsl_proto::shm::{IMU_SHM_NAME, SPLINE_SHM_NAME, SplineStateBlock};

#[derive(Debug, Subcommand)]
pub(crate) enum ShmCommand {
    /// One snapshot: consumer flags, every joint's state and faults, the IMU sample and its age.
    Status(ShmArgs),
    /// Live: one line per interval with flags, joint positions and IMU age, until Ctrl-C.
    Watch(WatchArgs),
}

#[derive(Debug, Args)]
pub(crate) struct ShmArgs {
    /// Spline object name.
    #[arg(long, default_value = SPLINE_SHM_NAME)]
    name: String,
    /// IMU object name.
    #[arg(long, default_value = IMU_SHM_NAME)]
    imu_name: String,
}

#[derive(Debug, Args)]
pub(crate) struct WatchArgs {
    #[command(flatten)]
    shm: ShmArgs,
    /// Milliseconds between lines.
    #[arg(long, default_value_t = 200)]
    interval_ms: u64,
    /// Stop after this many lines (default: until Ctrl-C).
    #[arg(long)]
    count: Option<u64>,
}

pub(crate) fn run(command: &ShmCommand) -> anyhow::Result<ExitCode> {
    match command {
        ShmCommand::Status(args) => status(args),
        ShmCommand::Watch(args) => watch(args),
    }
}

fn open(args: &ShmArgs) -> anyhow::Result<SplineClient> {
    Ok(SplineClient::open(&args.name)?.with_consumer(ConsumerIndex::Other))
}

fn status(args: &ShmArgs) -> anyhow::Result<ExitCode> {
    let mut client = open(args)?;
    let flags = client.flags()?;
    println!("{} ({} bytes mapped)", args.name, client.mapped_len());
    println!("  cmd.consumer_flags   control {}  other {}", flags.command_control, flags.command_other);
    println!("  state.consumer_flags control {}  other {}", flags.state_control, flags.state_other);
    let state = client.wait_state(Duration::from_millis(100)).context("reading the state block")?;
    print_state(&state);
    match ImuReader::open(&args.imu_name) {
        Ok(mut imu) => match imu.read() {
            Ok(s) => println!(
                "{}: age {:.3} ms  acc [{:.3}, {:.3}, {:.3}] m/s²  gyro [{:.3}, {:.3}, {:.3}] rad/s  q(wxyz) [{:.4}, {:.4}, {:.4}, {:.4}]",
                args.imu_name,
                s.age_at(monotonic_ns()).as_secs_f64() * 1e3,
                s.acc_mps2[0],
                s.acc_mps2[1],
                s.acc_mps2[2],
                s.gyro_radps[0],
                s.gyro_radps[1],
                s.gyro_radps[2],
                s.quaternion_wxyz[0],
                s.quaternion_wxyz[1],
                s.quaternion_wxyz[2],
                s.quaternion_wxyz[3]
            ),
            Err(e) => println!("{}: {e}", args.imu_name),
        },
        Err(e) => println!("{}: {e}", args.imu_name),
    }
    Ok(ExitCode::SUCCESS)
}

fn print_state(state: &SplineStateBlock) {
    println!("  leg joint      p (rad)    v (rad/s)  t (N·m)   V    °C  enabled  faults");
    for leg in Leg::ALL {
        for joint in JointIndex::ALL {
            let s = state.joint(leg, joint);
            let f = JointFlags(s.flags.get());
            let faults = f.faults();
            let names: Vec<&str> = [
                (faults.overvoltage, "overvoltage"),
                (faults.overcurrent, "overcurrent"),
                (faults.over_temperature, "over-temperature"),
                (faults.overspeed, "overspeed"),
                (faults.dual_encoder, "dual-encoder"),
            ]
            .into_iter()
            .filter_map(|(set, name)| set.then_some(name))
            .collect();
            println!(
                "  {:<3} {:<6} {:>10.4} {:>10.4} {:>8.3} {:>4} {:>5}  {:<7}  {}",
                leg.abbreviation(),
                format!("{joint:?}").to_lowercase(),
                s.p.get(),
                s.v.get(),
                s.t.get(),
                f.voltage_v(),
                f.temperature_c(),
                if f.enabled() { "yes" } else { "no" },
                if names.is_empty() { "-".to_string() } else { names.join(",") }
            );
        }
    }
}

fn watch(args: &WatchArgs) -> anyhow::Result<ExitCode> {
    let mut client = open(&args.shm)?;
    let mut imu = ImuReader::open(&args.shm.imu_name).ok();
    let mut lines = 0u64;
    while args.count.is_none_or(|n| lines < n) {
        let flags = client.flags()?;
        let positions = match client.wait_state(Duration::from_millis(100)) {
            Ok(state) => Leg::ALL
                .iter()
                .map(|&leg| {
                    let p = |j| state.joint(leg, j).p.get();
                    format!(
                        "{} {:+.2} {:+.2} {:+.2}",
                        leg.abbreviation(),
                        p(JointIndex::Abad),
                        p(JointIndex::Hip),
                        p(JointIndex::Knee)
                    )
                })
                .collect::<Vec<_>>()
                .join(" | "),
            Err(e) => format!("no fresh state: {e}"),
        };
        let imu_age = imu
            .as_mut()
            .and_then(|r| r.latest_age().ok())
            .map_or("-".to_string(), |age| format!("{:.2} ms", age.as_secs_f64() * 1e3));
        println!("flags cmd {} state {} | {positions} | imu age {imu_age}", flags.command_control, flags.state_control);
        lines += 1;
        std::thread::sleep(Duration::from_millis(args.interval_ms));
    }
    Ok(ExitCode::SUCCESS)
}
