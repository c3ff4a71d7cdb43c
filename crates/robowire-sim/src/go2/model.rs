//! The Go2's body, sans I/O: 12 motors on a [`Plant`] (the shared PD joint model, or physics
//! with the `mujoco` feature), driven by the latched `LowCmd`, and the `LowState` it reports
//! (IMU and foot forces from the physics, else at rest and from the calf torques; battery,
//! tick).
//!
//! The firmware's sentinels are modelled as torque terms that vanish with their gain: `PosStopF`
//! with kp 0 and `VelStopF` with kd 0 contribute nothing (a `VelStopF` with kd > 0 would be a
//! 16000 rad/s target: clamped to the torque limit, as a real drive would saturate).

use unitree_proto::{LowCmd, LowState};

use crate::joints::PdTarget;
use crate::plant::{BaseReading, LegJoints, Plant};
use crate::unitree::COMMAND_HOLD_S;

/// The pose Unitree's stand example starts from, per motor (hip, thigh, calf × FR, FL, RR, RL):
/// lying, rear hips turned out.
pub const LYING_POSE_RAD: [f32; 12] = [0.0, 1.36, -2.65, 0.0, 1.36, -2.65, -0.2, 1.36, -2.65, 0.2, 1.36, -2.65];
/// The stand pose of Unitree's examples, per leg (hip, thigh, calf).
pub const STAND_POSE_RAD: [f32; 3] = [0.0, 0.67, -1.3];
/// Motors driven on the Go2.
pub const JOINTS: usize = 12;

/// The body.
#[derive(Debug)]
pub struct Go2Body {
    plant: Box<dyn Plant>,
    command: Option<LowCmd>,
    command_age_s: f32,
    /// Motors that failed: they report mode 0, produce no torque, count lost frames.
    faulted: [bool; JOINTS],
    lost: [u32; JOINTS],
    tick_ms: u32,
}

impl Default for Go2Body {
    fn default() -> Self {
        Self::new()
    }
}

impl Go2Body {
    /// Lying, at rest, motors passive, on the kinematic joint model.
    pub fn new() -> Self {
        Self::on(Box::new(LegJoints::at(&LYING_POSE_RAD)))
    }

    /// Lying on its floor in MuJoCo, motors passive: robowire's model of the Go2 or the user's
    /// MJCF of `options`.
    #[cfg(feature = "mujoco")]
    pub fn physics(options: &crate::physics::PhysicsOptions) -> Result<Self, crate::physics::PhysicsError> {
        let mut physics = crate::physics::Physics::load(&physics_rig(), options)?;
        if !options.hanging {
            physics.settle(1.0);
        }
        Ok(Self::on(Box::new(physics)))
    }

    fn on(plant: Box<dyn Plant>) -> Self {
        Self { plant, command: None, command_age_s: 0.0, faulted: [false; JOINTS], lost: [0; JOINTS], tick_ms: 0 }
    }

    /// A LowCmd the robot accepted: the motors follow it.
    pub fn command(&mut self, command: &LowCmd) {
        self.command = Some(*command);
        self.command_age_s = 0.0;
    }

    /// Fault: motor `motor` fails (or recovers).
    pub fn set_motor_fault(&mut self, motor: usize, faulted: bool) {
        if let Some(f) = self.faulted.get_mut(motor) {
            *f = faulted;
        }
    }

    /// Joint positions, rad, in motor order.
    pub fn joint_positions(&self) -> [f32; JOINTS] {
        core::array::from_fn(|m| self.plant.joint(m).q_rad)
    }

    /// The base (position, velocity, orientation) when the body is simulated physics; `None`
    /// on the kinematic joint model.
    pub(crate) fn base(&self) -> Option<BaseReading> {
        self.plant.base()
    }

    /// Simulated time stepped so far, s.
    pub fn time_s(&self) -> f64 {
        self.plant.time_s()
    }

    /// What `rt/sportmodestate` says (physics only): the base's place and the 4 feet's forces.
    pub fn sport_state(&self) -> Option<unitree_proto::sport_state::SportModeState> {
        crate::plant::sport_mode_state(&*self.plant, 4)
    }

    /// Advances the `tick` counter by `ms` (the state stream: its period per slot, skipped slots
    /// included, so that a receiver sees a fixed step and counts what it missed).
    pub fn advance_tick(&mut self, ms: u32) {
        self.tick_ms = self.tick_ms.wrapping_add(ms);
    }

    /// Advances the body by `dt_s` seconds.
    pub fn step(&mut self, dt_s: f32) {
        self.command_age_s += dt_s;
        let active = self.command.filter(|_| self.command_age_s <= COMMAND_HOLD_S);
        let targets: [PdTarget; JOINTS] = core::array::from_fn(|motor| match active {
            Some(cmd) if !self.faulted[motor] => {
                let m = &cmd.motor_cmd[motor];
                let (kp, kd) = (m.kp.get(), m.kd.get());
                PdTarget {
                    // A term without its gain contributes nothing, sentinel or not.
                    q_rad: if kp == 0.0 { 0.0 } else { m.q.get() },
                    qd_radps: if kd == 0.0 { 0.0 } else { m.dq.get() },
                    kp,
                    kd,
                    tau_ff_nm: m.tau.get(),
                }
            }
            _ => PdTarget::default(),
        });
        self.plant.step(dt_s, &targets);
        for (motor, faulted) in self.faulted.iter().enumerate() {
            if *faulted {
                self.lost[motor] = self.lost[motor].wrapping_add(1);
            }
        }
    }

    /// Each foot's force (FR, FL, RR, RL) as the state reports it: with physics the contact
    /// force in N, else the calf's load in the robot's raw units (about 10 per N·m).
    pub fn foot_forces(&self) -> [i16; 4] {
        core::array::from_fn(|leg| {
            let force = match self.plant.foot_force_n(leg) {
                Some(newtons) => newtons,
                None => self.plant.joint(leg * 3 + 2).tau_nm.abs() * 10.0,
            };
            force.clamp(0.0, f32::from(i16::MAX)) as i16
        })
    }

    /// The state the robot reports now (the CRC is written by the encoder).
    pub fn low_state(&self) -> LowState {
        let mut state = LowState::default();
        state.head = unitree_proto::go2::HEAD;
        let base = self.plant.base().unwrap_or(BaseReading::at_rest(0.0));
        state.imu_state.quaternion = base.quaternion.map(Into::into);
        state.imu_state.gyroscope = base.gyro_radps.map(Into::into);
        state.imu_state.accelerometer = base.accelerometer_mps2.map(Into::into);
        state.imu_state.rpy = base.rpy_rad.map(Into::into);
        state.imu_state.temperature = 40;
        let mut total_torque = 0.0;
        for motor in 0..JOINTS {
            let joint = self.plant.joint(motor);
            let s = &mut state.motor_state[motor];
            s.mode = u8::from(!self.faulted[motor]);
            s.q = joint.q_rad.into();
            s.dq = joint.qd_radps.into();
            s.tau_est = joint.tau_nm.into();
            s.q_raw = s.q;
            s.dq_raw = s.dq;
            s.temperature = 30 + (joint.tau_nm.abs() / 3.0) as u8;
            s.lost = self.lost[motor].into();
            total_torque += joint.tau_nm.abs();
        }
        for (leg, force) in self.foot_forces().into_iter().enumerate() {
            state.foot_force[leg] = force.into();
            state.foot_force_est[leg] = force.into();
        }
        state.bms_state.soc = 90;
        state.bms_state.current = (-2000 - (total_torque * 50.0) as i32).into();
        state.bms_state.cell_vol = [3600u16; 15].map(Into::into);
        state.power_v = 28.8.into();
        state.power_a = (2.0 + total_torque * 0.05).into();
        state.tick = self.tick_ms.into();
        // robowire's simulator only: the last accepted LowCmd's `reserve` word, echoed, so that a
        // client can match a state to a command (round trips). A real Go2 leaves it 0.
        state.reserve = self.command.map_or(0, |c| c.reserve.get()).into();
        state
    }
}

/// The Go2 as the physics drives it: its motors' joints by Unitree's names (`FR_hip`, matched as
/// `FR_hip_joint` too), torques from [`unitree_proto::robot::GO2_JOINT_LIMITS`], lying at the
/// start, the calves' bodies its feet.
#[cfg(feature = "mujoco")]
fn physics_rig() -> crate::physics::Rig {
    use unitree_proto::robot::{GO2_JOINT_LIMITS, GO2_JOINT_NAMES};
    crate::physics::Rig {
        robot: "Go2",
        mjcf: include_str!("../../models/go2.xml"),
        joints: GO2_JOINT_NAMES.iter().map(|&name| Some(name)).collect(),
        tau_max_nm: GO2_JOINT_LIMITS.iter().map(|l| l.tau_max).collect(),
        start_pose_rad: LYING_POSE_RAD.to_vec(),
        base_height_m: 0.2,
        feet: vec![2, 5, 8, 11],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use unitree_proto::go2::MotorCmd;

    fn stand() -> LowCmd {
        let mut cmd = LowCmd::default();
        for (motor, m) in cmd.motor_cmd.iter_mut().take(JOINTS).enumerate() {
            *m = MotorCmd::servo(STAND_POSE_RAD[motor % 3], 0.0, 60.0, 5.0, 0.0);
        }
        cmd
    }

    #[test]
    fn the_stand_command_stands_and_damping_stops_the_joints() {
        let mut body = Go2Body::new();
        assert_eq!(body.joint_positions(), LYING_POSE_RAD);
        for _ in 0..1000 {
            body.command(&stand());
            body.step(0.002);
            body.advance_tick(2);
        }
        let q = body.joint_positions();
        assert!(q.iter().enumerate().all(|(m, q)| (q - STAND_POSE_RAD[m % 3]).abs() < 0.01), "{q:?}");
        let state = body.low_state();
        assert_eq!(state.tick.get(), 2000);
        assert_eq!(state.motor_state[2].mode, 1);
        // The vendor's "hold nothing" command (PosStopF, VelStopF, no gains) exerts no torque.
        body.command(&LowCmd::default());
        body.step(0.002);
        assert!(body.low_state().motor_state[..JOINTS].iter().all(|m| m.tau_est.get() == 0.0));
        body.set_motor_fault(4, true);
        body.step(0.002);
        let state = body.low_state();
        assert_eq!((state.motor_state[4].mode, state.motor_state[4].lost.get()), (0, 1));
    }
}
