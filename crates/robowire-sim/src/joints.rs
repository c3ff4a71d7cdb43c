//! The joint model every simulated robot shares: per joint an inertia with viscous damping,
//! driven by a PD law with feed-forward torque, a torque limit and mechanical stops
//! (semi-implicit Euler). [`JointModel`] holds 4 legs × 4 joints (the Go2, the ZSL-1), with one
//! torque limit and stops at ±π; [`Joints`] holds any number, each with its own limits (the G1).

/// Joint inertia, kg·m².
const INERTIA_KGM2: f32 = 0.02;
/// Viscous damping, N·m·s/rad.
const DAMPING_NMS: f32 = 0.05;
/// Motor torque limit of the legged robots, N·m.
#[cfg(any(feature = "zsl", feature = "go2"))]
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

/// A joint's limits in the model: the motor's torque and the mechanical stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointStops {
    /// |torque| at most, N·m.
    pub(crate) tau_max_nm: f32,
    /// Lower stop, rad.
    pub(crate) q_min_rad: f32,
    /// Upper stop, rad.
    pub(crate) q_max_rad: f32,
}

/// The legged robots' joints: 45 N·m, stops at ±π.
#[cfg(any(feature = "zsl", feature = "go2"))]
const LEG_STOPS: JointStops =
    JointStops { tau_max_nm: TORQUE_LIMIT_NM, q_min_rad: -std::f32::consts::PI, q_max_rad: std::f32::consts::PI };

/// One joint at `q`, `qd`, commanded `c`, one step of `dt` seconds: its new position, velocity
/// and torque. Non-finite commands give zero torque (a real drive rejects them); at a stop the
/// joint stays there, its velocity into the stop gone.
fn step_joint(q: f32, qd: f32, c: PdTarget, stops: JointStops, dt: f32) -> (f32, f32, f32) {
    let torque = c.kp * (c.q_rad - q) + c.kd * (c.qd_radps - qd) + c.tau_ff_nm;
    let torque = if torque.is_finite() { torque.clamp(-stops.tau_max_nm, stops.tau_max_nm) } else { 0.0 };
    let acc = (torque - DAMPING_NMS * qd) / INERTIA_KGM2;
    let qd = qd + acc * dt;
    let moved = q + qd * dt;
    let q = moved.clamp(stops.q_min_rad, stops.q_max_rad);
    let qd = if q == moved { qd } else { 0.0 };
    (q, qd, torque)
}

/// Positions, velocities and torques of 4 legs × 4 joints (abad, hip, knee, foot), `[leg][joint]`.
#[cfg(any(feature = "zsl", feature = "go2"))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct JointModel {
    pub(crate) q_rad: [[f32; 4]; 4],
    pub(crate) qd_radps: [[f32; 4]; 4],
    pub(crate) tau_nm: [[f32; 4]; 4],
}

#[cfg(any(feature = "zsl", feature = "go2"))]
impl JointModel {
    /// Every leg at `pose` (abad, hip, knee; the foot at 0), at rest.
    pub(crate) fn at(pose: [f32; 3]) -> Self {
        let leg = [pose[0], pose[1], pose[2], 0.0];
        Self { q_rad: [leg; 4], qd_radps: [[0.0; 4]; 4], tau_nm: [[0.0; 4]; 4] }
    }

    /// One step of `dt` seconds, joint `(leg, joint)` commanded by `target(leg, joint)`.
    pub(crate) fn step(&mut self, dt: f32, target: impl Fn(usize, usize) -> PdTarget) {
        for leg in 0..4 {
            for joint in 0..4 {
                let (q, qd) = (self.q_rad[leg][joint], self.qd_radps[leg][joint]);
                let (q, qd, tau) = step_joint(q, qd, target(leg, joint), LEG_STOPS, dt);
                (self.q_rad[leg][joint], self.qd_radps[leg][joint], self.tau_nm[leg][joint]) = (q, qd, tau);
            }
        }
    }
}

/// Positions, velocities and torques of `N` joints, each with its own limits.
#[cfg(feature = "g1")]
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Joints<const N: usize> {
    pub(crate) q_rad: [f32; N],
    pub(crate) qd_radps: [f32; N],
    pub(crate) tau_nm: [f32; N],
    stops: [JointStops; N],
}

#[cfg(feature = "g1")]
impl<const N: usize> Joints<N> {
    /// At `q_rad` (each clamped to its stops), at rest.
    pub(crate) fn at(q_rad: [f32; N], stops: [JointStops; N]) -> Self {
        let q_rad = core::array::from_fn(|j| q_rad[j].clamp(stops[j].q_min_rad, stops[j].q_max_rad));
        Self { q_rad, qd_radps: [0.0; N], tau_nm: [0.0; N], stops }
    }

    /// One step of `dt` seconds, joint `j` commanded by `target(j)`.
    pub(crate) fn step(&mut self, dt: f32, target: impl Fn(usize) -> PdTarget) {
        for j in 0..N {
            (self.q_rad[j], self.qd_radps[j], self.tau_nm[j]) =
                step_joint(self.q_rad[j], self.qd_radps[j], target(j), self.stops[j], dt);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(any(feature = "zsl", feature = "go2"))]
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

    #[test]
    #[cfg(feature = "g1")]
    fn each_joint_has_its_own_torque_limit_and_stops() {
        let stops = [
            JointStops { tau_max_nm: 5.0, q_min_rad: -1.0, q_max_rad: 0.5 },
            JointStops { tau_max_nm: 50.0, q_min_rad: -1.0, q_max_rad: 1.0 },
        ];
        let mut joints = Joints::at([0.0, 3.0], stops);
        assert_eq!(joints.q_rad, [0.0, 1.0], "placed within the stops");
        let target = PdTarget { q_rad: 0.9, kp: 100.0, kd: 1.0, ..PdTarget::default() };
        joints.step(0.002, |_| target);
        assert_eq!(joints.tau_nm[0], 5.0, "limited to its own torque");
        for _ in 0..2000 {
            joints.step(0.002, |_| target);
        }
        assert_eq!(joints.q_rad[0], 0.5, "held at its upper stop");
        assert_eq!(joints.qd_radps[0], 0.0, "no velocity into the stop");
        assert!((joints.q_rad[1] - 0.9).abs() < 1e-3, "{:?}", joints.q_rad);
    }
}
