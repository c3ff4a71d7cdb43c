//! What moves a simulated Unitree robot's motors: the kinematic joint model (no body: each
//! joint an inertia on its own, the base at rest) or physics (feature `mujoco`: the whole
//! robot in MuJoCo, standing or falling on its floor). The robot's firmware model (which
//! command owns which motor, faults, the state's bookkeeping) is the same over either.

#[cfg(feature = "go2")]
use crate::joints::JointModel;
#[cfg(feature = "g1")]
use crate::joints::Joints;
use crate::joints::PdTarget;

/// One motor's joint now.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct JointReading {
    /// Position, rad.
    pub(crate) q_rad: f32,
    /// Velocity, rad/s.
    pub(crate) qd_radps: f32,
    /// Torque the motor exerts, N·m.
    pub(crate) tau_nm: f32,
}

/// The robot's base now, as its IMU and a motion-capture system would see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BaseReading {
    /// Orientation quaternion (w, x, y, z), base frame to world.
    pub(crate) quaternion: [f32; 4],
    /// Roll, pitch, yaw (ZYX), rad.
    pub(crate) rpy_rad: [f32; 3],
    /// Angular velocity in the base frame, rad/s.
    pub(crate) gyro_radps: [f32; 3],
    /// Specific force in the base frame (at rest: +9.81 up), m/s².
    pub(crate) accelerometer_mps2: [f32; 3],
    /// Position in the world (z up from the floor), m.
    pub(crate) position_m: [f32; 3],
    /// Velocity in the world, m/s.
    pub(crate) velocity_mps: [f32; 3],
}

impl BaseReading {
    /// Level, at rest, `height_m` above the floor.
    pub(crate) const fn at_rest(height_m: f32) -> Self {
        Self {
            quaternion: [1.0, 0.0, 0.0, 0.0],
            rpy_rad: [0.0; 3],
            gyro_radps: [0.0; 3],
            accelerometer_mps2: [0.0, 0.0, 9.81],
            position_m: [0.0, 0.0, height_m],
            velocity_mps: [0.0; 3],
        }
    }
}

/// The motors' joints and the base they move.
pub(crate) trait Plant: Send + std::fmt::Debug {
    /// Advances `dt_s` seconds, motor `m` commanded `targets[m]` (PD plus feed-forward, clamped
    /// to the motor's torque).
    fn step(&mut self, dt_s: f32, targets: &[PdTarget]);
    /// Motor `motor`'s joint (a motor the robot does not have reads 0).
    fn joint(&self, motor: usize) -> JointReading;
    /// The base; `None` (the default): the plant has no body (the kinematic model).
    fn base(&self) -> Option<BaseReading> {
        None
    }
    /// Contact force on foot `foot` (the plant's order of feet), N; `None` (the default): no
    /// body.
    fn foot_force_n(&self, _foot: usize) -> Option<f32> {
        None
    }
    /// Simulated time stepped so far, s.
    fn time_s(&self) -> f64;
    /// Whether the base is held (Unitree's elastic band); `false` (the default): it is not.
    fn held(&self) -> bool {
        false
    }
    /// Lets the base go (a plant that holds none ignores it).
    fn let_go(&mut self) {}
}

/// The Go2's 12 motors on the kinematic joint model: motor `m` is leg `m / 3`, joint `m % 3`.
#[cfg(feature = "go2")]
#[derive(Debug, Clone)]
pub(crate) struct LegJoints {
    pub(crate) joints: JointModel,
    time_s: f64,
}

#[cfg(feature = "go2")]
impl LegJoints {
    /// Motor `m` at `pose_rad[m]`, at rest.
    pub(crate) fn at(pose_rad: &[f32; 12]) -> Self {
        let mut joints = JointModel::at([pose_rad[0], pose_rad[1], pose_rad[2]]);
        for (motor, q) in pose_rad.iter().enumerate() {
            joints.q_rad[motor / 3][motor % 3] = *q;
        }
        Self { joints, time_s: 0.0 }
    }
}

#[cfg(feature = "go2")]
impl Plant for LegJoints {
    fn step(&mut self, dt_s: f32, targets: &[PdTarget]) {
        self.time_s += f64::from(dt_s);
        self.joints.step(dt_s, |leg, joint| match joint {
            0..3 => targets.get(leg * 3 + joint).copied().unwrap_or_default(),
            _ => PdTarget::default(),
        });
    }
    fn joint(&self, motor: usize) -> JointReading {
        let (leg, joint) = (motor / 3, motor % 3);
        if leg >= 4 {
            return JointReading::default();
        }
        let j = &self.joints;
        JointReading { q_rad: j.q_rad[leg][joint], qd_radps: j.qd_radps[leg][joint], tau_nm: j.tau_nm[leg][joint] }
    }
    fn time_s(&self) -> f64 {
        self.time_s
    }
}

/// `N` motors on the kinematic joint model, each with its own limits (the G1's slots).
#[cfg(feature = "g1")]
#[derive(Debug, Clone)]
pub(crate) struct SlotJoints<const N: usize> {
    joints: Joints<N>,
    time_s: f64,
}

#[cfg(feature = "g1")]
impl<const N: usize> SlotJoints<N> {
    pub(crate) fn new(joints: Joints<N>) -> Self {
        Self { joints, time_s: 0.0 }
    }
}

#[cfg(feature = "g1")]
impl<const N: usize> Plant for SlotJoints<N> {
    fn step(&mut self, dt_s: f32, targets: &[PdTarget]) {
        self.time_s += f64::from(dt_s);
        self.joints.step(dt_s, |j| targets.get(j).copied().unwrap_or_default());
    }
    fn joint(&self, motor: usize) -> JointReading {
        let j = &self.joints;
        match (j.q_rad.get(motor), j.qd_radps.get(motor), j.tau_nm.get(motor)) {
            (Some(&q_rad), Some(&qd_radps), Some(&tau_nm)) => JointReading { q_rad, qd_radps, tau_nm },
            _ => JointReading::default(),
        }
    }
    fn time_s(&self) -> f64 {
        self.time_s
    }
}

/// What `rt/sportmodestate` says of a plant with a body (`None` without): the time stamp
/// (simulated time), the IMU, the base's position, height (its z above the floor) and velocity
/// in the world, the yaw rate, and the contact force of its first `feet` feet (N, the rest 0).
/// `mode` 0 (idle) and everything the sport service plans (gait, path, obstacles) zero: no
/// sport service drives the simulated robot.
pub(crate) fn sport_mode_state(plant: &dyn Plant, feet: usize) -> Option<unitree_proto::sport_state::SportModeState> {
    let base = plant.base()?;
    let mut state = unitree_proto::sport_state::SportModeState::default();
    let t = plant.time_s();
    state.stamp.sec = (t.trunc() as i32).into();
    state.stamp.nanosec = ((t.fract() * 1e9) as u32).into();
    state.imu_state.quaternion = base.quaternion.map(Into::into);
    state.imu_state.gyroscope = base.gyro_radps.map(Into::into);
    state.imu_state.accelerometer = base.accelerometer_mps2.map(Into::into);
    state.imu_state.rpy = base.rpy_rad.map(Into::into);
    state.imu_state.temperature = 40;
    state.position = base.position_m.map(Into::into);
    state.body_height = base.position_m[2].into();
    state.velocity = base.velocity_mps.map(Into::into);
    state.yaw_speed = base.gyro_radps[2].into();
    for foot in 0..feet.min(4) {
        let force = plant.foot_force_n(foot).unwrap_or(0.0).clamp(0.0, f32::from(i16::MAX));
        state.foot_force[foot] = (force as i16).into();
    }
    Some(state)
}
