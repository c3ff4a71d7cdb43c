//! `robowire demo`: every simulated device, driven through its client API, with checks that
//! what was commanded was observed.

mod g1;
mod kmc;
mod lowcmd;
mod progress;
mod report;
mod spline;
mod zsl1;

pub(crate) use progress::{Progress, Status};
pub(crate) use report::{Check, DeviceReport, InjectedFault};

use std::process::ExitCode;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use robowire_dds::netns::Loopback;
use robowire_record::RecordLinks;

use crate::output::Output;

/// Runs a DDS scenario where loopback carries multicast: here if it does, else (root) on a thread
/// in a private network namespace.
fn on_dds_loopback<T: Send>(out: &Output, scenario: impl FnOnce() -> anyhow::Result<T> + Send) -> anyhow::Result<T> {
    if robowire_dds::netns::loopback_has_multicast() {
        return scenario();
    }
    out.line("loopback has no multicast (DDS discovery needs it): running in a private network namespace (root)");
    robowire_dds::netns::in_loopback_namespace(scenario).context("DDS on one machine needs multicast on lo")?
}

/// The simulated device at `sim:KIND`, opened by address as any app opens a device: its client
/// and, still reachable for faults and snapshots, its simulator.
fn open_simulated(
    kind: robowire_devices::DeviceKind,
    options: &robowire_devices::OpenOptions,
) -> anyhow::Result<robowire_devices::AnyDevice> {
    let address = robowire_devices::DeviceAddress::Sim(kind);
    robowire_devices::open(&address, options).map_err(|e| anyhow::anyhow!("opening {address}: {e:#}"))
}

#[derive(Debug, Args)]
pub(crate) struct DemoArgs {
    /// Seconds of motion per device scenario, split over its phases (at least 0.8 s each, so
    /// the machine can settle).
    #[arg(long, default_value_t = 3.0)]
    duration: f64,
    /// Run one device's scenario only.
    #[arg(long, value_enum)]
    only: Option<Device>,
    /// Print the checks and every device's figures as JSON on stdout (the report goes to
    /// stderr).
    #[arg(long)]
    json: bool,
    /// Record every device's links, both ways, into this one MCAP file.
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
    /// Draw the run: one PNG per device (DIR/kmc.png, DIR/zsl1.png, …), from its capture (the
    /// --record file, else DIR/demo.mcap).
    #[arg(long, value_name = "DIR")]
    plot: Option<std::path::PathBuf>,
}

/// One PNG per device of the run's capture into `dir`.
fn draw(dir: &std::path::Path, capture: &std::path::Path, out: &Output) -> anyhow::Result<()> {
    for device in ["kmc", "zsl1", "spline", "go2", "g1"] {
        let image = dir.join(format!("{device}.png"));
        let selection = crate::cmd::plot::Selection { device: Some(device.into()), ..Default::default() };
        // A device whose scenario did not run (--only) has nothing to draw.
        if !crate::cmd::plot::plot_capture(capture, &image, &selection)?.is_empty() {
            out.line(format_args!("plot: {}", image.display()));
        }
    }
    Ok(())
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Device {
    /// KMC wheeled chassis on a pseudo-terminal.
    Kmc,
    /// ZSL-1 on loopback UDP (the HighLevel client).
    // `dog`: its old name, kept for one release.
    #[value(alias = "dog")]
    Zsl1,
    /// ZSL-1 spline daemon on shared memory (the 1 kHz low-level loop).
    Spline,
    /// A Unitree Go2 on DDS (simulated): sport mode release, stand-up, CRC faults on the wire.
    // `lowcmd`: its old name, kept for one release.
    #[value(alias = "lowcmd")]
    Go2,
    /// A Unitree G1 humanoid on DDS (simulated): rt/arm_sdk, release, zero posture, ankle swing
    /// in PR and AB mode, frames the robot ignores refused and counted.
    G1,
}

impl DemoArgs {
    /// Whether a DDS scenario (Go2, G1) is among those to run (they need multicast on loopback).
    pub(crate) fn runs_go2(&self) -> bool {
        self.only.is_none_or(|d| d.uses_dds())
    }
}

impl Device {
    fn uses_dds(self) -> bool {
        matches!(self, Self::Go2 | Self::G1)
    }
}

/// A device's scenario: runs for about the given seconds of motion, reports what it saw; its
/// device's links recorded with the recorder, if any.
type Scenario = fn(f64, &Output, Option<&RecordLinks>) -> anyhow::Result<DeviceReport>;

/// How long `demo --live` waits for its first viewer.
const LIVE_VIEWER_WAIT: std::time::Duration = std::time::Duration::from_secs(30);

/// Runs the demo; `loopback`: where the DDS scenarios run (`None`: they are not run).
pub(crate) fn run(args: &DemoArgs, loopback: Option<Loopback>) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.duration.is_finite() && (0.3..=600.0).contains(&args.duration),
        "--duration must be between 0.3 and 600 s, got {}",
        args.duration
    );
    // With `--json`, the human-readable report goes to stderr and stdout carries only the JSON.
    let out = Output::new(args.json);
    let mut dds = true;
    match loopback {
        Some(Loopback::UserNamespace) => out.line(
            "loopback has no multicast (DDS discovery needs it): the demo runs in a user + network namespace of its own",
        ),
        Some(Loopback::Unavailable(e)) if args.only.is_none() => {
            out.line(format_args!("skipped the Go2 and G1 scenarios: DDS on one machine needs multicast on lo: {e}"));
            dds = false;
        }
        Some(Loopback::Unavailable(e)) => anyhow::bail!("the DDS scenarios need multicast on lo: {e}"),
        _ => {}
    }
    let scenarios: [(Device, Scenario); 5] = [
        (Device::Kmc, kmc::run),
        (Device::Zsl1, zsl1::run),
        (Device::Spline, spline::run),
        (Device::Go2, lowcmd::run),
        (Device::G1, g1::run),
    ];
    if let Some(dir) = &args.plot {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let capture = match (&args.record.record, &args.plot) {
        (Some(file), _) => Some(file.clone()),
        (None, Some(dir)) => Some(dir.join("demo.mcap")),
        (None, None) => None,
    };
    let taps = crate::cmd::taps::Taps {
        recorder: crate::cmd::record::start_with(capture.as_deref(), "robowire demo", args.record.compression)?,
        live: args.record.live.start("robowire demo")?,
    };
    let record = taps.links();
    if let Some(events) = taps.events() {
        out.also_to(events, "demo");
    }
    if let Some(live) = &taps.live {
        // Each device's scenario is over in seconds: the first viewer is waited for, so that it
        // sees every device.
        eprintln!("live: waiting up to {} s for a viewer", LIVE_VIEWER_WAIT.as_secs());
        if !live.wait_for_viewer(LIVE_VIEWER_WAIT) {
            eprintln!("live: no viewer; the demo runs all the same");
        }
    }
    let mut reports = Vec::new();
    for (device, scenario) in scenarios {
        if args.only.is_none_or(|d| d == device) && (dds || !device.uses_dds()) {
            if !reports.is_empty() {
                out.line("");
            }
            let started = Instant::now();
            let mut report = scenario(args.duration, &out, record.as_ref())?;
            report.elapsed = started.elapsed();
            reports.push(report);
        }
    }
    taps.finish()?;
    if let (Some(dir), Some(capture)) = (&args.plot, &capture) {
        draw(dir, capture, &out)?;
    }
    out.line("");
    out.line("checks");
    for check in reports.iter().flat_map(|r| &r.checks).filter(|c| !c.timing) {
        let mark = if check.passed { " ok " } else { "FAIL" };
        out.line(format_args!("  [{mark}] {:<52} {}", check.what, check.observed));
    }
    out.line("");
    out.line("timing (reported, not judged here: `cargo xtask bench` holds the targets on an idle machine)");
    for check in reports.iter().flat_map(|r| &r.checks).filter(|c| c.timing) {
        let mark = if check.passed { " ok " } else { "slow" };
        out.line(format_args!("  [{mark}] {:<52} {}", check.what, check.observed));
    }
    out.line("");
    out.line("summary");
    out.line(format_args!("{}", report::table(&reports).trim_end()));
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report::json(&reports))?);
    }
    let functional = || reports.iter().flat_map(|r| &r.checks).filter(|c| !c.timing);
    let total = functional().count();
    let failed = functional().filter(|c| !c.passed).count();
    out.line("");
    if failed == 0 {
        out.line(format_args!("demo passed: {total} checks"));
        Ok(ExitCode::SUCCESS)
    } else {
        out.line(format_args!("demo FAILED: {failed} of {total} checks"));
        Ok(ExitCode::FAILURE)
    }
}
