//! MuJoCo for the simulators' physics (robowire-sim's feature `mujoco`): `cargo xtask mujoco`
//! puts MuJoCo 3.17.0's `libmujoco.so`, from the PyPI wheel `mujoco==3.17.0` (fetched with
//! pip, nothing else downloaded), into `target/mujoco/lib`; `cargo xtask test` then runs the
//! physics tests, built with the feature against that library (or the one
//! `MUJOCO_DYNAMIC_LINK_DIR` names). Without it they are skipped with a line, or failed under
//! `ROBOWIRE_INTEROP=1`, as the interop tests are.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use robowire_fixtures::interop;

/// The MuJoCo release mujoco-rs 7.0.0 binds.
pub const MUJOCO_VERSION: &str = "3.17.0";

/// The library's directory in the target directory.
fn own_dir(target: &Path) -> PathBuf {
    target.join("mujoco").join("lib")
}

/// The directory holding `libmujoco.so`: `$MUJOCO_DYNAMIC_LINK_DIR`, else `target/mujoco/lib`.
pub fn lib_dir(target: &Path) -> Result<PathBuf, String> {
    let dir = match std::env::var_os("MUJOCO_DYNAMIC_LINK_DIR") {
        Some(dir) => PathBuf::from(dir),
        None => own_dir(target),
    };
    if dir.join("libmujoco.so").is_file() {
        Ok(dir)
    } else {
        Err(format!(
            "no libmujoco.so in {} (`cargo xtask mujoco` fetches MuJoCo {MUJOCO_VERSION} there from PyPI)",
            dir.display()
        ))
    }
}

/// Fetches the `mujoco==3.17.0` wheel with `python`'s pip and unpacks its `libmujoco.so.3.17.0`
/// into `target/mujoco/lib` beside a `libmujoco.so` link; the directory.
pub fn fetch(python: &Path, target: &Path) -> anyhow::Result<PathBuf> {
    let dir = own_dir(target);
    let library = format!("libmujoco.so.{MUJOCO_VERSION}");
    if dir.join(&library).is_file() && dir.join("libmujoco.so").is_file() {
        return Ok(dir);
    }
    let wheels = target.join("mujoco").join("wheel");
    let spec = format!("mujoco=={MUJOCO_VERSION}");
    let status = Command::new(python)
        .args(["-m", "pip", "--disable-pip-version-check", "-q", "download", "--no-deps", "--only-binary=:all:"])
        .arg("-d")
        .arg(&wheels)
        .arg(&spec)
        .status()
        .with_context(|| format!("cannot start {} -m pip", python.display()))?;
    if !status.success() {
        bail!("pip download {spec} failed ({status})");
    }
    std::fs::create_dir_all(&dir)?;
    // The wheel is a zip: Python's zipfile takes the library out.
    let unpack = "import glob, shutil, sys, zipfile\n\
                  wheel = sorted(glob.glob(sys.argv[1] + '/mujoco-*.whl'))[-1]\n\
                  with zipfile.ZipFile(wheel) as z, z.open('mujoco/' + sys.argv[3]) as src, \
                  open(sys.argv[2] + '/' + sys.argv[3], 'wb') as dst:\n    shutil.copyfileobj(src, dst)";
    let status = Command::new(python).arg("-c").arg(unpack).arg(&wheels).arg(&dir).arg(&library).status()?;
    if !status.success() {
        bail!("unpacking {library} from the {spec} wheel failed ({status})");
    }
    let link = dir.join("libmujoco.so");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&library, &link).with_context(|| format!("linking {}", link.display()))?;
    Ok(dir)
}

/// The physics tests: robowire-sim's, robowire-devices' (`sim:go2` and `sim:g1` by address) and
/// the CLI's (Unitree's examples against the physics simulators) and the conformance tests'
/// physics half, with the feature `mujoco`.
pub fn test(root: &Path, target: &Path) -> anyhow::Result<()> {
    let dir = match lib_dir(target) {
        Ok(dir) => dir,
        Err(missing) => {
            interop::missing("the physics tests (MuJoCo)", missing).map_err(anyhow::Error::msg)?;
            return Ok(());
        }
    };
    let loader_path = match std::env::var_os("LD_LIBRARY_PATH") {
        Some(paths) => {
            let mut all = vec![dir.clone()];
            all.extend(std::env::split_paths(&paths));
            std::env::join_paths(all)?
        }
        None => dir.clone().into_os_string(),
    };
    let runs: [&[&str]; 3] = [
        &[
            "test",
            "-p",
            "robowire-sim",
            "--features",
            "mujoco",
            "--lib",
            "--test",
            "it",
            "--",
            "physics::",
            "unitree_conformance::",
        ],
        &["test", "-p", "robowire-devices", "--features", "mujoco", "--test", "it", "--", "physics::"],
        &["test", "-p", "robowire", "--features", "mujoco", "--test", "physics"],
    ];
    for args in runs {
        let status = Command::new("cargo")
            .args(args)
            .current_dir(root)
            .env("MUJOCO_DYNAMIC_LINK_DIR", &dir)
            .env("LD_LIBRARY_PATH", &loader_path)
            .status()
            .context("cannot start cargo")?;
        if !status.success() {
            bail!("cargo {} failed ({status})", args.join(" "));
        }
    }
    Ok(())
}

/// `cargo xtask mujoco`: fetches the library and prints the exports that build and run with it.
pub fn run() -> anyhow::Result<()> {
    let root = crate::workspace_root();
    let dir = fetch(Path::new("python3"), &crate::python::target_dir(&root))?;
    let dir = dir.canonicalize()?;
    eprintln!("MuJoCo {} in {}; for physics (`--features mujoco`):", MUJOCO_VERSION, dir.display());
    // The exports alone on stdout, for `eval "$(cargo xtask mujoco)"`.
    println!(
        "export MUJOCO_DYNAMIC_LINK_DIR={0} LD_LIBRARY_PATH={0}${{LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}}",
        dir.display()
    );
    Ok(())
}
