//! `robowire demo`: every simulated device, driven through its client API, with checks that
//! what was commanded was observed.

mod dog;
mod kmc;
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
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Device {
    /// KMC wheeled chassis on a pseudo-terminal.
    Kmc,
    /// ZSL-1 on loopback UDP (the HighLevel client).
    Dog,
    /// ZSL-1 spline daemon on shared memory (the 1 kHz low-level loop).
    Spline,
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
    let mut checks = Vec::new();
    if args.only.is_none_or(|d| d == Device::Kmc) {
        checks.extend(kmc::run(args.duration)?);
    }
    if args.only.is_none_or(|d| d == Device::Dog) {
        println!();
        checks.extend(dog::run(args.duration)?);
    }
    if args.only.is_none_or(|d| d == Device::Spline) {
        println!();
        checks.extend(spline::run(args.duration)?);
    }
    println!();
    println!("checks");
    for check in &checks {
        println!("  [{}] {:<52} {}", if check.passed { " ok " } else { "FAIL" }, check.what, check.observed);
    }
    let failed = checks.iter().filter(|c| !c.passed).count();
    println!();
    if failed == 0 {
        println!("demo passed: {} checks", checks.len());
        Ok(ExitCode::SUCCESS)
    } else {
        println!("demo FAILED: {failed} of {} checks", checks.len());
        Ok(ExitCode::FAILURE)
    }
}
