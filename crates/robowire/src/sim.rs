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
    }
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
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    runtime.block_on(async {
        let report = args.report_every_s.is_finite() && args.report_every_s > 0.0;
        let period = Duration::from_secs_f64(if report { args.report_every_s } else { 3600.0 });
        let mut ticker = tokio::time::interval(period);
        ticker.tick().await;
        loop {
            tokio::select! {
                signal = tokio::signal::ctrl_c() => {
                    signal.context("waiting for Ctrl-C")?;
                    break;
                }
                _ = ticker.tick(), if report => {
                    let (s, st) = (sim.stats(), sim.state());
                    eprintln!(
                        "cmd {:+.2} m/s {:+.2} 1/m | speed {:+.3} m/s | battery {:.2} V | rx: control {} speed-req {} af-read {} af-write {} | sent {} | skipped {} rejected {}",
                        st.commanded_velocity_mps, st.commanded_curvature_per_m, st.speed_mps, st.battery_volts,
                        s.control_frames, s.speed_requests, s.af_reads, s.af_writes, s.responses_sent,
                        s.decoder.skipped_bytes, s.decoder.rejected_candidates
                    );
                }
            }
        }
        anyhow::Ok(())
    })?;
    Ok(ExitCode::SUCCESS)
}
