//! What a low-level controller must respect, per robot family, as pure functions: which
//! messages it exchanges, which commands are refused before anything is sent (NaN, infinities,
//! gains, torques, velocities, the Go2's joint limits), and the damping command that replaces a
//! stale one.
//!
//! **Damping** (robowire decision): kp 0, a small kd, no position target (`PosStopF`), a
//! velocity target of 0 and no torque, on every driven joint: the torque is `−kd · dq` whatever
//! the firmware does with its sentinels. (`VelStopF` with kd > 0 is not documented to mean
//! "damp": it is either ignored, leaving the joint limp, or taken as a 16000 rad/s target.)

use core::fmt;

use crate::go2::{self, LowCmd, LowState, POS_STOP_F, VEL_STOP_F};
use crate::hg::{HgLowCmd, HgLowState};
use crate::{F32, Message};

/// The joint names of the Go2, in `motor_cmd` order (`LegID`, spec §5.3).
pub const GO2_JOINT_NAMES: [&str; 12] = [
    "FR_hip", "FR_thigh", "FR_calf", "FL_hip", "FL_thigh", "FL_calf", "RR_hip", "RR_thigh", "RR_calf", "RL_hip",
    "RL_thigh", "RL_calf",
];

/// A joint's limits on the Go2 (Unitree's `go2_description` URDF), rad, rad/s, N·m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// Lowest position, rad.
    pub q_min: f32,
    /// Highest position, rad.
    pub q_max: f32,
    /// Largest |velocity|, rad/s.
    pub dq_max: f32,
    /// Largest |torque|, N·m.
    pub tau_max: f32,
}

// The URDF's decimal literals as written there (they are rounded π fractions, not π fractions).
#[allow(clippy::approx_constant)]
const HIP: JointLimits = JointLimits { q_min: -1.0472, q_max: 1.0472, dq_max: 30.1, tau_max: 23.7 };
#[allow(clippy::approx_constant)]
const FRONT_THIGH: JointLimits = JointLimits { q_min: -1.5708, q_max: 3.4907, dq_max: 30.1, tau_max: 23.7 };
#[allow(clippy::approx_constant)]
const REAR_THIGH: JointLimits = JointLimits { q_min: -0.5236, q_max: 4.5379, dq_max: 30.1, tau_max: 23.7 };
const CALF: JointLimits = JointLimits { q_min: -2.7227, q_max: -0.83776, dq_max: 15.7, tau_max: 45.43 };

/// The Go2's 12 joints' limits, in `motor_cmd` order.
pub const GO2_JOINT_LIMITS: [JointLimits; 12] =
    [HIP, FRONT_THIGH, CALF, HIP, FRONT_THIGH, CALF, HIP, REAR_THIGH, CALF, HIP, REAR_THIGH, CALF];

/// Largest accepted position gain (robowire's bound; Unitree's stand example uses 60).
pub const KP_MAX: f32 = 500.0;
/// Largest accepted velocity gain (robowire's bound; Unitree's stand example uses 5).
pub const KD_MAX: f32 = 50.0;
/// The damping command's default kd.
pub const DAMPING_KD: f32 = 1.0;

/// Which field of a motor command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotorField {
    /// `q`, rad.
    Q,
    /// `dq`, rad/s.
    Dq,
    /// `tau`, N·m.
    Tau,
    /// `kp`.
    Kp,
    /// `kd`.
    Kd,
    /// `mode`.
    Mode,
}

impl fmt::Display for MotorField {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Q => "q",
            Self::Dq => "dq",
            Self::Tau => "tau",
            Self::Kp => "kp",
            Self::Kd => "kd",
            Self::Mode => "mode",
        })
    }
}

/// Why a command is refused. Nothing is sent; the previous command stays.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CommandError {
    /// NaN or an infinity.
    #[error("motor {motor} {field} is {value}: not finite")]
    NonFinite {
        /// Motor slot.
        motor: usize,
        /// Field.
        field: MotorField,
        /// Value.
        value: f32,
    },
    /// Outside the documented range.
    #[error("motor {motor} {field} = {value} is outside {min}..={max}")]
    OutOfRange {
        /// Motor slot.
        motor: usize,
        /// Field.
        field: MotorField,
        /// Value.
        value: f32,
        /// Lowest accepted.
        min: f32,
        /// Highest accepted.
        max: f32,
    },
    /// A "no target" sentinel with a non-zero gain on it (`PosStopF` with kp > 0, `VelStopF`
    /// with kd > 0).
    #[error("motor {motor} {field} is the no-target sentinel but its gain is not zero")]
    SentinelWithGain {
        /// Motor slot.
        motor: usize,
        /// Field.
        field: MotorField,
    },
    /// A motor the robot does not have (Go2 slots 12..19) with a gain or torque.
    #[error("motor {motor} is not driven on this robot; its kp, kd and tau must be 0")]
    UndrivenMotor {
        /// Motor slot.
        motor: usize,
    },
    /// No state has told the robot's `mode_machine` yet (HG): a command without it is ignored by
    /// the robot.
    #[error("no LowState seen yet: the robot's mode_machine is unknown, and it ignores a LowCmd without it")]
    NoModeMachine,
    /// The command's `mode_machine` is not the one the robot reports (HG): the robot ignores it.
    #[error("mode_machine {found} is not the robot's ({expected}, from its LowState): the robot ignores this LowCmd")]
    ModeMachine {
        /// The robot's, from its LowState.
        expected: u8,
        /// The command's.
        found: u8,
    },
    /// `mode_pr` is neither 0 (PR) nor 1 (AB), or not what the topic takes (HG).
    #[error("mode_pr {found} is not accepted here (0: pitch/roll, 1: A/B)")]
    ModePr {
        /// The command's.
        found: u8,
    },
    /// A motor with `mode` 0 (disabled) and a target, gain or torque set (HG): the robot accepts
    /// the frame and the motor does nothing.
    #[error("motor {motor} has mode 0 (disabled) but a target, gain or torque: set mode 1 to command it")]
    DisabledMotor {
        /// Motor slot.
        motor: usize,
    },
    /// The `rt/arm_sdk` weight (slot 29's `q`) outside 0..=1 or not finite.
    #[error("the arm_sdk weight {value} is outside 0..=1")]
    ArmSdkWeight {
        /// The weight.
        value: f32,
    },
    /// A header the robot drops (Go2: `head` FE EF, `level_flag` 0xFF).
    #[error("the command's header is {found:02x?}, the robot expects {expected:02x?}")]
    Header {
        /// What the robot expects (`head[0]`, `head[1]`, `level_flag`).
        expected: [u8; 3],
        /// What the command has.
        found: [u8; 3],
    },
}

/// A robot family's low-level messages and rules.
pub trait Robot: Send + Sync + 'static {
    /// Its command.
    type Cmd: Message + robowire_core::cdr::CdrType + fmt::Debug + Send + Sync;
    /// Its state.
    type State: Message + robowire_core::cdr::CdrType + fmt::Debug + Send + Sync;
    /// Joints driven (Go2: 12).
    const JOINTS: usize;
    /// Family name for messages.
    const NAME: &'static str;

    /// `Ok` if `cmd` may be sent.
    fn check(cmd: &Self::Cmd) -> Result<(), CommandError>;

    /// The damping command, derived from the last one sent (what the family keeps from it).
    fn damping(last: &Self::Cmd, kd: f32) -> Self::Cmd;

    /// Position of joint `joint` (a motor slot below [`JOINTS`](Self::JOINTS)) in a state, rad.
    fn joint_position(state: &Self::State, joint: usize) -> Option<f32>;

    /// The state's `tick` counter.
    fn tick(state: &Self::State) -> u32;
}

/// The Go2 (`unitree_go`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Go2;

/// The HG family (G1, H1-2; `unitree_hg`): its 35 slots are checked for finiteness, gains and
/// sentinels. The G1's own rules (`mode_machine`, disabled motors, joint limits) need the robot's
/// LowState and are [`crate::g1::check_low_cmd`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Hg;

pub(crate) fn finite(motor: usize, field: MotorField, value: F32) -> Result<f32, CommandError> {
    let value = value.get();
    if value.is_finite() { Ok(value) } else { Err(CommandError::NonFinite { motor, field, value }) }
}

pub(crate) fn within(motor: usize, field: MotorField, value: f32, min: f32, max: f32) -> Result<(), CommandError> {
    if (min..=max).contains(&value) { Ok(()) } else { Err(CommandError::OutOfRange { motor, field, value, min, max }) }
}

/// The checks every family shares: finite fields, gains in range, sentinels only with gain 0.
pub(crate) fn check_motor(motor: usize, q: F32, dq: F32, tau: F32, kp: F32, kd: F32) -> Result<[f32; 5], CommandError> {
    let [q, dq, tau, kp, kd] = [
        finite(motor, MotorField::Q, q)?,
        finite(motor, MotorField::Dq, dq)?,
        finite(motor, MotorField::Tau, tau)?,
        finite(motor, MotorField::Kp, kp)?,
        finite(motor, MotorField::Kd, kd)?,
    ];
    within(motor, MotorField::Kp, kp, 0.0, KP_MAX)?;
    within(motor, MotorField::Kd, kd, 0.0, KD_MAX)?;
    if q == POS_STOP_F && kp != 0.0 {
        return Err(CommandError::SentinelWithGain { motor, field: MotorField::Q });
    }
    if dq == VEL_STOP_F && kd != 0.0 {
        return Err(CommandError::SentinelWithGain { motor, field: MotorField::Dq });
    }
    Ok([q, dq, tau, kp, kd])
}

impl Robot for Go2 {
    type Cmd = LowCmd;
    type State = LowState;
    const JOINTS: usize = 12;
    const NAME: &'static str = "Go2";

    /// The header the robot expects; on the 12 joints: finite values, kp 0..=500, kd 0..=50,
    /// |tau| within the joint's torque, `q` within the joint's range when kp > 0, |dq| within
    /// its speed when kd > 0, sentinels only with a zero gain; slots 12..19 without gain or torque.
    fn check(cmd: &LowCmd) -> Result<(), CommandError> {
        let found = [cmd.head[0], cmd.head[1], cmd.level_flag];
        let expected = [go2::HEAD[0], go2::HEAD[1], go2::LEVEL_LOW];
        if found != expected {
            return Err(CommandError::Header { expected, found });
        }
        for (motor, m) in cmd.motor_cmd.iter().enumerate() {
            let [q, dq, tau, kp, kd] = check_motor(motor, m.q, m.dq, m.tau, m.kp, m.kd)?;
            if m.mode > go2::MOTOR_MODE_SERVO {
                let value = f32::from(m.mode);
                return Err(CommandError::OutOfRange { motor, field: MotorField::Mode, value, min: 0.0, max: 1.0 });
            }
            let Some(limits) = GO2_JOINT_LIMITS.get(motor) else {
                if kp != 0.0 || kd != 0.0 || tau != 0.0 {
                    return Err(CommandError::UndrivenMotor { motor });
                }
                continue;
            };
            within(motor, MotorField::Tau, tau, -limits.tau_max, limits.tau_max)?;
            if kp != 0.0 {
                within(motor, MotorField::Q, q, limits.q_min, limits.q_max)?;
            }
            if kd != 0.0 {
                within(motor, MotorField::Dq, dq, -limits.dq_max, limits.dq_max)?;
            }
        }
        Ok(())
    }

    fn damping(_: &LowCmd, kd: f32) -> LowCmd {
        let mut cmd = LowCmd::default();
        for m in cmd.motor_cmd.iter_mut().take(Self::JOINTS) {
            *m = go2::MotorCmd::servo(POS_STOP_F, 0.0, 0.0, kd, 0.0);
        }
        cmd
    }

    fn joint_position(state: &LowState, joint: usize) -> Option<f32> {
        (joint < Self::JOINTS).then(|| state.motor_state[joint].q.get())
    }

    fn tick(state: &LowState) -> u32 {
        state.tick.get()
    }
}

impl Robot for Hg {
    type Cmd = HgLowCmd;
    type State = HgLowState;
    const JOINTS: usize = crate::hg::HG_MOTOR_COUNT;
    const NAME: &'static str = "HG";

    fn check(cmd: &HgLowCmd) -> Result<(), CommandError> {
        for (motor, m) in cmd.motor_cmd.iter().enumerate() {
            check_motor(motor, m.q, m.dq, m.tau, m.kp, m.kd)?;
        }
        Ok(())
    }

    /// `mode_pr` and `mode_machine` kept from the last command (the robot ignores a LowCmd
    /// without its `mode_machine`); the motors the last command enabled (every motor if it
    /// enabled none) enabled with kp 0, `kd`, no targets or torque.
    fn damping(last: &HgLowCmd, kd: f32) -> HgLowCmd {
        let mut cmd = HgLowCmd::default();
        cmd.mode_pr = last.mode_pr;
        cmd.mode_machine = last.mode_machine;
        let any_enabled = last.motor_cmd.iter().any(|m| m.mode != 0);
        for (m, was) in cmd.motor_cmd.iter_mut().zip(&last.motor_cmd) {
            if was.mode != 0 || !any_enabled {
                m.mode = 1;
                m.kd = kd.into();
            }
        }
        cmd
    }

    fn joint_position(state: &HgLowState, joint: usize) -> Option<f32> {
        state.motor_state.get(joint).map(|m| m.q.get())
    }

    fn tick(state: &HgLowState) -> u32 {
        state.tick.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::go2::MotorCmd;

    fn stand() -> LowCmd {
        let mut cmd = LowCmd::default();
        for (i, m) in cmd.motor_cmd.iter_mut().take(12).enumerate() {
            *m = MotorCmd::servo([0.0, 0.67, -1.3][i % 3], 0.0, 60.0, 5.0, 0.0);
        }
        cmd
    }

    #[test]
    fn the_stand_command_and_damping_pass_and_bad_values_are_named() {
        assert_eq!(Go2::check(&stand()), Ok(()));
        assert_eq!(Go2::check(&LowCmd::default()), Ok(()), "the safe default");
        let damping = Go2::damping(&stand(), DAMPING_KD);
        assert_eq!(Go2::check(&damping), Ok(()));
        assert!(damping.motor_cmd[..12].iter().all(|m| m.kp.get() == 0.0 && m.kd.get() == 1.0 && m.dq.get() == 0.0));

        let mut nan = stand();
        nan.motor_cmd[4].kd = f32::NAN.into();
        assert!(matches!(Go2::check(&nan), Err(CommandError::NonFinite { motor: 4, field: MotorField::Kd, .. })));
        let mut calf = stand();
        calf.motor_cmd[2].q = 0.0.into();
        assert!(matches!(Go2::check(&calf), Err(CommandError::OutOfRange { motor: 2, field: MotorField::Q, .. })));
        calf.motor_cmd[2].kp = 0.0.into(); // no position gain: the target does not matter
        assert_eq!(Go2::check(&calf), Ok(()));
        let mut torque = stand();
        torque.motor_cmd[0].tau = 30.0.into();
        assert!(matches!(Go2::check(&torque), Err(CommandError::OutOfRange { field: MotorField::Tau, .. })));
        let mut sentinel = stand();
        sentinel.motor_cmd[1].q = POS_STOP_F.into();
        assert_eq!(Go2::check(&sentinel), Err(CommandError::SentinelWithGain { motor: 1, field: MotorField::Q }));
        let mut slot = stand();
        slot.motor_cmd[15].tau = 1.0.into();
        assert_eq!(Go2::check(&slot), Err(CommandError::UndrivenMotor { motor: 15 }));
        let mut header = stand();
        header.level_flag = go2::LEVEL_HIGH;
        assert!(matches!(Go2::check(&header), Err(CommandError::Header { .. })));
    }

    #[test]
    fn hg_damping_keeps_the_machine_mode() {
        let mut last = HgLowCmd::default();
        last.mode_machine = 5;
        let damping = Hg::damping(&last, 2.0);
        assert_eq!(damping.mode_machine, 5);
        assert_eq!(Hg::check(&damping), Ok(()));
    }
}
