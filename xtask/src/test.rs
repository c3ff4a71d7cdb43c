//! `cargo xtask test`: every test of the project, Rust then Python.
//!
//! The Python suite (`crates/robowire-py/tests`) runs on the wheel built here the way a user
//! builds it (`pip wheel crates/robowire-py`: maturin from PyPI, release profile), installed
//! into two CPythons (never an editable install):
//!
//! - 3.10: Unitree's pin of cyclonedds has wheels for it and the vendor's ZSL-1 modules are built
//!   for it, so this is the environment of the interop tests (`robowire-fixtures`' venv with
//!   cyclonedds 0.10.2, numpy, mcap and Unitree's SDK), where the vendor's module, Unitree's SDK,
//!   the `mcap` reader and the CLI are required: a missing peer fails the run instead of skipping. Without CPython 3.10
//!   or the peers this run is skipped with a line (failed under `ROBOWIRE_INTEROP=1`);
//! - 3.12 (or 3.13, else any `python3` ≥ 3.9): a bare venv with pytest only, which proves numpy
//!   is not needed.
//!
//! DDS is required in both where a private network can be made (root, or a user namespace).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::bail;
use robowire_dds::netns::userns;
use robowire_fixtures::interop;
use robowire_fixtures::peers::{cpython, unitree_python};

use crate::python::{build_wheel, build_wheel_with, install, pip, run, target_dir};
use crate::workspace_root;

/// Whether this process runs as root (pytest then makes its private network itself).
fn is_root() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("Uid:")).map(|l| l.split_whitespace().nth(1) == Some("0")))
        .unwrap_or(false)
}

/// `cargo test --workspace`, the Python suite, then the physics tests ([`crate::mujoco`]).
pub fn test_all() -> anyhow::Result<()> {
    let root = workspace_root();
    cargo(&root, &["test", "--workspace"])?;
    // The Python suite runs the CLI that run built (`target/debug/robowire`): built again by
    // itself, with the features of its own dependencies only, half the workspace would be rebuilt.
    python_suite(&root)?;
    crate::mujoco::test(&root, &target_dir(&root))
}

/// Builds the wheel and runs the Python suite: on the CPython 3.10 interop environment (gated
/// like every interop test: skipped with a line when CPython 3.10 or the peers are missing,
/// failed under `ROBOWIRE_INTEROP=1`), then on CPython 3.12/3.13 or any `python3` ≥ 3.9. Not
/// root, pytest runs as the root of a user namespace with a network of its own
/// (`unshare --user --map-root-user --net`), where the suite makes its DDS network; pip runs
/// before, outside.
pub fn test_python() -> anyhow::Result<()> {
    let root = workspace_root();
    cargo(&root, &["build", "-q", "-p", "robowire"])?;
    python_suite(&root)
}

/// [`test_python`] with the CLI built.
fn python_suite(root: &Path) -> anyhow::Result<()> {
    let target = target_dir(root);
    let py310 = match unitree_python() {
        Ok(python) => Some(python),
        Err(e) => {
            interop::missing("the Python suite's CPython 3.10 interop run", e).map_err(anyhow::Error::msg)?;
            None
        }
    };
    let (version, second) = second_python()?;
    let second_venv = bare_venv(&target, &version, &second)?;
    let wheel = build_wheel(root, &target, py310.as_ref().unwrap_or(&second_venv))?;
    // DDS: root makes its namespace in the suite; anyone else runs it in a user namespace.
    let userns = if is_root() { Ok(false) } else { userns::command("true").map(|_| true) };
    let dds = match &userns {
        Ok(_) => ",dds",
        Err(e) => {
            interop::missing("the Python suite's DDS tests", format!("no user + network namespace: {e}"))
                .map_err(anyhow::Error::msg)?;
            ""
        }
    };
    let suite = |python, require: &str| PytestRun {
        python,
        wheel: wheel.clone(),
        require: require.into(),
        tests: &[],
        mujoco: None,
    };
    let runs = py310.map(|python| suite(python, "vendor,sdk,mcap,cli")).into_iter().chain([suite(second_venv, "cli")]);
    for run_ in runs {
        pytest_run(root, &target, &run_, &userns, dds)?;
    }
    // With MuJoCo here, the physics tests once more on a wheel built with the feature, in a
    // venv of their own: after the suite's runs, as maturin also writes each wheel it builds
    // into target/wheels, where the default wheel of the runs above lies.
    match crate::mujoco::lib_dir(&target) {
        Ok(dir) => {
            let venv = bare_venv(&target, &format!("{version}-physics"), &second)?;
            let wheel = build_wheel_with(root, &target, &venv, Some(&dir))?;
            let tests = &["test_physics.py", "test_policy.py"];
            let physics = PytestRun { python: venv, wheel, require: "physics".into(), tests, mujoco: Some(dir) };
            pytest_run(root, &target, &physics, &userns, dds)
        }
        Err(missing) => interop::missing("the Python physics tests (MuJoCo)", missing).map_err(anyhow::Error::msg),
    }
}

/// Runs `run_`: pytest in a user + network namespace (`userns` `Ok(true)`) or here; `dds` is
/// `",dds"` where DDS must not skip.
fn pytest_run(
    root: &Path,
    target: &Path,
    run_: &PytestRun,
    userns: &Result<bool, String>,
    dds: &str,
) -> anyhow::Result<()> {
    install(&run_.python, &run_.wheel)?;
    pip(&run_.python, &["install", "--no-warn-script-location", "pytest"])?;
    let require = format!("{}{dds}", run_.require);
    let mut pytest = match userns {
        Ok(true) => userns::command(&run_.python).map_err(anyhow::Error::msg)?,
        _ => Command::new(&run_.python),
    };
    let inside = if matches!(userns, Ok(true)) { " in a user + network namespace" } else { "" };
    println!("\n== pytest on {}{inside} (required here: {require})", run_.python.display());
    let suite = root.join("crates/robowire-py/tests");
    let tests: Vec<PathBuf> = match run_.tests {
        [] => vec![suite],
        files => files.iter().map(|f| suite.join(f)).collect(),
    };
    run(
        "pytest",
        pytest
            .args(["-m", "pytest"])
            .args(tests)
            .args(["-q", "-p", "no:cacheprovider", "-rs"])
            .env("ROBOWIRE_REQUIRE", &require)
            .env("ROBOWIRE_CLI", target.join("debug/robowire"))
            .envs(run_.mujoco.iter().map(|dir| ("LD_LIBRARY_PATH", dir)))
            .current_dir(root),
    )?;
    Ok(())
}

/// One pytest run: `tests` (files of the suite; none: all of it) with `python`, on `wheel`,
/// `require` naming what must not be missing; `mujoco`: MuJoCo's directory for the loader.
struct PytestRun {
    python: PathBuf,
    wheel: PathBuf,
    require: String,
    tests: &'static [&'static str],
    mujoco: Option<PathBuf>,
}

fn cargo(root: &Path, args: &[&str]) -> anyhow::Result<()> {
    run(&format!("cargo {}", args.join(" ")), Command::new("cargo").args(args).current_dir(root))
}

/// `major.minor` of `python`, if it runs.
fn python_version(python: &Path) -> Option<(u32, u32)> {
    let out = Command::new(python).args(["-c", "import sys; print(*sys.version_info[:2])"]).output().ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut parts = text.split_whitespace().map(|n| n.parse().ok());
    Some((parts.next()??, parts.next()??))
}

/// The Python of the suite's second run: CPython 3.12 or 3.13, else any `python3` ≥ 3.9 on the
/// `PATH`; its `major.minor`.
fn second_python() -> anyhow::Result<(String, PathBuf)> {
    let found = ["3.12", "3.13"].into_iter().find_map(|v| cpython(v).map(|p| (v.to_owned(), p)));
    if let Some(found) = found {
        return Ok(found);
    }
    let python3 = PathBuf::from("python3");
    match python_version(&python3) {
        Some((major, minor)) if (major, minor) >= (3, 9) => Ok((format!("{major}.{minor}"), python3)),
        Some((major, minor)) => bail!("python3 is {major}.{minor}; the Python suite needs 3.9 or newer"),
        None => bail!("no python3 on the PATH for the Python suite (3.9 or newer; 3.12 preferred)"),
    }
}

/// A venv with nothing but pip (pytest is added by the caller), made once per `target/`.
fn bare_venv(target: &Path, version: &str, python: &Path) -> anyhow::Result<PathBuf> {
    let venv = target.join("pytest").join(format!("py{}", version.replace('.', "")));
    let bin = venv.join("bin/python");
    if !bin.exists() {
        run("creating a venv", Command::new(python).args(["-m", "venv"]).arg(&venv))?;
    }
    Ok(bin)
}
