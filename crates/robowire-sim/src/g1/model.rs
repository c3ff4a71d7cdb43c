//! The G1's body without I/O: 29 joint slots on a [`Plant`] (the shared PD joint model, each
//! joint with its torque and range from [`unitree_proto::g1::JOINT_LIMITS`], or physics with the
//! `mujoco` feature), the robot's own controller
//! holding the stand pose with `rt/arm_sdk` blended in, `rt/lowcmd` once released, and the HG
//! `LowState` it reports.

use unitree_proto::g1::{
    self, ARM_SDK_JOINTS, ARM_SDK_WEIGHT_RATE_PER_S, G1Variant, Gains, ModePr, PARALLEL_PAIRS, ab_to_pr, pr_to_ab, slot,
};
use unitree_proto::{HgLowCmd, HgLowState, HgMotorCmd};

use crate::joints::{JointStops, Joints, PdTarget};
use crate::plant::{BaseReading, Plant, SlotJoints};
use crate::unitree::COMMAND_HOLD_S;

/// Joint slots of the G1 (0..29).
pub const JOINTS: usize = g1::JOINTS;

/// The pose the robot's controller holds: unitree_rl_gym's G1 default angles (per leg hip pitch
/// −0.1, knee 0.3, ankle pitch −0.2 rad; every other joint 0), by slot.
pub const STAND_POSE_RAD: [f32; JOINTS] = {
    let mut pose = [0.0; JOINTS];
    let mut leg = 0;
    while leg < 2 {
        pose[6 * leg] = -0.1;
        pose[6 * leg + 3] = 0.3;
        pose[6 * leg + 4] = -0.2;
        leg += 1;
    }
    pose
};

const fn gains(kp: f32, kd: f32) -> Gains {
    Gains { kp, kd }
}

/// The gains the robot's controller holds its pose with, by slot: unitree_rl_gym's G1 deploy
/// gains (legs 100/100/100/150/40/40, kd 2/2/2/4/2/2; waist 300, kd 3; per arm
/// 100/100/50/50/20/20/20, kd 2/2/2/2/1/1/1). robowire's choice: the robot's own are not public.
pub const CONTROLLER_GAINS: [Gains; JOINTS] = {
    const LEG: [Gains; 6] = [
        gains(100.0, 2.0),
        gains(100.0, 2.0),
        gains(100.0, 2.0),
        gains(150.0, 4.0),
        gains(40.0, 2.0),
        gains(40.0, 2.0),
    ];
    const ARM: [Gains; 7] = [
        gains(100.0, 2.0),
        gains(100.0, 2.0),
        gains(50.0, 2.0),
        gains(50.0, 2.0),
        gains(20.0, 1.0),
        gains(20.0, 1.0),
        gains(20.0, 1.0),
    ];
    let mut all = [gains(300.0, 3.0); JOINTS];
    let mut i = 0;
    while i < 6 {
        all[i] = LEG[i];
        all[6 + i] = LEG[i];
        i += 1;
    }
    let mut i = 0;
    while i < 7 {
        all[15 + i] = ARM[i];
        all[22 + i] = ARM[i];
        i += 1;
    }
    all
};

/// The motors' supply voltage the state reports, V (robowire's choice: a constant).
pub const SUPPLY_V: f32 = 48.0;

/// The joints' stops: each joint's torque and range.
const STOPS: [JointStops; JOINTS] = {
    let mut stops = [JointStops { tau_max_nm: 0.0, q_min_rad: 0.0, q_max_rad: 0.0 }; JOINTS];
    let mut j = 0;
    while j < JOINTS {
        let l = &g1::JOINT_LIMITS[j];
        stops[j] = JointStops { tau_max_nm: l.tau_max, q_min_rad: l.q_min, q_max_rad: l.q_max };
        j += 1;
    }
    stops
};

/// Where the pelvis starts above the floor in physics, m (hanging: where it is held).
#[cfg(feature = "mujoco")]
const PELVIS_HEIGHT_M: f64 = 0.95;

/// The leg joints: slots 0..12 (left hip pitch … right ankle roll).
const LEG_SLOTS: usize = 12;

/// How long a LowCmd stream drives every leg joint with stiffness before a held pelvis is let
/// go, s.
pub const LET_GO_AFTER_S: f32 = 3.5;

/// [`STAND_POSE_RAD`], the slots `variant` does not drive at 0.
fn start_pose(variant: G1Variant) -> [f32; JOINTS] {
    core::array::from_fn(|s| if variant.drives(s) { STAND_POSE_RAD[s] } else { 0.0 })
}

/// The body.
#[derive(Debug)]
pub struct G1Body {
    variant: G1Variant,
    mode_machine: u8,
    plant: Box<dyn Plant>,
    /// The robot's controller owns the motors.
    controller: bool,
    lowcmd: Option<HgLowCmd>,
    lowcmd_age_s: f32,
    /// How the last applied LowCmd addressed the parallel joints (what the state echoes).
    mode_pr: ModePr,
    arm_sdk: Option<HgLowCmd>,
    arm_sdk_age_s: f32,
    /// The onboard controller's latest command (the robot's own locomotion), and its age.
    gait: Option<HgLowCmd>,
    gait_age_s: f32,
    /// The weight `rt/arm_sdk` is blended in with, 0..=1.
    arm_weight: f32,
    /// Motors that failed: they report mode 0 and produce no torque.
    faulted: [bool; JOINTS],
    tick_ms: u32,
    /// How long the LowCmds have driven every leg joint, while the pelvis is held, s.
    driven_s: f32,
}

/// Whether a motor command sets any target, gain or torque.
fn commands_something(m: &HgMotorCmd) -> bool {
    [m.q, m.dq, m.tau, m.kp, m.kd].iter().any(|v| v.get() != 0.0)
}

/// Whether `cmd` has a motor that `variant` drives with `mode` 0 and a target, gain or torque
/// set: that motor exerts no torque, whatever the frame asks of it.
pub fn has_disabled_motor(cmd: &HgLowCmd, variant: G1Variant) -> bool {
    cmd.motor_cmd.iter().enumerate().any(|(slot, m)| variant.drives(slot) && m.mode == 0 && commands_something(m))
}

/// `values` by slot with each parallel pair's A/B motors (roll slot A, pitch slot B) mapped
/// to pitch and roll.
fn ab_values_to_pr(mut values: [f32; JOINTS]) -> [f32; JOINTS] {
    for (pitch, roll) in PARALLEL_PAIRS {
        (values[pitch], values[roll]) = ab_to_pr(values[roll], values[pitch]);
    }
    values
}

impl G1Body {
    /// Standing at [`STAND_POSE_RAD`] (the slots `variant` does not drive at 0), at rest, held
    /// by the robot's controller; the state says `mode_machine`. On the kinematic joint model.
    pub fn new(variant: G1Variant, mode_machine: u8) -> Self {
        Self::on(Box::new(SlotJoints::new(Joints::at(start_pose(variant), STOPS))), variant, mode_machine)
    }

    /// As [`G1Body::new`], in MuJoCo: robowire's model of the G1 or the user's MJCF of
    /// `options`. Hanging (`options.hanging`): its pelvis held where it starts for good. Free:
    /// it settles on the floor, standing, and its pelvis is held there as on Unitree's elastic
    /// band until a LowCmd stream has driven every leg joint with stiffness for
    /// [`LET_GO_AFTER_S`]; then it is let go (a real G1 hangs on its gantry until its controller
    /// runs).
    #[cfg(feature = "mujoco")]
    pub fn physics(
        variant: G1Variant,
        mode_machine: u8,
        options: &crate::physics::PhysicsOptions,
    ) -> Result<Self, crate::physics::PhysicsError> {
        let rig = crate::physics::Rig {
            robot: "G1",
            mjcf: include_str!("../../models/g1.xml"),
            joints: (0..JOINTS).map(|s| variant.drives(s).then_some(g1::JOINT_NAMES[s])).collect(),
            tau_max_nm: g1::JOINT_LIMITS.iter().map(|l| l.tau_max).collect(),
            start_pose_rad: start_pose(variant).to_vec(),
            base_height_m: PELVIS_HEIGHT_M,
            feet: vec![slot::LEFT_ANKLE_ROLL, slot::RIGHT_ANKLE_ROLL],
        };
        let mut physics = crate::physics::Physics::load(&rig, options)?;
        if !options.hanging {
            physics.settle(0.5);
            physics.hold_base();
        }
        Ok(Self::on(Box::new(physics), variant, mode_machine))
    }

    fn on(plant: Box<dyn Plant>, variant: G1Variant, mode_machine: u8) -> Self {
        Self {
            variant,
            mode_machine,
            plant,
            controller: true,
            lowcmd: None,
            lowcmd_age_s: 0.0,
            mode_pr: ModePr::Pr,
            arm_sdk: None,
            arm_sdk_age_s: 0.0,
            gait: None,
            gait_age_s: 0.0,
            arm_weight: 0.0,
            faulted: [false; JOINTS],
            tick_ms: 0,
            driven_s: 0.0,
        }
    }

    /// Whether the pelvis is held (a free body not yet let go).
    pub fn held(&self) -> bool {
        self.plant.held()
    }

    /// Whether the latest command of whoever owns the motors (a `rt/lowcmd` LowCmd once
    /// released, the onboard controller's while the controller owns them), fresh, drives every
    /// leg joint (slots 0..12) with stiffness.
    fn drives_legs(&self) -> bool {
        let fresh = match self.controller {
            false => self.lowcmd.as_ref().filter(|_| self.lowcmd_age_s <= COMMAND_HOLD_S),
            true => self.fresh_gait(),
        };
        fresh.is_some_and(|cmd| {
            cmd.motor_cmd[..LEG_SLOTS]
                .iter()
                .enumerate()
                .all(|(s, m)| !self.faulted[s] && m.mode == 1 && m.kp.get() > 0.0)
        })
    }

    /// Which G1 this is.
    pub fn variant(&self) -> G1Variant {
        self.variant
    }

    /// The robot's controller takes the motors (`true`: a mode was selected; the last LowCmd is
    /// forgotten) or lets them go (`false`: released; `rt/arm_sdk` is forgotten, its weight 0).
    pub fn set_controller(&mut self, owns: bool) {
        if owns && !self.controller {
            self.lowcmd = None;
            self.gait = None;
            self.mode_pr = ModePr::Pr;
        }
        if !owns {
            self.arm_sdk = None;
            self.arm_weight = 0.0;
        }
        self.controller = owns;
    }

    /// Whether the robot's controller owns the motors.
    pub fn controller_owns(&self) -> bool {
        self.controller
    }

    /// A `rt/lowcmd` LowCmd the robot accepted (its `mode_machine` checked): the motors with
    /// `mode` 1 follow it until it is [`COMMAND_HOLD_S`] old. Ignored while the controller owns
    /// the motors.
    pub fn command(&mut self, command: &HgLowCmd) {
        if self.controller {
            return;
        }
        self.lowcmd = Some(*command);
        self.lowcmd_age_s = 0.0;
        self.mode_pr = ModePr::from_byte(command.mode_pr).unwrap_or_default();
    }

    /// A `rt/arm_sdk` frame: while the controller owns the motors, the arm and waist joints
    /// follow `(1 − w)·controller + w·frame` (targets and gains), `w` its slot 29's `q` clamped
    /// to 0..=1. A frame older than [`COMMAND_HOLD_S`] still holds its targets while `w` decays
    /// to 0 at [`ARM_SDK_WEIGHT_RATE_PER_S`]: the controller takes the arms back, never at a
    /// jump. Ignored once released.
    pub fn arm_sdk(&mut self, command: &HgLowCmd) {
        if !self.controller {
            return;
        }
        let w = command.motor_cmd[slot::ARM_SDK_WEIGHT].q.get();
        self.arm_weight = if w.is_nan() { 0.0 } else { w.clamp(0.0, 1.0) };
        self.arm_sdk = Some(*command);
        self.arm_sdk_age_s = 0.0;
    }

    /// A command of the robot's own locomotion (an onboard controller, `mode_pr` PR): while the
    /// controller owns the motors, each motor with `mode` 1 follows it in place of the stand
    /// pose until it is [`COMMAND_HOLD_S`] old (`rt/arm_sdk` still blended in). Ignored once
    /// released.
    pub fn gait(&mut self, command: &HgLowCmd) {
        if !self.controller {
            return;
        }
        self.gait = Some(*command);
        self.gait_age_s = 0.0;
    }

    /// The onboard controller's command, if fresh.
    fn fresh_gait(&self) -> Option<&HgLowCmd> {
        self.gait.as_ref().filter(|_| self.gait_age_s <= COMMAND_HOLD_S)
    }

    /// The weight `rt/arm_sdk` is blended in with now, 0..=1.
    pub fn arm_sdk_weight(&self) -> f32 {
        self.arm_weight
    }

    /// Fault: motor `motor` fails (or recovers).
    pub fn set_motor_fault(&mut self, motor: usize, faulted: bool) {
        if let Some(f) = self.faulted.get_mut(motor) {
            *f = faulted;
        }
    }

    /// Joint positions, rad, by slot (pitch and roll for the parallel joints).
    pub fn joint_positions(&self) -> [f32; JOINTS] {
        core::array::from_fn(|s| self.plant.joint(s).q_rad)
    }

    /// The base (pelvis) when the body is simulated physics; `None` on the kinematic model.
    pub(crate) fn base(&self) -> Option<BaseReading> {
        self.plant.base()
    }

    /// Simulated time stepped so far, s.
    pub fn time_s(&self) -> f64 {
        self.plant.time_s()
    }

    /// What `rt/sportmodestate` says (physics only; Unitree's simulator publishes the Go2's
    /// message for the G1 too): the pelvis's place and the 2 feet's forces (left, right).
    pub fn sport_state(&self) -> Option<unitree_proto::sport_state::SportModeState> {
        crate::plant::sport_mode_state(&*self.plant, 2)
    }

    /// Advances the `tick` counter by `ms` (the state stream: its period per slot, skipped slots
    /// included).
    pub fn advance_tick(&mut self, ms: u32) {
        self.tick_ms = self.tick_ms.wrapping_add(ms);
    }

    /// What the controller commands slot `slot`, `rt/arm_sdk` blended in.
    fn controller_target(&self, slot: usize) -> PdTarget {
        let target = match self.fresh_gait().map(|cmd| &cmd.motor_cmd[slot]) {
            Some(m) if m.mode == 1 => PdTarget {
                q_rad: m.q.get(),
                qd_radps: m.dq.get(),
                kp: m.kp.get(),
                kd: m.kd.get(),
                tau_ff_nm: m.tau.get(),
            },
            _ => {
                let own = CONTROLLER_GAINS[slot];
                PdTarget { q_rad: STAND_POSE_RAD[slot], kp: own.kp, kd: own.kd, ..PdTarget::default() }
            }
        };
        let w = self.arm_weight;
        match &self.arm_sdk {
            Some(arm) if w > 0.0 && ARM_SDK_JOINTS.contains(&slot) => {
                let m = &arm.motor_cmd[slot];
                let blend = |own: f32, arm: f32| (1.0 - w) * own + w * arm;
                PdTarget {
                    q_rad: blend(target.q_rad, m.q.get()),
                    qd_radps: w * m.dq.get(),
                    kp: blend(target.kp, m.kp.get()),
                    kd: blend(target.kd, m.kd.get()),
                    tau_ff_nm: w * m.tau.get(),
                }
            }
            _ => target,
        }
    }

    /// What each slot is commanded now.
    fn targets(&self) -> [PdTarget; JOINTS] {
        let lowcmd = self.lowcmd.as_ref().filter(|_| !self.controller && self.lowcmd_age_s <= COMMAND_HOLD_S);
        let (q, dq) = match lowcmd {
            Some(cmd) => (
                g1::joint_targets(cmd),
                match self.mode_pr {
                    ModePr::Ab => ab_values_to_pr(core::array::from_fn(|s| cmd.motor_cmd[s].dq.get())),
                    ModePr::Pr => core::array::from_fn(|s| cmd.motor_cmd[s].dq.get()),
                },
            ),
            None => ([0.0; JOINTS], [0.0; JOINTS]),
        };
        core::array::from_fn(|slot| {
            if !self.variant.drives(slot) || self.faulted[slot] {
                return PdTarget::default();
            }
            if self.controller {
                return self.controller_target(slot);
            }
            match lowcmd.map(|cmd| &cmd.motor_cmd[slot]) {
                Some(m) if m.mode == 1 => PdTarget {
                    q_rad: q[slot],
                    qd_radps: dq[slot],
                    kp: m.kp.get(),
                    kd: m.kd.get(),
                    tau_ff_nm: m.tau.get(),
                },
                // Disabled (mode 0), stale or no command: passive.
                _ => PdTarget::default(),
            }
        })
    }

    /// Advances the body by `dt_s` seconds.
    pub fn step(&mut self, dt_s: f32) {
        self.lowcmd_age_s += dt_s;
        self.arm_sdk_age_s += dt_s;
        self.gait_age_s += dt_s;
        if self.arm_sdk_age_s > COMMAND_HOLD_S {
            self.arm_weight = (self.arm_weight - ARM_SDK_WEIGHT_RATE_PER_S * dt_s).max(0.0);
        }
        if self.plant.held() {
            self.driven_s = if self.drives_legs() { self.driven_s + dt_s } else { 0.0 };
            if self.driven_s >= LET_GO_AFTER_S {
                self.plant.let_go();
            }
        }
        let targets = self.targets();
        self.plant.step(dt_s, &targets);
    }

    /// The state the robot reports now (the CRC is written by the encoder). In AB mode (the
    /// last applied LowCmd's `mode_pr`) the parallel pairs are reported as their A and B motors
    /// ([`pr_to_ab`]: roll slot A, pitch slot B), as they are commanded.
    pub fn low_state(&self) -> HgLowState {
        let mut state = HgLowState::default();
        state.mode_pr = self.mode_pr as u8;
        state.mode_machine = self.mode_machine;
        state.tick = self.tick_ms.into();
        let base = self.plant.base().unwrap_or(BaseReading::at_rest(0.0));
        state.imu_state.quaternion = base.quaternion.map(Into::into);
        state.imu_state.gyroscope = base.gyro_radps.map(Into::into);
        state.imu_state.accelerometer = base.accelerometer_mps2.map(Into::into);
        state.imu_state.rpy = base.rpy_rad.map(Into::into);
        state.imu_state.temperature = 40.into();
        let joints: [_; JOINTS] = core::array::from_fn(|s| self.plant.joint(s));
        let (mut q, mut dq, mut tau) = (joints.map(|j| j.q_rad), joints.map(|j| j.qd_radps), joints.map(|j| j.tau_nm));
        if self.mode_pr == ModePr::Ab {
            for (pitch, roll) in PARALLEL_PAIRS {
                for v in [&mut q, &mut dq, &mut tau] {
                    let (a, b) = pr_to_ab(v[pitch], v[roll]);
                    (v[roll], v[pitch]) = (a, b);
                }
            }
        }
        for slot in (0..JOINTS).filter(|&s| self.variant.drives(s)) {
            let s = &mut state.motor_state[slot];
            let load = joints[slot].tau_nm.abs();
            s.mode = u8::from(!self.faulted[slot]);
            s.q = q[slot].into();
            s.dq = dq[slot].into();
            s.tau_est = tau[slot].into();
            s.temperature = [30 + (load / 3.0) as i16, 35 + (load / 2.0) as i16].map(Into::into);
            s.vol = SUPPLY_V.into();
            // robowire's choice: bit 0 on a failed motor (the bits' meanings are not public).
            s.motorstate = u32::from(self.faulted[slot]).into();
        }
        state
    }
}

#[cfg(test)]
mod tests;
