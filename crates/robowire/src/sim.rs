//! `robowire sim …`: a simulator alone, until Ctrl-C.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::{Args, Subcommand};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};

#[derive(Debug, Subcommand)]
pub(crate) enum SimCommand {
    /// A KMC chassis on a pseudo-terminal; prints the device path to open.
    Kmc(KmcSimArgs),
    /// The ZSL-1 spline daemon: a 1 kHz loop on /spline_shm and /imu_shm with a PD joint model.
    Spline(SplineSimArgs),
}

#[derive(Debug, Args)]
pub(crate) struct SplineSimArgs {
    /// Spline object name.
    #[arg(long, default_value = zsl_proto::shm::SPLINE_SHM_NAME)]
    name: String,
    /// IMU object name.
    #[arg(long, default_value = zsl_proto::shm::IMU_SHM_NAME)]
    imu_name: String,
    /// Permission bits of the objects (octal), applied after creation regardless of the umask.
    #[arg(long, default_value = "660", value_parser = parse_octal)]
    mode: u32,
    /// Print the simulator's counters every this many seconds (0: never).
    #[arg(long, default_value_t = 1.0)]
    report_every_s: f64,
}

fn parse_octal(text: &str) -> Result<u32, String> {
    u32::from_str_radix(text, 8).ok().filter(|m| *m <= 0o777).ok_or_else(|| format!("{text:?} is no octal mode"))
}

#[derive(Debug, Args)]
pub(crate) struct KmcSimArgs {
    /// Also make a symlink here to the pty (a stable path, e.g. /tmp/kmc0).
    #[arg(long)]
    link: Option<PathBuf>,
    /// Stop the wheels when no 0xA5 arrived for this long, ms (0 disables).
    #[arg(long, default_value_t = 1000)]
    watchdog_ms: u64,
    /// Print the simulator's counters every this many seconds (0: never).
    #[arg(long, default_value_t = 1.0)]
    report_every_s: f64,
}

pub(crate) fn run(command: SimCommand) -> anyhow::Result<ExitCode> {
    match command {
        SimCommand::Kmc(args) => run_kmc(&args),
        SimCommand::Spline(args) => run_spline(&args),
    }
}

/// Runs until Ctrl-C, reporting every `every_s` seconds (0: never).
fn until_ctrl_c(every_s: f64, mut report: impl FnMut()) -> anyhow::Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    runtime.block_on(async {
        let enabled = every_s.is_finite() && every_s > 0.0;
        let mut ticker = tokio::time::interval(Duration::from_secs_f64(if enabled { every_s } else { 3600.0 }));
        ticker.tick().await;
        loop {
            tokio::select! {
                signal = tokio::signal::ctrl_c() => {
                    signal.context("waiting for Ctrl-C")?;
                    return Ok(());
                }
                _ = ticker.tick(), if enabled => report(),
            }
        }
    })
}

fn run_spline(args: &SplineSimArgs) -> anyhow::Result<ExitCode> {
    let config = robowire_sim::spline::SplineSimConfig {
        spline_name: args.name.clone(),
        imu_name: args.imu_name.clone(),
        create: robowire_shm::CreateOptions { mode: args.mode, unlink_on_drop: true },
        ..Default::default()
    };
    let sim = robowire_sim::spline::SplineSim::spawn(config).context("starting the spline daemon simulator")?;
    println!("{} {}", args.name, args.imu_name);
    eprintln!(
        "spline daemon simulator on {} and {} (mode {:o}), 1 kHz. Try: robowire shm status --name {} --imu-name {}. Ctrl-C stops and removes the objects.",
        args.name, args.imu_name, args.mode, args.name, args.imu_name
    );
    until_ctrl_c(args.report_every_s, || {
        let s = sim.stats();
        eprintln!(
            "cycles {} missed {} | lateness p50 {} µs p99 {} µs max {} µs | commands fresh {} repeated {} cleared {} rejected {}",
            s.cycles,
            s.missed_cycles,
            s.lateness.p50_us,
            s.lateness.p99_us,
            s.lateness.max_us,
            s.daemon.fresh,
            s.daemon.repeated,
            s.daemon.cleared,
            s.daemon.rejected
        );
    })?;
    Ok(ExitCode::SUCCESS)
}

fn run_kmc(args: &KmcSimArgs) -> anyhow::Result<ExitCode> {
    let config = ChassisSimConfig {
        link: args.link.clone(),
        command_watchdog: (args.watchdog_ms > 0).then(|| Duration::from_millis(args.watchdog_ms)),
        ..ChassisSimConfig::default()
    };
    let sim = ChassisSim::spawn(config).context("starting the chassis simulator")?;
    // The first line is the path, alone, for scripts: `port=$(robowire sim kmc | head -1)`.
    println!("{}", sim.path().display());
    eprintln!(
        "KMC chassis simulator on {} (pty {}). Try: robowire kmc --port {} drive --velocity 0.5 --yaw-rate 0.2. Ctrl-C stops.",
        sim.path().display(),
        sim.pty_path().display(),
        sim.path().display()
    );
    until_ctrl_c(args.report_every_s, || {
        let (s, st) = (sim.stats(), sim.state());
        eprintln!(
            "cmd {:+.2} m/s {:+.2} 1/m | speed {:+.3} m/s | battery {:.2} V | rx: control {} speed-req {} af-read {} af-write {} | sent {} | skipped {} rejected {}",
            st.commanded_velocity_mps,
            st.commanded_curvature_per_m,
            st.speed_mps,
            st.battery_volts,
            s.control_frames,
            s.speed_requests,
            s.af_reads,
            s.af_writes,
            s.responses_sent,
            s.decoder.skipped_bytes,
            s.decoder.rejected_candidates
        );
    })?;
    Ok(ExitCode::SUCCESS)
}
