//! The vendors' own software as the other end of the wire in interop tests
//! (`../shared/peers/`, see its README): a CPython 3.10 environment with `cyclonedds` 0.10.2
//! (Unitree's pin; its wheel bundles a libddsc of its own that names itself 0.11.0:
//! `libddsc-….so.0.11.0`, "0.11.0" in its SPDP version info), numpy, mcap, mcap-ros2-support and
//! rosbags (the capture readers) and Unitree's Python SDK installed as its README says
//! (`pip install --no-deps -e`, from a copy under `target/` so that the peers' tree stays
//! untouched); and a second one with CycloneDDS 11 ([`cyclonedds11_python`]).
//!
//! Made once per `target/` directory, under a file lock (tests run in parallel), and reused. When
//! it cannot be made (no peers, no CPython 3.10, no PyPI on the first run) the error says what is
//! missing; a test passes it to [`crate::interop::require`], which skips the test with that line,
//! or fails it under `ROBOWIRE_INTEROP=1`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// `cyclonedds` on PyPI: the version Unitree's SDK pins.
pub const CYCLONEDDS_VERSION: &str = "0.10.2";
/// `cyclonedds` on PyPI of CycloneDDS 11 (its wheel bundles libddsc 11.0.1; wheels for CPython
/// 3.12 and 3.13 among others, none for 3.10), the second CycloneDDS of the interop tests.
pub const CYCLONEDDS11_VERSION: &str = "11.0.1";
/// The `mcap` Python package: the independent reader of robowire's captures.
pub const MCAP_PY_VERSION: &str = "1.6.0";
/// `mcap-ros2-support`: the `mcap` package's ROS 2 decoder (`ros2msg` schemas, CDR).
pub const MCAP_ROS2_PY_VERSION: &str = "0.6.0";
/// `rosbags`: an independent ROS 2 bag reader and CDR decoder (no ROS install).
pub const ROSBAGS_VERSION: &str = "0.11.9";

/// The workspace root.
fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The vendors' software: `$ROBOWIRE_PEERS`, else `../shared/peers` beside the workspace.
pub fn peers_dir() -> PathBuf {
    std::env::var_os("ROBOWIRE_PEERS").map_or_else(
        || {
            // Resolved, so that a message names `/home/me/shared/peers`, not `…/crates/x/../../..`.
            let workspace = workspace().canonicalize().unwrap_or_else(|_| workspace());
            workspace.parent().unwrap_or(&workspace).join("shared/peers")
        },
        PathBuf::from,
    )
}

/// Unitree's walking policies as ONNX with their deploy configs: `$ROBOWIRE_POLICIES`, else
/// `../shared/policies` beside the workspace; an error when it has no `g1_walk.onnx`.
pub fn policies_dir() -> Result<PathBuf, String> {
    let dir =
        std::env::var_os("ROBOWIRE_POLICIES").map_or_else(|| peers_dir().with_file_name("policies"), PathBuf::from);
    if dir.join("g1_walk.onnx").is_file() {
        Ok(dir)
    } else {
        Err(format!(
            "no {}: Unitree's G1 walking policy as ONNX (set ROBOWIRE_POLICIES)",
            dir.join("g1_walk.onnx").display()
        ))
    }
}

/// Where the environment lives: `$CARGO_TARGET_DIR` (or `target/`)`/interop/py310`.
fn env_dir() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| workspace().join("target"), PathBuf::from);
    target.join("interop")
}

/// A CPython 3.10 interpreter: `$ROBOWIRE_PYTHON310`, pyenv's newest 3.10, or `python3.10`.
fn python310() -> Result<PathBuf, String> {
    if let Some(path) = std::env::var_os("ROBOWIRE_PYTHON310") {
        return Ok(path.into());
    }
    cpython("3.10").ok_or_else(|| {
        "no CPython 3.10 (cyclonedds 0.10.2 has wheels for 3.10 only): install one with pyenv, or set \
         ROBOWIRE_PYTHON310"
            .into()
    })
}

/// A CPython `version` (`"3.12"`) interpreter: pyenv's newest of that version, or `python3.12`
/// on the `PATH`.
pub fn cpython(version: &str) -> Option<PathBuf> {
    let pyenv_root = std::env::var_os("PYENV_ROOT")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".pyenv")));
    let executable = format!("python{version}");
    if let Some(root) = pyenv_root
        && let Ok(versions) = std::fs::read_dir(root.join("versions"))
    {
        let prefix = format!("{version}.");
        let mut found: Vec<(u32, PathBuf)> = versions
            .flatten()
            .map(|e| e.path())
            .filter_map(|p| {
                let name = p.file_name()?.to_str()?;
                let patch = name.strip_prefix(&prefix)?.parse().ok()?;
                Some((patch, p.join("bin").join(&executable)))
            })
            .filter(|(_, p)| p.exists())
            .collect();
        found.sort();
        if let Some((_, newest)) = found.pop() {
            return Some(newest);
        }
    }
    let on_path = Command::new(&executable).arg("--version").output();
    on_path.is_ok_and(|o| o.status.success()).then(|| executable.into())
}

fn run(what: &str, command: &mut Command) -> Result<(), String> {
    let out = command.output().map_err(|e| format!("{what}: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!("{what} failed ({}): {}", out.status, String::from_utf8_lossy(&out.stderr).trim()))
    }
}

fn copy_tree(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let target = to.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            copy_tree(&entry.path(), &target)?;
        } else {
            std::fs::copy(entry.path(), target)?;
        }
    }
    Ok(())
}

/// The Python of the environment (made on first use); see the [module](self).
pub fn unitree_python() -> Result<PathBuf, String> {
    let dir = env_dir();
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let lock = std::fs::File::create(dir.join(".lock")).map_err(|e| e.to_string())?;
    lock.lock().map_err(|e| format!("locking {}: {e}", dir.display()))?;
    let venv = dir.join("py310");
    let python = venv.join("bin/python");
    // Versioned: an environment made before a package was added is made again.
    let stamp = venv.join(".robowire-ready-3");
    if stamp.exists() {
        return Ok(python);
    }
    let sdk = peers_dir().join("unitree_sdk2_python");
    if !sdk.join("setup.py").exists() {
        return Err(format!("Unitree's Python SDK is not at {} (set ROBOWIRE_PEERS)", sdk.display()));
    }
    let _ = std::fs::remove_dir_all(&venv);
    run("creating the venv", Command::new(python310()?).args(["-m", "venv"]).arg(&venv))?;
    let pip = |args: &[&str]| {
        let mut c = Command::new(&python);
        c.args(["-m", "pip", "install", "-q", "--disable-pip-version-check"]).args(args);
        c
    };
    run(
        "pip install cyclonedds numpy mcap mcap-ros2-support rosbags",
        &mut pip(&[
            &format!("cyclonedds=={CYCLONEDDS_VERSION}"),
            "numpy",
            &format!("mcap=={MCAP_PY_VERSION}"),
            &format!("mcap-ros2-support=={MCAP_ROS2_PY_VERSION}"),
            &format!("rosbags=={ROSBAGS_VERSION}"),
        ]),
    )?;
    let copy = dir.join("unitree_sdk2_python");
    let _ = std::fs::remove_dir_all(&copy);
    copy_tree(&sdk, &copy).map_err(|e| format!("copying the SDK: {e}"))?;
    run("pip install the SDK", pip(&["--no-deps", "-e"]).arg(&copy))?;
    std::fs::write(&stamp, b"").map_err(|e| e.to_string())?;
    Ok(python)
}

/// The Python of a second environment, `$CARGO_TARGET_DIR/interop-cyclone11/py`: CPython 3.12
/// (else 3.13) with `cyclonedds` [`CYCLONEDDS11_VERSION`], numpy and Unitree's Python SDK
/// (`--no-deps -e`, from a copy beside it: its IDL classes and CRC; its pin of cyclonedds 0.10.2
/// is not followed). Made once, under a file lock, as [`unitree_python`].
pub fn cyclonedds11_python() -> Result<PathBuf, String> {
    let target = env_dir();
    let dir = target.with_file_name("interop-cyclone11");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let lock = std::fs::File::create(dir.join(".lock")).map_err(|e| e.to_string())?;
    lock.lock().map_err(|e| format!("locking {}: {e}", dir.display()))?;
    let venv = dir.join("py");
    let python = venv.join("bin/python");
    let stamp = venv.join(".robowire-ready-1");
    if stamp.exists() {
        return Ok(python);
    }
    let sdk = peers_dir().join("unitree_sdk2_python");
    if !sdk.join("setup.py").exists() {
        return Err(format!("Unitree's Python SDK is not at {} (set ROBOWIRE_PEERS)", sdk.display()));
    }
    let interpreter = cpython("3.12").or_else(|| cpython("3.13")).ok_or_else(|| {
        format!(
            "no CPython 3.12 or 3.13 (cyclonedds {CYCLONEDDS11_VERSION} has no wheel for 3.10): install one with pyenv"
        )
    })?;
    let _ = std::fs::remove_dir_all(&venv);
    run("creating the venv", Command::new(interpreter).args(["-m", "venv"]).arg(&venv))?;
    let pip = |args: &[&str]| {
        let mut c = Command::new(&python);
        c.args(["-m", "pip", "install", "-q", "--disable-pip-version-check"]).args(args);
        c
    };
    run("pip install cyclonedds numpy", &mut pip(&[&format!("cyclonedds=={CYCLONEDDS11_VERSION}"), "numpy"]))?;
    let copy = dir.join("unitree_sdk2_python");
    let _ = std::fs::remove_dir_all(&copy);
    copy_tree(&sdk, &copy).map_err(|e| format!("copying the SDK: {e}"))?;
    run("pip install the SDK", pip(&["--no-deps", "-e"]).arg(&copy))?;
    std::fs::write(&stamp, b"").map_err(|e| e.to_string())?;
    Ok(python)
}

/// Unitree's Go2 low-level examples (in the environment's copy of the SDK).
pub fn unitree_go2_examples() -> Result<PathBuf, String> {
    unitree_python()?;
    Ok(env_dir().join("unitree_sdk2_python/example/go2/low_level"))
}

/// Unitree's G1 examples (`low_level/`, `high_level/`, in the environment's copy of the SDK).
pub fn unitree_g1_examples() -> Result<PathBuf, String> {
    unitree_python()?;
    Ok(env_dir().join("unitree_sdk2_python/example/g1"))
}

/// The npm packages of the project in `project` (its `package.json` and `package-lock.json`),
/// installed by `npm ci` from the lock file under `target/interop/npm/{name}` (once per lock
/// file, under a file lock): their `node_modules`, for `NODE_PATH`. An error says what is missing
/// (node, npm, the npm registry).
pub fn npm_project(name: &str, project: &Path) -> Result<PathBuf, String> {
    run("node", Command::new("node").arg("--version"))?;
    run("npm", Command::new("npm").arg("--version"))?;
    let dir = env_dir().join("npm").join(name);
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let lock = std::fs::File::create(dir.join(".lock")).map_err(|e| e.to_string())?;
    lock.lock().map_err(|e| format!("locking {}: {e}", dir.display()))?;
    let read = |p: PathBuf| std::fs::read(&p).map_err(|e| format!("{}: {e}", p.display()));
    let manifest = [read(project.join("package.json"))?, read(project.join("package-lock.json"))?];
    let stamp = dir.join(".robowire-ready");
    if std::fs::read(&stamp).ok() == Some(manifest.concat()) {
        return Ok(dir.join("node_modules"));
    }
    let _ = std::fs::remove_file(&stamp);
    std::fs::write(dir.join("package.json"), &manifest[0]).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("package-lock.json"), &manifest[1]).map_err(|e| e.to_string())?;
    run(
        &format!("npm ci in {} (packages from the npm registry)", project.display()),
        Command::new("npm").args(["ci", "--no-audit", "--no-fund", "--ignore-scripts"]).current_dir(&dir),
    )?;
    std::fs::write(&stamp, manifest.concat()).map_err(|e| e.to_string())?;
    Ok(dir.join("node_modules"))
}

/// `node SCRIPT ARGS…` with the packages of `node_modules`: its stdout as JSON. Fails the test,
/// with node's stderr, when the script fails.
#[track_caller]
pub fn node_json(node_modules: &Path, script: &Path, args: &[&str]) -> serde_json::Value {
    let out = Command::new("node")
        .arg(script)
        .args(args)
        .env("NODE_PATH", node_modules)
        .output()
        .unwrap_or_else(|e| panic!("running node {}: {e}", script.display()));
    let name = script.display();
    assert!(out.status.success(), "{name}: {}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{name}: {e}: {}", String::from_utf8_lossy(&out.stdout)))
}

/// Chromium for the browser tests: `$CHROMIUM`, else Debian's `/usr/bin/chromium`.
pub fn chromium() -> Result<PathBuf, String> {
    let path = std::env::var_os("CHROMIUM").map_or_else(|| PathBuf::from("/usr/bin/chromium"), PathBuf::from);
    path.exists().then_some(path).ok_or_else(|| "no Chromium (/usr/bin/chromium, or set CHROMIUM)".into())
}
