//! What the G1 tests share.

use std::time::Duration;

use unitree::g1::{JOINTS, JointCommand};

/// Generous: a condition not reached within this is a failure, not slowness.
pub(crate) const WAIT: Duration = Duration::from_secs(20);

/// A pattern for the 29 joints, each within its range, speed and torque: q 0.01·(i+1) rad,
/// dq 0.001·i rad/s, kp 40 + i, kd 1 + 0.05·i, tau 0.1·(i mod 3) N·m.
pub(crate) fn pattern() -> [JointCommand; JOINTS] {
    std::array::from_fn(|i| JointCommand {
        q_rad: 0.01 * (i + 1) as f32,
        dq_radps: 0.001 * i as f32,
        kp: 40.0 + i as f32,
        kd: 1.0 + 0.05 * i as f32,
        tau_nm: 0.1 * (i % 3) as f32,
    })
}
