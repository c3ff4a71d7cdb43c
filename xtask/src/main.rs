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
    /// Run every test of the project: `cargo test --workspace`, the physics tests (when MuJoCo
    /// is here: `cargo xtask mujoco`), then the Python suite on the wheel built as users build
    /// it, on CPython 3.10 and 3.12 (or 3.13).
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
        Task::Golden { bless } => golden(bless),
        Task::Fuzz { target, time } => xtask::fuzz::run(target.as_deref(), time),
        Task::Test { python_only: false } => xtask::python::test_all(),
        Task::Test { python_only: true } => xtask::python::test_python(),
        Task::Mujoco => mujoco(),
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

fn mujoco() -> anyhow::Result<()> {
    let root = xtask::workspace_root();
    let dir = xtask::physics::fetch(std::path::Path::new("python3"), &xtask::python::target_dir(&root))?;
    let dir = dir.canonicalize()?;
    eprintln!("MuJoCo {} in {}; for physics (`--features mujoco`):", xtask::physics::MUJOCO_VERSION, dir.display());
    // The exports alone on stdout, for `eval "$(cargo xtask mujoco)"`.
    println!(
        "export MUJOCO_DYNAMIC_LINK_DIR={0} LD_LIBRARY_PATH={0}${{LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}}",
        dir.display()
    );
    Ok(())
}

fn golden(bless: bool) -> anyhow::Result<()> {
    let kmc_path = xtask::golden::kmc::kmc_fixture_path();
    let unitree_path = xtask::golden::unitree::vectors_path();
    let zsl1_path = xtask::golden::zsl1::frames_path();
    let rtps_path = xtask::golden::rtps::fixtures_path();
    let suites = [
        ("kmc", xtask::golden::kmc::check_kmc(&kmc_path, bless)?),
        ("unitree", xtask::golden::unitree::check(&unitree_path)?),
        ("zsl1", xtask::golden::zsl1::check(&zsl1_path)?),
        ("rtps", xtask::golden::rtps::check(&rtps_path)?),
    ];
    let mut failed = 0;
    let mut total = 0;
    for (suite, outcomes) in &suites {
        for outcome in outcomes {
            total += 1;
            let status = if !outcome.problems.is_empty() {
                failed += 1;
                "FAIL"
            } else if outcome.blessed {
                "BLESSED"
            } else {
                "ok"
            };
            println!("{suite:<8} {:<48} {status}", outcome.name);
            for problem in &outcome.problems {
                println!("    {problem}");
            }
        }
    }
    anyhow::ensure!(failed == 0, "{failed} of {total} golden checks failed");
    println!(
        "{total} golden checks passed ({}, {}, {}, {})",
        kmc_path.display(),
        unitree_path.display(),
        zsl1_path.display(),
        rtps_path.display()
    );
    Ok(())
}
