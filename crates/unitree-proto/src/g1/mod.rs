//! The Unitree G1 humanoid on the HG messages: its joints by slot, their limits, the example
//! gains, what `mode_machine` and `mode_pr` mean, `rt/arm_sdk`, and the rules a command must
//! meet before it is sent ([`check_low_cmd`], [`check_arm_sdk`]). Pure functions; the stream
//! that sends the commands is [`CommandStream<Hg>`](crate::stream::CommandStream).
//!
//! Sources: Unitree's SDKs (`unitree_sdk2`, `unitree_sdk2_python`: joint enums, examples),
//! `unitree_ros`' `g1_29dof_rev_1_0` URDF (ranges, speeds, torques) and `unitree_mujoco`'s
//! `g1_29dof.xml`. Where they disagree on a torque (hip roll 88 or 139 N·m; ankle and waist
//! roll/pitch 50 or 35 N·m) the table keeps the smaller.
//!
//! ```
//! use unitree_proto::g1::{self, G1Variant};
//! use unitree_proto::HgLowCmd;
//!
//! // The robot said mode_machine 5 (a 29-dof G1) in its LowState.
//! let variant = G1Variant::of_mode_machine(5).unwrap();
//! let mut cmd = g1::hold(&[0.0; g1::JOINTS], 5, variant);
//! assert_eq!(g1::check_low_cmd(&cmd, Some(5), variant), Ok(()));
//! cmd.mode_machine = 6;
//! assert!(g1::check_low_cmd(&cmd, Some(5), variant).is_err(), "the robot ignores it");
//! assert!(g1::check_low_cmd(&HgLowCmd::default(), None, variant).is_err(), "no LowState yet");
//! ```

// The tables' decimal literals are the URDF's (rounded π fractions).
#![allow(clippy::approx_constant)]

use crate::hg::{HG_MOTOR_COUNT, HgLowCmd, HgMotorCmd};
use crate::robot::{JointLimits, KD_MAX, KP_MAX};

pub mod arm_stream;
mod check;

pub use check::{check_arm_sdk, check_low_cmd};

/// Joint slots of the G1 (0..29); slots 29..35 drive nothing.
pub const JOINTS: usize = 29;

/// The G1's joints by slot, as its URDF and MJCF name them (`joint_states` names).
pub const JOINT_NAMES: [&str; JOINTS] = [
    "left_hip_pitch_joint",
    "left_hip_roll_joint",
    "left_hip_yaw_joint",
    "left_knee_joint",
    "left_ankle_pitch_joint",
    "left_ankle_roll_joint",
    "right_hip_pitch_joint",
    "right_hip_roll_joint",
    "right_hip_yaw_joint",
    "right_knee_joint",
    "right_ankle_pitch_joint",
    "right_ankle_roll_joint",
    "waist_yaw_joint",
    "waist_roll_joint",
    "waist_pitch_joint",
    "left_shoulder_pitch_joint",
    "left_shoulder_roll_joint",
    "left_shoulder_yaw_joint",
    "left_elbow_joint",
    "left_wrist_roll_joint",
    "left_wrist_pitch_joint",
    "left_wrist_yaw_joint",
    "right_shoulder_pitch_joint",
    "right_shoulder_roll_joint",
    "right_shoulder_yaw_joint",
    "right_elbow_joint",
    "right_wrist_roll_joint",
    "right_wrist_pitch_joint",
    "right_wrist_yaw_joint",
];

/// Slots by name (Unitree's `G1JointIndex`).
pub mod slot {
    /// Left hip pitch.
    pub const LEFT_HIP_PITCH: usize = 0;
    /// Left knee.
    pub const LEFT_KNEE: usize = 3;
    /// Left ankle pitch (PR mode) or its B motor (AB mode).
    pub const LEFT_ANKLE_PITCH: usize = 4;
    /// Left ankle roll (PR mode) or its A motor (AB mode).
    pub const LEFT_ANKLE_ROLL: usize = 5;
    /// Right hip pitch.
    pub const RIGHT_HIP_PITCH: usize = 6;
    /// Right knee.
    pub const RIGHT_KNEE: usize = 9;
    /// Right ankle pitch (PR) or B (AB).
    pub const RIGHT_ANKLE_PITCH: usize = 10;
    /// Right ankle roll (PR) or A (AB).
    pub const RIGHT_ANKLE_ROLL: usize = 11;
    /// Waist yaw.
    pub const WAIST_YAW: usize = 12;
    /// Waist roll (PR) or A (AB).
    pub const WAIST_ROLL: usize = 13;
    /// Waist pitch (PR) or B (AB).
    pub const WAIST_PITCH: usize = 14;
    /// Left shoulder pitch.
    pub const LEFT_SHOULDER_PITCH: usize = 15;
    /// Left shoulder roll.
    pub const LEFT_SHOULDER_ROLL: usize = 16;
    /// Left elbow.
    pub const LEFT_ELBOW: usize = 18;
    /// Left wrist roll.
    pub const LEFT_WRIST_ROLL: usize = 19;
    /// Right shoulder pitch.
    pub const RIGHT_SHOULDER_PITCH: usize = 22;
    /// Right shoulder roll.
    pub const RIGHT_SHOULDER_ROLL: usize = 23;
    /// Right elbow.
    pub const RIGHT_ELBOW: usize = 25;
    /// Right wrist roll.
    pub const RIGHT_WRIST_ROLL: usize = 26;
    /// In `rt/arm_sdk`: `q` is the weight of the arm command (0..=1). In `rt/lowcmd`: unused.
    pub const ARM_SDK_WEIGHT: usize = 29;
}

/// The topic of the arm command blended with the robot's own controller.
pub const ARM_SDK_TOPIC: &str = "rt/arm_sdk";

/// The joints `rt/arm_sdk` drives: both arms (15..29), then the waist (12, 13, 14).
pub const ARM_SDK_JOINTS: [usize; 17] = [15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 12, 13, 14];

/// Unitree's arm examples stream `rt/arm_sdk` every 20 ms (50 Hz).
pub const ARM_SDK_PERIOD: core::time::Duration = core::time::Duration::from_millis(20);

/// The fastest change of the `rt/arm_sdk` weight robowire sends, per second (0 → 1 in 2 s;
/// Unitree's teleoperation ramps at 0.5/s, its C++ arm example at 0.2/s).
pub const ARM_SDK_WEIGHT_RATE_PER_S: f32 = 0.5;

// Ranges and speeds: the `g1_29dof_rev_1_0` URDF (the same ranges as `g1_29dof.xml`), its decimal
// literals as written there (rounded π fractions, not π fractions).
const fn limits(q_min: f32, q_max: f32, dq_max: f32, tau_max: f32) -> JointLimits {
    JointLimits { q_min, q_max, dq_max, tau_max }
}
const HIP_PITCH: JointLimits = limits(-2.5307, 2.8798, 32.0, 88.0);
const L_HIP_ROLL: JointLimits = limits(-0.5236, 2.9671, 20.0, 88.0);
const R_HIP_ROLL: JointLimits = limits(-2.9671, 0.5236, 20.0, 88.0);
const HIP_YAW: JointLimits = limits(-2.7576, 2.7576, 32.0, 88.0);
const KNEE: JointLimits = limits(-0.087267, 2.8798, 20.0, 139.0);
const ANKLE_PITCH: JointLimits = limits(-0.87267, 0.5236, 30.0, 35.0);
const ANKLE_ROLL: JointLimits = limits(-0.2618, 0.2618, 30.0, 35.0);
const WAIST_YAW: JointLimits = limits(-2.618, 2.618, 32.0, 88.0);
const WAIST_ROLL_PITCH: JointLimits = limits(-0.52, 0.52, 30.0, 35.0);
const SHOULDER_PITCH: JointLimits = limits(-3.0892, 2.6704, 37.0, 25.0);
const L_SHOULDER_ROLL: JointLimits = limits(-1.5882, 2.2515, 37.0, 25.0);
const R_SHOULDER_ROLL: JointLimits = limits(-2.2515, 1.5882, 37.0, 25.0);
const SHOULDER_YAW: JointLimits = limits(-2.618, 2.618, 37.0, 25.0);
const ELBOW: JointLimits = limits(-1.0472, 2.0944, 37.0, 25.0);
const WRIST_ROLL: JointLimits = limits(-1.97222, 1.97222, 37.0, 25.0);
const WRIST_PITCH_YAW: JointLimits = limits(-1.61443, 1.61443, 22.0, 5.0);

/// Each joint's limits by slot (position rad, speed rad/s, torque N·m).
pub const JOINT_LIMITS: [JointLimits; JOINTS] = [
    HIP_PITCH,
    L_HIP_ROLL,
    HIP_YAW,
    KNEE,
    ANKLE_PITCH,
    ANKLE_ROLL,
    HIP_PITCH,
    R_HIP_ROLL,
    HIP_YAW,
    KNEE,
    ANKLE_PITCH,
    ANKLE_ROLL,
    WAIST_YAW,
    WAIST_ROLL_PITCH,
    WAIST_ROLL_PITCH,
    SHOULDER_PITCH,
    L_SHOULDER_ROLL,
    SHOULDER_YAW,
    ELBOW,
    WRIST_ROLL,
    WRIST_PITCH_YAW,
    WRIST_PITCH_YAW,
    SHOULDER_PITCH,
    R_SHOULDER_ROLL,
    SHOULDER_YAW,
    ELBOW,
    WRIST_ROLL,
    WRIST_PITCH_YAW,
    WRIST_PITCH_YAW,
];

/// One joint's gains.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// Position gain, N·m/rad.
    pub kp: f32,
    /// Velocity gain, N·m·s/rad.
    pub kd: f32,
}

const fn gains(kp: f32, kd: f32) -> Gains {
    Gains { kp, kd }
}

/// The gains of Unitree's G1 low-level example, by slot: legs 60/60/60/100/40/40 (kd 1, 2 at the
/// knees), waist 60/40/40, arms 40 (kd 1).
pub const DEFAULT_GAINS: [Gains; JOINTS] = {
    const LEG: [Gains; 6] =
        [gains(60.0, 1.0), gains(60.0, 1.0), gains(60.0, 1.0), gains(100.0, 2.0), gains(40.0, 1.0), gains(40.0, 1.0)];
    let mut all = [gains(40.0, 1.0); JOINTS];
    let mut i = 0;
    while i < 6 {
        all[i] = LEG[i];
        all[6 + i] = LEG[i];
        i += 1;
    }
    all[12] = gains(60.0, 1.0);
    all
};

/// The control mode of the parallel joints (ankles, waist roll/pitch), `LowCmd_.mode_pr`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[repr(u8)]
pub enum ModePr {
    /// 0: the slots are the serial pitch and roll joints (the firmware drives the motors).
    #[default]
    Pr = 0,
    /// 1: the slots are the parallel A and B motors themselves (ankle: slot 4/10 B, 5/11 A;
    /// waist: 13 A, 14 B).
    Ab = 1,
}

impl ModePr {
    /// The mode of a `mode_pr` byte; `None` for anything but 0 and 1.
    pub fn from_byte(byte: u8) -> Option<Self> {
        match byte {
            0 => Some(Self::Pr),
            1 => Some(Self::Ab),
            _ => None,
        }
    }
}

/// The A and B motor angles (rad) of a parallel joint pair from its pitch and roll (rad):
/// robowire's linearised model of the linkage, `a = pitch + roll`, `b = pitch − roll`.
pub fn pr_to_ab(pitch_rad: f32, roll_rad: f32) -> (f32, f32) {
    (pitch_rad + roll_rad, pitch_rad - roll_rad)
}

/// Pitch and roll (rad) from the A and B motor angles (rad); the inverse of [`pr_to_ab`].
pub fn ab_to_pr(a_rad: f32, b_rad: f32) -> (f32, f32) {
    ((a_rad + b_rad) / 2.0, (a_rad - b_rad) / 2.0)
}

/// The parallel joint pairs as `(pitch slot, roll slot)`: in AB mode the pitch slot carries B
/// and the roll slot A.
pub const PARALLEL_PAIRS: [(usize, usize); 3] = [
    (slot::LEFT_ANKLE_PITCH, slot::LEFT_ANKLE_ROLL),
    (slot::RIGHT_ANKLE_PITCH, slot::RIGHT_ANKLE_ROLL),
    (slot::WAIST_PITCH, slot::WAIST_ROLL),
];

/// A command's positions as pitch and roll joints: the slots' `q` in PR mode, mapped back from
/// the A/B motors ([`ab_to_pr`]) in AB mode. Indexed by slot.
pub fn joint_targets(cmd: &HgLowCmd) -> [f32; JOINTS] {
    let mut q: [f32; JOINTS] = core::array::from_fn(|i| cmd.motor_cmd[i].q.get());
    if cmd.mode_pr == ModePr::Ab as u8 {
        for (pitch, roll) in PARALLEL_PAIRS {
            let (b, a) = (q[pitch], q[roll]);
            (q[pitch], q[roll]) = ab_to_pr(a, b);
        }
    }
    q
}

/// Which G1 the robot is: which slots drive a joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum G1Variant {
    /// 29 joints: legs 0..12, waist 12..15, arms 15..29.
    Dof29,
    /// The 29-dof body with the waist's roll and pitch locked (Unitree's "27-dof"): 13 and 14
    /// drive nothing.
    Dof29WaistLocked,
    /// 23 joints in the same slots: waist roll/pitch (13, 14) and wrist pitch/yaw (20, 21, 27,
    /// 28) drive nothing.
    Dof23,
    /// The dual-arm G1: only the arms (15..29).
    DualArm,
}

impl G1Variant {
    /// The variant a LowState's `mode_machine` names (Unitree's `g1_description` table: 4 23-dof,
    /// 5 29-dof, 6 29-dof with the waist locked, 9 dual arm, 10–16 later revisions, 1–3
    /// deprecated). `None` for 0 (a simulator) and values not in the table.
    pub fn of_mode_machine(mode_machine: u8) -> Option<Self> {
        match mode_machine {
            1 | 4 | 10 => Some(Self::Dof23),
            2 | 5 | 11 | 13 | 15 => Some(Self::Dof29),
            3 | 6 | 12 | 14 | 16 => Some(Self::Dof29WaistLocked),
            9 => Some(Self::DualArm),
            _ => None,
        }
    }

    /// The `mode_machine` a robot of this variant (revision 1.0) reports.
    pub fn mode_machine(self) -> u8 {
        match self {
            Self::Dof23 => 4,
            Self::Dof29 => 5,
            Self::Dof29WaistLocked => 6,
            Self::DualArm => 9,
        }
    }

    /// Whether slot `slot` drives a joint on this variant.
    pub fn drives(self, slot: usize) -> bool {
        slot < JOINTS
            && match self {
                Self::Dof29 => true,
                Self::Dof29WaistLocked => !matches!(slot, 13 | 14),
                Self::Dof23 => !matches!(slot, 13 | 14 | 20 | 21 | 27 | 28),
                Self::DualArm => slot >= 15,
            }
    }

    /// Joints driven.
    pub fn joint_count(self) -> usize {
        (0..JOINTS).filter(|&s| self.drives(s)).count()
    }
}

/// A command that holds `q_rad` (by slot) with [`DEFAULT_GAINS`] on every joint `variant`
/// drives, in PR mode, with `mode_machine`; every other slot disabled and zero.
pub fn hold(q_rad: &[f32; JOINTS], mode_machine: u8, variant: G1Variant) -> HgLowCmd {
    let mut cmd = HgLowCmd::default();
    cmd.mode_machine = mode_machine;
    for (slot, m) in cmd.motor_cmd.iter_mut().enumerate().take(JOINTS) {
        if variant.drives(slot) {
            let g = DEFAULT_GAINS[slot];
            *m = HgMotorCmd::servo(q_rad[slot], 0.0, g.kp, g.kd, 0.0);
        }
    }
    cmd
}

/// The `rt/arm_sdk` weight, moved toward its target at most `rate_per_s` per second: an arm
/// command is blended in and out, never switched. Caller time (seconds between steps).
///
/// ```
/// use unitree_proto::g1::WeightRamp;
/// let mut ramp = WeightRamp::new(0.5);
/// ramp.set_target(1.0);
/// assert_eq!(ramp.step(0.02), 0.01);
/// for _ in 0..200 { ramp.step(0.02); }
/// assert_eq!(ramp.weight(), 1.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightRamp {
    weight: f32,
    target: f32,
    rate_per_s: f32,
}

impl WeightRamp {
    /// At weight 0, target 0, moving at most `rate_per_s` (a finite positive rate; anything else
    /// is [`ARM_SDK_WEIGHT_RATE_PER_S`]).
    pub fn new(rate_per_s: f32) -> Self {
        let rate_per_s =
            if rate_per_s.is_finite() && rate_per_s > 0.0 { rate_per_s } else { ARM_SDK_WEIGHT_RATE_PER_S };
        Self { weight: 0.0, target: 0.0, rate_per_s }
    }

    /// Where the weight goes, clamped to 0..=1 (NaN: 0).
    pub fn set_target(&mut self, target: f32) {
        self.target = if target.is_nan() { 0.0 } else { target.clamp(0.0, 1.0) };
    }

    /// The target.
    pub fn target(&self) -> f32 {
        self.target
    }

    /// The weight now.
    pub fn weight(&self) -> f32 {
        self.weight
    }

    /// Advances by `dt_s` seconds (negative or NaN: 0) and returns the weight.
    pub fn step(&mut self, dt_s: f32) -> f32 {
        let dt_s = if dt_s.is_finite() { dt_s.max(0.0) } else { 0.0 };
        let max_step = self.rate_per_s * dt_s;
        let delta = (self.target - self.weight).clamp(-max_step, max_step);
        self.weight = (self.weight + delta).clamp(0.0, 1.0);
        self.weight
    }
}

// Keep the bounds these rules document in one place.
const _: () = assert!(KP_MAX >= 300.0 && KD_MAX >= 3.0, "Unitree's teleoperation gains must pass");
const _: () = assert!(HG_MOTOR_COUNT > slot::ARM_SDK_WEIGHT);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_weight_ramps_both_ways_and_never_jumps() {
        let mut ramp = WeightRamp::new(ARM_SDK_WEIGHT_RATE_PER_S);
        ramp.set_target(1.0);
        let mut last = 0.0;
        for _ in 0..150 {
            let w = ramp.step(0.02);
            assert!(w - last <= 0.0100001 && w >= last);
            last = w;
        }
        assert_eq!(last, 1.0);
        ramp.set_target(f32::NAN);
        assert_eq!(ramp.target(), 0.0);
        assert!((ramp.step(1.0) - 0.5).abs() < 1e-6);
        assert_eq!(ramp.step(f32::INFINITY), 0.5, "a bad step does not move it");
        assert_eq!(ramp.step(10.0), 0.0);
    }

    #[test]
    fn mode_machine_table() {
        assert_eq!(G1Variant::of_mode_machine(5), Some(G1Variant::Dof29));
        assert_eq!(G1Variant::of_mode_machine(4), Some(G1Variant::Dof23));
        assert_eq!(G1Variant::of_mode_machine(6), Some(G1Variant::Dof29WaistLocked));
        assert_eq!(G1Variant::of_mode_machine(0), None);
        assert_eq!(G1Variant::Dof23.joint_count(), 23);
        assert_eq!(G1Variant::Dof29WaistLocked.joint_count(), 27);
        for v in [G1Variant::Dof29, G1Variant::Dof23, G1Variant::Dof29WaistLocked, G1Variant::DualArm] {
            assert_eq!(G1Variant::of_mode_machine(v.mode_machine()), Some(v));
        }
    }
}
