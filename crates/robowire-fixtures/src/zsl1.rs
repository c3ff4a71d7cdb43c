//! The ZSL-1 captures of `fixtures/zsl1/frames.json` and the vendor calls they were made with.

use std::path::PathBuf;

use serde_json::Value;
use zsl_proto::udp::MotorCommand;
use zsl_proto::zerocopy::little_endian::F32;

/// The capture file.
pub fn frames_path() -> PathBuf {
    crate::fixtures_dir().join("zsl1/frames.json")
}

/// The captures, in file order (each an object with `direction`, `api`, `hex`, `decoded`,
/// `note`).
pub fn frames() -> Result<Vec<Value>, String> {
    let path = frames_path();
    let text = std::fs::read_to_string(&path).map_err(|e| format!("reading {}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("parsing {}: {e}", path.display()))
}

/// The vendor call a capture's `api` text names: `HighLevel.move(0.5, -0.25, 1.5)` gives
/// `("move", [0.5, -0.25, 1.5, 0.0], 3)`; `nan` is NaN. `None` if the text names no call.
pub fn vendor_call(api: &str) -> Option<(&str, [f32; 4], usize)> {
    let call = api.split_once("HighLevel.").map(|(_, c)| c).or_else(|| api.split_once("LowLevel.").map(|(_, c)| c))?;
    let (name, rest) = call.split_once('(')?;
    let (inside, _) = rest.split_once(')')?;
    let mut args = [0.0f32; 4];
    let mut n = 0;
    if name != "sendMotorCmd" {
        for arg in inside.split(',').map(str::trim).filter(|a| !a.is_empty()) {
            *args.get_mut(n)? = if arg == "nan" { f32::NAN } else { arg.parse().ok()? };
            n += 1;
        }
    }
    Some((name, args, n))
}

/// The motor command of a fixture's `sendMotorCmd` call, built from the call's description.
pub fn motor_command(api: &str) -> Option<MotorCommand> {
    if api.contains("demo-like stand pose") {
        return Some(MotorCommand::pd_hold([[0.0; 4], [0.8; 4], [-1.5; 4]], [80.0; 3], [1.0; 3]));
    }
    if !api.contains("field k>=3 leg j = 10*(k+1)+j+0.5") {
        return None;
    }
    // Field k, leg j: positions 0.10 + 0.01 j, 1.00 + 0.01 j, -(1.00 + 0.01 j); the rest 10 (k + 1) + j + 0.5.
    let value = |k: usize, j: usize| -> f32 {
        match k {
            0 => [0.10, 0.11, 0.12, 0.13][j],
            1 => [1.00, 1.01, 1.02, 1.03][j],
            2 => [-1.00, -1.01, -1.02, -1.03][j],
            _ => 10.0 * (k as f32 + 1.0) + j as f32 + 0.5,
        }
    };
    let arrays = |base: usize| -> [[F32; 4]; 3] {
        core::array::from_fn(|i| core::array::from_fn(|j| F32::new(value(base + i, j))))
    };
    Some(MotorCommand { q_des: arrays(0), qd_des: arrays(3), kp: arrays(6), kd: arrays(9), tau_ff: arrays(12) })
}
