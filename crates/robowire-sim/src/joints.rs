//! The joint model every simulated robot shares: per joint an inertia with viscous damping,
//! driven by a PD law with feed-forward torque and a torque limit (semi-implicit Euler).

/// Joint inertia, kg·m².
const INERTIA_KGM2: f32 = 0.02;
/// Viscous damping, N·m·s/rad.
const DAMPING_NMS: f32 = 0.05;
/// Motor torque limit, N·m.
pub(crate) const TORQUE_LIMIT_NM: f32 = 45.0;

/// What a joint is commanded: `tau = kp (q − q_des) + kd (qd − qd_des) + tau_ff`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct PdTarget {
    pub(crate) q_rad: f32,
    pub(crate) qd_radps: f32,
    pub(crate) kp: f32,
    pub(crate) kd: f32,
    pub(crate) tau_ff_nm: f32,
}

/// Positions, velocities and torques of 4 legs × 4 joints (abad, hip, knee, foot), `[leg][joint]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointModel {
    pub(crate) q_rad: [[f32; 4]; 4],
    pub(crate) qd_radps: [[f32; 4]; 4],
    pub(crate) tau_nm: [[f32; 4]; 4],
}

impl JointModel {
    /// Every leg at `pose` (abad, hip, knee; the foot at 0), at rest.
    pub(crate) fn at(pose: [f32; 3]) -> Self {
        let leg = [pose[0], pose[1], pose[2], 0.0];
        Self { q_rad: [leg; 4], qd_radps: [[0.0; 4]; 4], tau_nm: [[0.0; 4]; 4] }
    }

    /// One step of `dt` seconds, joint `(leg, joint)` commanded by `target(leg, joint)`.
    /// Non-finite commands give zero torque (a real drive rejects them).
    pub(crate) fn step(&mut self, dt: f32, target: impl Fn(usize, usize) -> PdTarget) {
        for leg in 0..4 {
            for joint in 0..4 {
                let c = target(leg, joint);
                let (q, qd) = (self.q_rad[leg][joint], self.qd_radps[leg][joint]);
                let torque = c.kp * (c.q_rad - q) + c.kd * (c.qd_radps - qd) + c.tau_ff_nm;
                let torque = if torque.is_finite() { torque.clamp(-TORQUE_LIMIT_NM, TORQUE_LIMIT_NM) } else { 0.0 };
                let acc = (torque - DAMPING_NMS * qd) / INERTIA_KGM2;
                let qd = qd + acc * dt;
                self.qd_radps[leg][joint] = qd;
                self.q_rad[leg][joint] = (q + qd * dt).clamp(-std::f32::consts::PI, std::f32::consts::PI);
                self.tau_nm[leg][joint] = torque;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pd_target_is_reached_and_nan_gives_no_torque() {
        let mut model = JointModel::at([0.0, 1.0, -2.0]);
        let hold = |q: f32| PdTarget { q_rad: q, kp: 80.0, kd: 1.0, ..PdTarget::default() };
        for _ in 0..1000 {
            model.step(0.002, |_, j| hold([0.1, 0.8, -1.5, 0.0][j]));
        }
        assert!((model.q_rad[2][1] - 0.8).abs() < 1e-3, "{:?}", model.q_rad);
        model.step(0.002, |_, _| hold(f32::NAN));
        assert!(model.tau_nm.iter().flatten().all(|&t| t == 0.0));
    }
}
