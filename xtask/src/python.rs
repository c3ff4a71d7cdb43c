//! The Python toolbox of the test and bench tasks: the wheel built as a user builds it
//! (`pip wheel crates/robowire-py`), pip, and the CPython 3.10 interop environment.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, anyhow, bail};
use robowire_fixtures::peers::unitree_python;

/// The target directory (`$CARGO_TARGET_DIR` or `target/`).
pub fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from)
}

pub(crate) fn run(what: &str, command: &mut Command) -> anyhow::Result<()> {
    let status = command.status().with_context(|| format!("{what}: cannot start {command:?}"))?;
    if !status.success() {
        bail!("{what} failed ({status})");
    }
    Ok(())
}

pub(crate) fn pip(python: &Path, args: &[&str]) -> anyhow::Result<()> {
    run(
        &format!("pip {}", args.join(" ")),
        Command::new(python).args(["-m", "pip", "--disable-pip-version-check", "-q"]).args(args),
    )
}

/// The CPython 3.10 interop environment with the freshly built wheel installed.
pub(crate) fn py310_with_wheel(root: &Path, target: &Path) -> anyhow::Result<(PathBuf, PathBuf)> {
    let py310 = unitree_python().map_err(|e| anyhow!("the CPython 3.10 interop environment: {e}"))?;
    let wheel = build_wheel(root, target, &py310)?;
    install(&py310, &wheel)?;
    Ok((py310, wheel))
}

/// Installs `wheel` (not editable), replacing any earlier build of the same version.
pub(crate) fn install(python: &Path, wheel: &Path) -> anyhow::Result<()> {
    pip(python, &["install", "--force-reinstall", "--no-deps", "--no-warn-script-location", &wheel.to_string_lossy()])
}

/// `pip wheel crates/robowire-py`, as the README tells users to install it.
pub(crate) fn build_wheel(root: &Path, target: &Path, python: &Path) -> anyhow::Result<PathBuf> {
    build_wheel_with(root, target, python, None)
}

/// [`build_wheel`], with physics (the cargo feature `mujoco`, against the MuJoCo in `mujoco`)
/// when given, as the README tells users to build it.
pub(crate) fn build_wheel_with(
    root: &Path,
    target: &Path,
    python: &Path,
    mujoco: Option<&Path>,
) -> anyhow::Result<PathBuf> {
    let out = target.join(if mujoco.is_some() { "wheels-mujoco" } else { "wheels" });
    let _ = std::fs::remove_dir_all(&out);
    let with = if mujoco.is_some() { " --features mujoco" } else { "" };
    println!("== building the wheel (pip wheel crates/robowire-py, maturin, release{with})");
    let crate_dir = root.join("crates/robowire-py");
    run(
        "pip wheel",
        Command::new(python)
            .args(["-m", "pip", "--disable-pip-version-check", "-q", "wheel", "--no-deps", "-w"])
            .arg(&out)
            .arg(&crate_dir)
            .envs(mujoco.map(|dir| ("MUJOCO_DYNAMIC_LINK_DIR", dir.as_os_str())))
            .envs(mujoco.map(|_| ("MATURIN_PEP517_ARGS", std::ffi::OsStr::new("--features mujoco")))),
    )?;
    let wheel = std::fs::read_dir(&out)?
        .flatten()
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|e| e == "whl"))
        .context("pip wheel made no wheel")?;
    println!("built {}", wheel.display());
    Ok(wheel)
}
