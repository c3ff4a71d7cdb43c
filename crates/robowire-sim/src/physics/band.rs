//! Unitree's elastic band, in robowire's terms: the base held at a pose by a spring and a
//! damper on the free joint's six degrees of freedom, as generalized forces the caller applies
//! each step until it lets go.

use robowire_core::kinematics::multiply;

/// Stiffness, N/m.
const STIFFNESS: f64 = 1.0e4;
/// Stiffness, N·m/rad.
const STIFFNESS_ROT: f64 = 1.0e3;

/// The base's hold.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Band {
    /// Position (x, y, z) and orientation (w, x, y, z) held.
    pose: [f64; 7],
    /// Damping, N·s/m and N·m·s/rad.
    damping: [f64; 2],
}

impl Band {
    /// A hold at `pose` for a robot of `mass_kg` whose base alone weighs `base_kg` with a least
    /// principal inertia of `base_inertia_kgm2`, stepped every `dt_s`. The damping is critical
    /// for the whole robot but, applied explicitly, at most what the base alone takes stably in
    /// one step (half its mass or inertia per step).
    pub(super) fn at(pose: [f64; 7], mass_kg: f64, base_kg: f64, base_inertia_kgm2: f64, dt_s: f64) -> Self {
        let mass = mass_kg.max(1.0);
        let linear = (2.0 * (STIFFNESS * mass).sqrt()).min(0.5 * base_kg / dt_s);
        let angular = (2.0 * (STIFFNESS_ROT * mass * 0.05).sqrt()).min(0.5 * base_inertia_kgm2 / dt_s);
        Self { pose, damping: [linear, angular] }
    }

    /// The generalized forces on the free joint whose position is `qpos` (x, y, z, w, x, y, z)
    /// and velocity `qvel` (linear in the world frame, angular in the body's): a force in the
    /// world frame, then a torque in the body's.
    pub(super) fn forces(&self, qpos: &[f64; 7], qvel: &[f64; 6]) -> [f64; 6] {
        let [c_lin, c_rot] = self.damping;
        let mut out = [0.0; 6];
        for i in 0..3 {
            out[i] = -STIFFNESS * (qpos[i] - self.pose[i]) - c_lin * qvel[i];
        }
        // The body's turn from the held pose, in its own frame: held⁻¹ · now.
        let held = [self.pose[3], -self.pose[4], -self.pose[5], -self.pose[6]];
        let err = multiply(held, [qpos[3], qpos[4], qpos[5], qpos[6]]);
        let sign = if err[0] < 0.0 { -1.0 } else { 1.0 };
        for i in 0..3 {
            out[3 + i] = -STIFFNESS_ROT * 2.0 * sign * err[1 + i] - c_rot * qvel[3 + i];
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LEVEL: [f64; 7] = [0.0, 0.0, 0.8, 1.0, 0.0, 0.0, 0.0];

    #[test]
    fn at_the_pose_and_at_rest_nothing_pulls() {
        assert_eq!(Band::at(LEVEL, 35.0, 5.0, 0.05, 0.001).forces(&LEVEL, &[0.0; 6]), [0.0; 6]);
    }

    #[test]
    fn a_body_below_or_turned_is_pulled_back() {
        let band = Band::at(LEVEL, 35.0, 5.0, 0.05, 0.001);
        let low = [0.0, 0.0, 0.79, 1.0, 0.0, 0.0, 0.0];
        let f = band.forces(&low, &[0.0; 6]);
        assert!((f[2] - 100.0).abs() < 1e-9 && f[..2] == [0.0; 2] && f[3..] == [0.0; 3], "{f:?}");
        // Rolled 0.1 rad about x: a torque back about x.
        let (s, c) = (0.05f64.sin(), 0.05f64.cos());
        let f = band.forces(&[0.0, 0.0, 0.8, c, s, 0.0, 0.0], &[0.0; 6]);
        assert!((f[3] + STIFFNESS_ROT * 2.0 * s).abs() < 1e-9 && f[4].abs() < 1e-12 && f[5].abs() < 1e-12, "{f:?}");
        // Falling: damped.
        let f = band.forces(&LEVEL, &[0.0, 0.0, -1.0, 0.0, 0.0, 0.0]);
        assert!(f[2] > 0.0, "{f:?}");
    }

    #[test]
    fn the_damping_is_what_the_base_takes_stably_in_one_step() {
        // Turning at 1 rad/s: at most half the base's inertia per 1 ms step, 0.05 / 0.001 / 2.
        let f = Band::at(LEVEL, 35.0, 5.0, 0.05, 0.001).forces(&LEVEL, &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
        assert!((f[3] + 25.0).abs() < 1e-9, "{f:?}");
    }
}
