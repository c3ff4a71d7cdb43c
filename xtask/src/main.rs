//! `cargo xtask <command>`: see `cargo xtask --help`.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// robowire project automation.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask")]
struct Cli {
    #[command(subcommand)]
    command: Task,
}

#[derive(Debug, Subcommand)]
enum Task {
    /// Decode and re-encode every golden fixture byte for byte.
    Golden {
        /// Rewrite the expected fields of mismatching fixtures from the decoder (never the bytes).
        #[arg(long)]
        bless: bool,
    },
    /// Run the cargo-fuzz targets (all, or one) with seed corpora from the fixtures.
    Fuzz {
        /// Target name; all targets when omitted.
        target: Option<String>,
        /// Seconds per target.
        #[arg(long, default_value_t = 20)]
        time: u64,
    },
    /// Run the benchmarks and print the performance table.
    Bench {
        /// Shorter measurements (a smoke run).
        #[arg(long)]
        quick: bool,
    },
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Task::Golden { bless } => golden(bless),
        Task::Fuzz { target, time } => xtask::fuzz::run(target.as_deref(), time),
        Task::Bench { quick } => xtask::bench::run(quick).and_then(|rows| {
            anyhow::ensure!(rows.iter().all(|r| r.met != Some(false)), "a benchmark missed its target");
            Ok(())
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn golden(bless: bool) -> anyhow::Result<()> {
    let path = xtask::golden::kmc_fixture_path();
    let outcomes = xtask::golden::check_kmc(&path, bless)?;
    let mut failed = 0;
    for outcome in &outcomes {
        let status = if !outcome.problems.is_empty() {
            failed += 1;
            "FAIL"
        } else if outcome.blessed {
            "BLESSED"
        } else {
            "ok"
        };
        println!("kmc {:<28} {status}", outcome.name);
        for problem in &outcome.problems {
            println!("    {problem}");
        }
    }
    anyhow::ensure!(failed == 0, "{failed} golden check(s) failed ({})", path.display());
    println!("{} golden checks passed ({})", outcomes.len(), path.display());
    Ok(())
}
