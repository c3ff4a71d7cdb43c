//! `cargo xtask <command>`: see `cargo xtask --help`.

#![forbid(unsafe_code)]

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
    /// Run every test of the project: `cargo test --workspace`, the Python suite on the wheel
    /// built as users build it, on CPython 3.10 and 3.12 (or 3.13), then the physics tests (when
    /// MuJoCo is here: `cargo xtask mujoco`).
    Test {
        /// Only the Python suite (the wheel, both CPythons).
        #[arg(long)]
        python_only: bool,
    },
    /// Fetch MuJoCo 3.17.0's library from PyPI (the `mujoco==3.17.0` wheel, with `python3`'s
    /// pip) into target/mujoco/lib and print how to build and run with physics.
    Mujoco,
    /// Run the benchmarks and print the performance table.
    Bench {
        /// Shorter measurements (a smoke run).
        #[arg(long)]
        quick: bool,
    },
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Task::Golden { bless } => xtask::golden::run(bless),
        #[cfg(feature = "full")]
        Task::Fuzz { target, time } => xtask::fuzz::run(target.as_deref(), time),
        #[cfg(feature = "full")]
        Task::Test { python_only: false } => xtask::test::test_all(),
        #[cfg(feature = "full")]
        Task::Test { python_only: true } => xtask::test::test_python(),
        #[cfg(not(feature = "full"))]
        Task::Fuzz { .. } | Task::Test { .. } => xtask::with_full(),
        Task::Mujoco => xtask::mujoco::run(),
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
