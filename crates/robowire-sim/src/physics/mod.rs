//! MuJoCo behind a simulated robot's motors (feature `mujoco`): the robot's MJCF model, each
//! motor mapped to the model's joint of the same name, driven at 1 kHz by the motor model
//! `tau = clamp(kp·(q_des − q) + kd·(dq_des − dq) + tau_ff, ±tau_max)` on the latest targets,
//! as Unitree's own simulator bridge and the robot's motor drivers do.
//!
//! robowire applies every motor torque itself, as a generalized force on the joint's degree of
//! freedom, with MuJoCo's actuators disabled: a model's own actuators (a user's MJCF from
//! unitree_mujoco or MuJoCo Menagerie has some) take no part, so every model is driven alike.
//! The model's timestep is set to 1 ms. The base is read from the model's first joint, which
//! must be free (a floating base): its position and velocity in the world, and an ideal IMU at
//! the base's origin (orientation, angular velocity and specific force in the base frame).
//! A foot's force is the sum of the normal forces of the contacts on the foot motor's body and
//! the bodies below it.

mod band;
#[cfg(test)]
mod kinematics_check;
mod rig;

use std::path::{Path, PathBuf};

use mujoco_rs::mujoco_c::{mjtDisableBit, mjtJoint};
use mujoco_rs::prelude::*;

use robowire_core::kinematics::rotate_into;

use crate::joints::PdTarget;
use crate::plant::{BaseReading, JointReading, Plant};

pub use rig::Rig;

/// The motor model's and MuJoCo's step, s.
pub const STEP_S: f64 = 0.001;

/// Which model a simulator loads.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PhysicsOptions {
    /// A user's MJCF file (a scene with a floor and the robot, e.g. unitree_mujoco's
    /// `scene.xml`); `None`: robowire's own model of the robot.
    pub model: Option<PathBuf>,
    /// The base hung where it starts (as on Unitree's elastic band or a gantry): held by a
    /// stiff spring with damping in position and orientation, so the joints move and carry
    /// their links' weight while the body does not fall.
    pub hanging: bool,
}

/// Why a model cannot drive the robot.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PhysicsError {
    /// MuJoCo did not load the file.
    #[error("cannot load the MJCF model {model}: {reason}")]
    Load {
        /// The file.
        model: String,
        /// MuJoCo's message.
        reason: String,
    },
    /// A motor's joint is not in the model.
    #[error(
        "the model {model} has no joint named {joint} (or {joint}_joint) for motor {motor} of rt/lowcmd; \
         robowire maps each motor to the joint of its name: {expected}"
    )]
    MissingJoint {
        /// The file (or `robowire's <robot>`).
        model: String,
        /// The motor's joint name.
        joint: &'static str,
        /// The motor's slot.
        motor: usize,
        /// Every joint name the robot's motors need, in motor order.
        expected: String,
    },
    /// A motor's joint is not a hinge.
    #[error("joint {joint} of the model {model} is not a hinge (a motor turns it)")]
    NotAHinge {
        /// The file.
        model: String,
        /// The joint.
        joint: String,
    },
    /// The model's first joint is not free.
    #[error("the model {model} has no floating base: its first joint must be a free joint on the robot's base")]
    NoFloatingBase {
        /// The file.
        model: String,
    },
}

/// A motor's joint in the model.
#[derive(Debug, Clone, Copy)]
struct Motor {
    qpos: usize,
    dof: usize,
    tau_max_nm: f64,
}

/// The robot in MuJoCo.
pub struct Physics {
    data: MjData<Box<MjModel>>,
    /// By motor slot; `None`: a slot the robot does not drive.
    motors: Vec<Option<Motor>>,
    /// The torque each motor exerted in the last step, N·m.
    tau_nm: Vec<f32>,
    /// The free joint's qpos and dof addresses.
    base_qpos: usize,
    base_dof: usize,
    /// By body id: the foot it belongs to.
    foot_of_body: Vec<Option<usize>>,
    feet: usize,
    /// Each foot's contact force after the last step, N.
    foot_force_n: [f32; 4],
    /// Time given but not yet stepped (less than one step), s.
    carry_s: f64,
    /// Time stepped since the robot was placed (its settling not counted), s.
    time_s: f64,
    /// The base held until [`Plant::let_go`].
    band: Option<band::Band>,
}

impl std::fmt::Debug for Physics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Physics").field("time_s", &self.time_s).finish_non_exhaustive()
    }
}

impl Physics {
    /// Loads the model `options` names (else `rig`'s own), maps the motors, and places the
    /// robot at `rig`'s start pose, its base `rig.base_height_m` above the floor.
    pub fn load(rig: &Rig, options: &PhysicsOptions) -> Result<Self, PhysicsError> {
        let (name, loaded) = match &options.model {
            Some(path) => (path.display().to_string(), load_file(path)),
            None => {
                (format!("robowire's {}", rig.robot), MjModel::from_xml_string(rig.mjcf).map_err(|e| e.to_string()))
            }
        };
        let mut model = loaded.map_err(|reason| PhysicsError::Load { model: name.clone(), reason })?;
        let opt = model.opt_mut();
        opt.timestep = STEP_S;
        opt.disableflags |= mjtDisableBit::mjDSBL_ACTUATION as i32;
        let (base_qpos, base_dof) = match model.jnt_type().first() {
            Some(&mjtJoint::mjJNT_FREE) => (model.jnt_qposadr()[0] as usize, model.jnt_dofadr()[0] as usize),
            _ => return Err(PhysicsError::NoFloatingBase { model: name }),
        };
        let mut motors = Vec::with_capacity(rig.joints.len());
        let mut foot_joints = Vec::new();
        for (motor, joint) in rig.joints.iter().enumerate() {
            let Some(joint) = joint else {
                motors.push(None);
                continue;
            };
            let id = model
                .name_to_id(MjtObjBase::mjOBJ_JOINT, joint)
                .or_else(|| model.name_to_id(MjtObjBase::mjOBJ_JOINT, &format!("{joint}_joint")))
                .ok_or_else(|| PhysicsError::MissingJoint {
                    model: name.clone(),
                    joint,
                    motor,
                    expected: rig.joints.iter().flatten().copied().collect::<Vec<_>>().join(", "),
                })?;
            if model.jnt_type()[id] != mjtJoint::mjJNT_HINGE {
                return Err(PhysicsError::NotAHinge { model: name, joint: (*joint).into() });
            }
            if rig.feet.contains(&motor) {
                foot_joints.push(model.jnt_bodyid()[id] as usize);
            }
            motors.push(Some(Motor {
                qpos: model.jnt_qposadr()[id] as usize,
                dof: model.jnt_dofadr()[id] as usize,
                tau_max_nm: f64::from(rig.tau_max_nm[motor]),
            }));
        }
        let parents: Vec<usize> = model.body_parentid().iter().map(|&p| p as usize).collect();
        let foot_of_body = (0..parents.len())
            .map(|mut body| {
                loop {
                    if let Some(foot) = foot_joints.iter().position(|&b| b == body) {
                        break Some(foot);
                    }
                    if body == 0 {
                        break None;
                    }
                    body = parents[body];
                }
            })
            .collect();
        let base_pose = [0.0, 0.0, rig.base_height_m, 1.0, 0.0, 0.0, 0.0];
        if options.hanging {
            hang(&mut model, base_pose, (base_qpos, base_dof));
        }
        let mut data = MjData::try_new(Box::new(model))
            .map_err(|e| PhysicsError::Load { model: name.clone(), reason: e.to_string() })?;
        {
            let qpos = data.qpos_mut();
            qpos[base_qpos..base_qpos + 7].copy_from_slice(&base_pose);
            for (motor, q) in motors.iter().zip(&rig.start_pose_rad) {
                if let Some(m) = motor {
                    qpos[m.qpos] = f64::from(*q);
                }
            }
        }
        data.forward();
        let feet = foot_joints.len();
        let tau_nm = vec![0.0; motors.len()];
        Ok(Self {
            data,
            motors,
            tau_nm,
            base_qpos,
            base_dof,
            foot_of_body,
            feet,
            foot_force_n: [0.0; 4],
            carry_s: 0.0,
            time_s: 0.0,
            band: None,
        })
    }

    /// Lets the body come to rest for `seconds` before the simulation's time starts, every
    /// motor holding its start angle under the stand gains of Unitree's examples (kp 60, kd 5):
    /// the base drops onto the floor with the legs in their pose.
    pub fn settle(&mut self, seconds: f64) {
        let targets: Vec<PdTarget> = self
            .motors
            .iter()
            .map(|m| match m {
                Some(m) => {
                    PdTarget { q_rad: self.data.qpos()[m.qpos] as f32, kp: 60.0, kd: 5.0, ..PdTarget::default() }
                }
                None => PdTarget::default(),
            })
            .collect();
        for _ in 0..(seconds / STEP_S).round() as u32 {
            self.step_once(&targets);
        }
        self.tau_nm.fill(0.0);
        self.data.set_time(0.0);
        self.data.forward();
    }

    /// Holds the base where it is, as on Unitree's elastic band, until [`Plant::let_go`].
    pub fn hold_base(&mut self) {
        let model = self.data.model();
        let base = model.jnt_bodyid()[0] as usize;
        let mass = model.body_subtreemass().get(base).copied().unwrap_or(30.0);
        let base_kg = model.body_mass().get(base).copied().unwrap_or(1.0);
        let inertia = model.body_inertia().get(base).map_or(0.01, |i| i.iter().copied().fold(f64::MAX, f64::min));
        let qpos = self.data.qpos();
        let mut pose = [0.0; 7];
        pose.copy_from_slice(&qpos[self.base_qpos..self.base_qpos + 7]);
        self.band = Some(band::Band::at(pose, mass, base_kg, inertia, STEP_S));
    }

    /// One 1 ms step, motor `m` commanded `targets[m]`.
    fn step_once(&mut self, targets: &[PdTarget]) {
        let (qpos, qvel) = (self.data.qpos(), self.data.qvel());
        for (slot, motor) in self.motors.iter().enumerate() {
            let (Some(m), Some(t)) = (motor, targets.get(slot)) else { continue };
            let torque = f64::from(t.kp) * (f64::from(t.q_rad) - qpos[m.qpos])
                + f64::from(t.kd) * (f64::from(t.qd_radps) - qvel[m.dof])
                + f64::from(t.tau_ff_nm);
            let torque = if torque.is_finite() { torque.clamp(-m.tau_max_nm, m.tau_max_nm) } else { 0.0 };
            self.tau_nm[slot] = torque as f32;
        }
        let held = self.band.as_ref().map(|band| {
            let (p, v) = (self.base_qpos, self.base_dof);
            let qpos: [f64; 7] = core::array::from_fn(|i| qpos[p + i]);
            let qvel: [f64; 6] = core::array::from_fn(|i| qvel[v + i]);
            band.forces(&qpos, &qvel)
        });
        let base_dof = self.base_dof;
        let applied = self.data.qfrc_applied_mut();
        applied[base_dof..base_dof + 6].copy_from_slice(&held.unwrap_or([0.0; 6]));
        for (motor, tau) in self.motors.iter().zip(&self.tau_nm) {
            if let Some(m) = motor {
                applied[m.dof] = f64::from(*tau);
            }
        }
        self.data.step();
    }

    /// Sum of the contacts' normal forces on each foot, N.
    fn foot_forces(&self) -> [f64; 4] {
        let mut forces = [0.0; 4];
        let geom_body = self.data.model().geom_bodyid();
        for (i, contact) in self.data.contact().iter().enumerate() {
            let foot = contact
                .geom
                .iter()
                .find_map(|&g| self.foot_of_body.get(*geom_body.get(g as usize)? as usize).copied().flatten());
            if let (Some(foot), Ok(f)) = (foot, self.data.try_contact_force(i))
                && let Some(total) = forces.get_mut(foot)
            {
                *total += f[0].abs();
            }
        }
        forces
    }
}

/// The hanging spring's stiffness, N/m and N·m/rad (a 35 kg robot hangs 3.4 cm low).
const HANG_STIFFNESS: f64 = 1.0e4;

/// Hangs the base at `pose`: the free joint (at `qpos`, `dof`) gets MuJoCo's passive spring to
/// `pose` and a damping near critical for the robot's mass (damping is integrated implicitly,
/// so a stiff hold stays stable at 1 ms).
fn hang(model: &mut MjModel, pose: [f64; 7], (qpos, dof): (usize, usize)) {
    let base = model.jnt_bodyid()[0] as usize;
    let mass = model.body_subtreemass().get(base).copied().unwrap_or(30.0).max(1.0);
    model.qpos_spring_mut()[qpos..qpos + 7].copy_from_slice(&pose);
    model.jnt_stiffness_mut()[0] = HANG_STIFFNESS;
    let damping = model.dof_damping_mut();
    damping[dof..dof + 3].fill(2.0 * (HANG_STIFFNESS * mass).sqrt());
    damping[dof + 3..dof + 6].fill(2.0 * (HANG_STIFFNESS * mass * 0.05).sqrt());
}

fn load_file(path: &Path) -> Result<MjModel, String> {
    if !path.is_file() {
        return Err("no such file".into());
    }
    MjModel::from_xml(path).map_err(|e| e.to_string())
}

impl Plant for Physics {
    fn step(&mut self, dt_s: f32, targets: &[PdTarget]) {
        self.carry_s += f64::from(dt_s);
        while self.carry_s >= STEP_S * 0.999 {
            self.step_once(targets);
            self.carry_s -= STEP_S;
            self.time_s += STEP_S;
        }
        self.foot_force_n = self.foot_forces().map(|f| f as f32);
    }

    fn joint(&self, motor: usize) -> JointReading {
        match self.motors.get(motor).copied().flatten() {
            Some(m) => JointReading {
                q_rad: self.data.qpos()[m.qpos] as f32,
                qd_radps: self.data.qvel()[m.dof] as f32,
                tau_nm: self.tau_nm[motor],
            },
            None => JointReading::default(),
        }
    }

    fn base(&self) -> Option<BaseReading> {
        let (qpos, qvel, qacc) = (self.data.qpos(), self.data.qvel(), self.data.qacc());
        let (p, v) = (self.base_qpos, self.base_dof);
        let quat = [qpos[p + 3], qpos[p + 4], qpos[p + 5], qpos[p + 6]];
        let gravity = self.data.model().opt().gravity;
        let specific_world = [qacc[v] - gravity[0], qacc[v + 1] - gravity[1], qacc[v + 2] - gravity[2]];
        let f = |a: [f64; 3]| a.map(|x| x as f32);
        Some(BaseReading {
            quaternion: quat.map(|x| x as f32),
            rpy_rad: f(rpy_of(quat)),
            // A free joint's angular velocity is in the body's frame already.
            gyro_radps: f([qvel[v + 3], qvel[v + 4], qvel[v + 5]]),
            accelerometer_mps2: f(rotate_into(quat, specific_world)),
            position_m: f([qpos[p], qpos[p + 1], qpos[p + 2]]),
            velocity_mps: f([qvel[v], qvel[v + 1], qvel[v + 2]]),
        })
    }

    fn foot_force_n(&self, foot: usize) -> Option<f32> {
        (foot < self.feet).then(|| self.foot_force_n.get(foot).copied().unwrap_or(0.0))
    }

    fn time_s(&self) -> f64 {
        self.time_s
    }

    fn held(&self) -> bool {
        self.band.is_some()
    }

    fn let_go(&mut self) {
        self.band = None;
    }
}

/// Roll, pitch, yaw (ZYX) of the quaternion (w, x, y, z), rad.
pub(crate) fn rpy_of(q: [f64; 4]) -> [f64; 3] {
    let [w, x, y, z] = q;
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    [roll, pitch, yaw]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_of_a_yaw_and_of_a_pitch() {
        let half = std::f64::consts::FRAC_PI_4; // a quarter turn: half angle π/4
        let yaw = rpy_of([half.cos(), 0.0, 0.0, half.sin()]);
        assert!((yaw[2] - std::f64::consts::FRAC_PI_2).abs() < 1e-12 && yaw[0].abs() < 1e-12, "{yaw:?}");
        let pitch = rpy_of([(0.1f64).cos(), 0.0, (0.1f64).sin(), 0.0]);
        assert!((pitch[1] - 0.2).abs() < 1e-12, "{pitch:?}");
    }

    #[test]
    fn a_yawed_body_sees_the_world_x_axis_turned() {
        let h = std::f64::consts::FRAC_PI_4; // a quarter turn about z
        let v = rotate_into([h.cos(), 0.0, 0.0, h.sin()], [1.0, 0.0, 9.81]);
        assert!((v[0]).abs() < 1e-12 && (v[1] + 1.0).abs() < 1e-12 && (v[2] - 9.81).abs() < 1e-12, "{v:?}");
    }
}
