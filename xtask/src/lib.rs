//! robowire project automation, as a library so that its checks also run under `cargo test`.

#![forbid(unsafe_code)]

pub mod architecture;
pub mod bench;
#[cfg(feature = "full")]
pub mod fuzz;
pub mod golden;
pub mod mujoco;
pub mod python;
#[cfg(feature = "full")]
pub mod test;

use std::path::PathBuf;

use anyhow::{Context, bail};

/// Runs this command again in xtask built with the feature `full` (the tasks that link DDS and
/// MCAP), so that `cargo xtask golden` and `mujoco` build neither; its exit status is ours.
#[cfg(not(feature = "full"))]
pub fn with_full() -> anyhow::Result<()> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = std::process::Command::new(cargo);
    command.args(["run", "--quiet", "--package", "xtask", "--features", "full", "--"]);
    command.args(std::env::args_os().skip(1)).current_dir(workspace_root());
    let status = command.status().context("cannot run cargo for the xtask with feature `full`")?;
    // It printed its own error: leave with its code, adding nothing.
    if !status.success() {
        std::process::exit(status.code().unwrap_or(1));
    }
    Ok(())
}

/// The workspace root (the parent of `xtask/`).
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).parent().map(PathBuf::from).unwrap_or_default()
}

/// Bytes from lowercase or uppercase hex without separators.
pub fn hex_decode(text: &str) -> anyhow::Result<Vec<u8>> {
    if !text.len().is_multiple_of(2) {
        bail!("odd number of hex digits in {text:?}");
    }
    (0..text.len())
        .step_by(2)
        .map(|i| {
            let pair = text.get(i..i + 2).context("non-ASCII hex")?;
            u8::from_str_radix(pair, 16).with_context(|| format!("{pair:?} is not hex"))
        })
        .collect()
}

/// Lowercase hex without separators.
pub fn hex_encode(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
