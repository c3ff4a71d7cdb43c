//! The checks a G1 command must pass before it is sent (see [`check_low_cmd`], [`check_arm_sdk`]).

use super::{ARM_SDK_JOINTS, G1Variant, JOINT_LIMITS, ModePr, joint_targets, slot};
use crate::hg::{HgLowCmd, HgMotorCmd};
use crate::robot::{CommandError, MotorField, check_motor, within};

/// Whether any of a motor command's targets, gains or torque is non-zero.
fn commands_something(m: &HgMotorCmd) -> bool {
    [m.q, m.dq, m.tau, m.kp, m.kd].iter().any(|v| v.get() != 0.0)
}

/// The checks of one slot that drives a joint: its documented range (when kp > 0), speed (when
/// kd > 0) and torque; in AB mode a parallel pair is checked as pitch and roll.
fn check_joint(slot: usize, m: &HgMotorCmd, q_joint: f32) -> Result<(), CommandError> {
    let limits = &JOINT_LIMITS[slot];
    let (dq, tau, kp, kd) = (m.dq.get(), m.tau.get(), m.kp.get(), m.kd.get());
    within(slot, MotorField::Tau, tau, -limits.tau_max, limits.tau_max)?;
    if kp != 0.0 {
        within(slot, MotorField::Q, q_joint, limits.q_min, limits.q_max)?;
    }
    if kd != 0.0 {
        within(slot, MotorField::Dq, dq, -limits.dq_max, limits.dq_max)?;
    }
    Ok(())
}

/// Every slot's finite values and gains (0..=[`KP_MAX`], 0..=[`KD_MAX`]), `mode` 0 or 1.
fn check_slots(cmd: &HgLowCmd) -> Result<(), CommandError> {
    for (motor, m) in cmd.motor_cmd.iter().enumerate() {
        check_motor(motor, m.q, m.dq, m.tau, m.kp, m.kd)?;
        if m.mode > 1 {
            return Err(CommandError::OutOfRange {
                motor,
                field: MotorField::Mode,
                value: f32::from(m.mode),
                min: 0.0,
                max: 1.0,
            });
        }
    }
    Ok(())
}

/// Whether a `rt/lowcmd` command may be sent to a G1 of `variant` whose LowState said
/// `mode_machine` (`None`: no LowState seen yet). The robot acts on a LowCmd only with its own
/// `mode_machine`, and on a motor only with `mode` 1; a frame that breaks either is accepted on
/// the wire and commands nothing, so it is refused here:
///
/// - `mode_machine` unknown ([`CommandError::NoModeMachine`]) or not the robot's
///   ([`CommandError::ModeMachine`]); `mode_pr` not 0 or 1 ([`CommandError::ModePr`]);
/// - on every slot: finite values, kp 0..=500, kd 0..=50, `mode` 0 or 1; a slot with `mode` 0
///   and any target, gain or torque set ([`CommandError::DisabledMotor`]);
/// - a slot that drives nothing on this variant (and 29..35) enabled or with anything set
///   ([`CommandError::UndrivenMotor`]);
/// - on every joint: |tau| within its torque, `q` within its range when kp > 0 (an AB-mode pair
///   mapped back to pitch and roll first), |dq| within its speed when kd > 0.
pub fn check_low_cmd(cmd: &HgLowCmd, mode_machine: Option<u8>, variant: G1Variant) -> Result<(), CommandError> {
    let expected = mode_machine.ok_or(CommandError::NoModeMachine)?;
    if cmd.mode_machine != expected {
        return Err(CommandError::ModeMachine { expected, found: cmd.mode_machine });
    }
    if ModePr::from_byte(cmd.mode_pr).is_none() {
        return Err(CommandError::ModePr { found: cmd.mode_pr });
    }
    check_slots(cmd)?;
    let q = joint_targets(cmd);
    for (motor, m) in cmd.motor_cmd.iter().enumerate() {
        if !variant.drives(motor) {
            if m.mode != 0 || commands_something(m) {
                return Err(CommandError::UndrivenMotor { motor });
            }
            continue;
        }
        if m.mode == 0 {
            if commands_something(m) {
                return Err(CommandError::DisabledMotor { motor });
            }
            continue;
        }
        check_joint(motor, m, q[motor])?;
    }
    Ok(())
}

/// Whether a `rt/arm_sdk` command may be sent: the weight (slot 29's `q`) within 0..=1; the arm
/// and waist joints ([`ARM_SDK_JOINTS`]) that `variant` drives checked as in [`check_low_cmd`]
/// (in PR mode; the robot's controller reads targets and gains, not `mode`); every other slot
/// zero. `mode_machine` is not checked (the robot's controller ignores it on this topic, and
/// Unitree's arm examples leave it 0).
pub fn check_arm_sdk(cmd: &HgLowCmd, variant: G1Variant) -> Result<(), CommandError> {
    let weight = cmd.motor_cmd[slot::ARM_SDK_WEIGHT].q.get();
    if !weight.is_finite() || !(0.0..=1.0).contains(&weight) {
        return Err(CommandError::ArmSdkWeight { value: weight });
    }
    if ModePr::from_byte(cmd.mode_pr) != Some(ModePr::Pr) {
        return Err(CommandError::ModePr { found: cmd.mode_pr });
    }
    check_slots(cmd)?;
    for (motor, m) in cmd.motor_cmd.iter().enumerate() {
        if motor == slot::ARM_SDK_WEIGHT {
            if [m.dq, m.tau, m.kp, m.kd].iter().any(|v| v.get() != 0.0) {
                return Err(CommandError::UndrivenMotor { motor });
            }
        } else if ARM_SDK_JOINTS.contains(&motor) && variant.drives(motor) {
            check_joint(motor, m, m.q.get())?;
        } else if m.mode != 0 || commands_something(m) {
            return Err(CommandError::UndrivenMotor { motor });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::g1::{JOINTS, ab_to_pr, hold, pr_to_ab};

    fn zero_hold(variant: G1Variant) -> HgLowCmd {
        hold(&[0.0; JOINTS], variant.mode_machine(), variant)
    }

    #[test]
    fn the_mode_machine_must_be_the_robots() {
        let cmd = zero_hold(G1Variant::Dof29);
        assert_eq!(check_low_cmd(&cmd, Some(5), G1Variant::Dof29), Ok(()));
        assert_eq!(check_low_cmd(&cmd, None, G1Variant::Dof29), Err(CommandError::NoModeMachine));
        assert_eq!(
            check_low_cmd(&cmd, Some(6), G1Variant::Dof29),
            Err(CommandError::ModeMachine { expected: 6, found: 5 })
        );
        let mut pr = cmd;
        pr.mode_pr = 2;
        assert_eq!(check_low_cmd(&pr, Some(5), G1Variant::Dof29), Err(CommandError::ModePr { found: 2 }));
    }

    #[test]
    fn a_disabled_motor_with_a_command_and_undriven_slots_are_refused() {
        let mut cmd = zero_hold(G1Variant::Dof29);
        cmd.motor_cmd[7].mode = 0;
        assert_eq!(check_low_cmd(&cmd, Some(5), G1Variant::Dof29), Err(CommandError::DisabledMotor { motor: 7 }));
        cmd.motor_cmd[7] = HgMotorCmd::default();
        assert_eq!(check_low_cmd(&cmd, Some(5), G1Variant::Dof29), Ok(()), "a disabled, empty slot is fine");
        // Unitree's 29-joint command on a 23-dof G1 commands joints it does not have.
        let all = zero_hold(G1Variant::Dof29);
        assert_eq!(check_low_cmd(&all, Some(5), G1Variant::Dof23), Err(CommandError::UndrivenMotor { motor: 13 }));
        assert_eq!(check_low_cmd(&zero_hold(G1Variant::Dof23), Some(4), G1Variant::Dof23), Ok(()));
        let mut extra = zero_hold(G1Variant::Dof29);
        extra.motor_cmd[30].kd = 1.0.into();
        assert_eq!(check_low_cmd(&extra, Some(5), G1Variant::Dof29), Err(CommandError::UndrivenMotor { motor: 30 }));
    }

    #[test]
    fn joint_ranges_speeds_and_torques() {
        let mut cmd = zero_hold(G1Variant::Dof29);
        cmd.motor_cmd[slot::LEFT_KNEE].q = (-0.5).into();
        assert!(matches!(
            check_low_cmd(&cmd, Some(5), G1Variant::Dof29),
            Err(CommandError::OutOfRange { motor: 3, field: MotorField::Q, .. })
        ));
        let mut cmd = zero_hold(G1Variant::Dof29);
        cmd.motor_cmd[20].tau = 6.0.into();
        assert!(matches!(
            check_low_cmd(&cmd, Some(5), G1Variant::Dof29),
            Err(CommandError::OutOfRange { motor: 20, field: MotorField::Tau, .. })
        ));
        let mut cmd = zero_hold(G1Variant::Dof29);
        cmd.motor_cmd[0].kp = f32::INFINITY.into();
        assert!(matches!(check_low_cmd(&cmd, Some(5), G1Variant::Dof29), Err(CommandError::NonFinite { .. })));
    }

    #[test]
    fn ab_mode_is_checked_as_pitch_and_roll() {
        let (a, b) = pr_to_ab(0.3, 0.2);
        let (pitch, roll) = ab_to_pr(a, b);
        assert!((pitch - 0.3).abs() < 1e-6 && (roll - 0.2).abs() < 1e-6);
        let mut cmd = zero_hold(G1Variant::Dof29);
        cmd.mode_pr = ModePr::Ab as u8;
        // Pitch 0.3, roll 0.2: A 0.5 (slot 5), B 0.1 (slot 4); 0.5 alone would be an out-of-range roll.
        cmd.motor_cmd[slot::LEFT_ANKLE_ROLL].q = a.into();
        cmd.motor_cmd[slot::LEFT_ANKLE_PITCH].q = b.into();
        assert_eq!(check_low_cmd(&cmd, Some(5), G1Variant::Dof29), Ok(()));
        let q = joint_targets(&cmd);
        assert!((q[4] - 0.3).abs() < 1e-6 && (q[5] - 0.2).abs() < 1e-6, "{:?}", &q[4..6]);
        cmd.mode_pr = ModePr::Pr as u8;
        assert!(check_low_cmd(&cmd, Some(5), G1Variant::Dof29).is_err(), "as PR, roll 0.5 is out of range");
    }

    #[test]
    fn arm_sdk_weight_and_legs() {
        let mut cmd = HgLowCmd::default();
        for &j in &ARM_SDK_JOINTS {
            cmd.motor_cmd[j].kp = 60.0.into();
            cmd.motor_cmd[j].kd = 1.5.into();
        }
        cmd.motor_cmd[slot::ARM_SDK_WEIGHT].q = 1.0.into();
        assert_eq!(check_arm_sdk(&cmd, G1Variant::Dof29), Ok(()), "Unitree's arm example: modes and mode_machine 0");
        cmd.motor_cmd[slot::ARM_SDK_WEIGHT].q = 1.5.into();
        assert_eq!(check_arm_sdk(&cmd, G1Variant::Dof29), Err(CommandError::ArmSdkWeight { value: 1.5 }));
        cmd.motor_cmd[slot::ARM_SDK_WEIGHT].q = f32::NAN.into();
        assert!(matches!(check_arm_sdk(&cmd, G1Variant::Dof29), Err(CommandError::ArmSdkWeight { .. })));
        cmd.motor_cmd[slot::ARM_SDK_WEIGHT].q = 0.5.into();
        cmd.motor_cmd[slot::LEFT_KNEE].kp = 10.0.into();
        assert_eq!(check_arm_sdk(&cmd, G1Variant::Dof29), Err(CommandError::UndrivenMotor { motor: 3 }));
    }
}
