//! `robowire demo`: every simulated device, driven through its client API, with checks that
//! what was commanded was observed.

use std::sync::atomic::{AtomicBool, Ordering};

/// With `--json`, the human-readable report goes to stderr and stdout carries only the JSON.
static JSON: AtomicBool = AtomicBool::new(false);

/// `println!` for the demo's report: stdout, or stderr under `--json`.
macro_rules! say {
    ($($arg:tt)*) => {
        if $crate::demo::JSON.load(std::sync::atomic::Ordering::Relaxed) {
            eprintln!($($arg)*)
        } else {
            println!($($arg)*)
        }
    };
}

mod dog;
mod kmc;
mod lowcmd;
mod spline;

use std::process::ExitCode;

use clap::{Args, ValueEnum};

#[derive(Debug, Args)]
pub(crate) struct DemoArgs {
    /// Seconds of motion per device scenario, split over its phases (at least 0.8 s each, so
    /// the machine can settle).
    #[arg(long, default_value_t = 3.0)]
    duration: f64,
    /// Run one device's scenario only.
    #[arg(long, value_enum)]
    only: Option<Device>,
    /// Print the checks as JSON on stdout (the report goes to stderr).
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Device {
    /// KMC wheeled chassis on a pseudo-terminal.
    Kmc,
    /// ZSL-1 on loopback UDP (the HighLevel client).
    Dog,
    /// ZSL-1 spline daemon on shared memory (the 1 kHz low-level loop).
    Spline,
    /// Unitree LowCmd/LowState encode, decode and verify at 500 Hz.
    Lowcmd,
}

/// One thing a scenario commanded and whether it was observed.
#[derive(Debug)]
pub(crate) struct Check {
    pub(crate) what: String,
    pub(crate) passed: bool,
    pub(crate) observed: String,
}

impl Check {
    pub(crate) fn new(what: impl Into<String>, passed: bool, observed: impl Into<String>) -> Self {
        Self { what: what.into(), passed, observed: observed.into() }
    }
}

pub(crate) fn run(args: &DemoArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.duration.is_finite() && (0.3..=600.0).contains(&args.duration),
        "--duration must be between 0.3 and 600 s, got {}",
        args.duration
    );
    JSON.store(args.json, Ordering::Relaxed);
    let mut checks = Vec::new();
    if args.only.is_none_or(|d| d == Device::Kmc) {
        checks.extend(kmc::run(args.duration)?);
    }
    if args.only.is_none_or(|d| d == Device::Dog) {
        say!();
        checks.extend(dog::run(args.duration)?);
    }
    if args.only.is_none_or(|d| d == Device::Spline) {
        say!();
        checks.extend(spline::run(args.duration)?);
    }
    if args.only.is_none_or(|d| d == Device::Lowcmd) {
        say!();
        checks.extend(lowcmd::run(args.duration)?);
    }
    say!();
    say!("checks");
    for check in &checks {
        say!("  [{}] {:<52} {}", if check.passed { " ok " } else { "FAIL" }, check.what, check.observed);
    }
    let failed = checks.iter().filter(|c| !c.passed).count();
    if args.json {
        let checks: Vec<_> = checks
            .iter()
            .map(|c| serde_json::json!({"check": c.what, "passed": c.passed, "observed": c.observed}))
            .collect();
        let report = serde_json::json!({"passed": failed == 0, "failed": failed, "checks": checks});
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    say!();
    if failed == 0 {
        say!("demo passed: {} checks", checks.len());
        Ok(ExitCode::SUCCESS)
    } else {
        say!("demo FAILED: {failed} of {} checks", checks.len());
        Ok(ExitCode::FAILURE)
    }
}
