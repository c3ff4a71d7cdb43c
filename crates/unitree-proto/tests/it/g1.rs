//! The G1's command checks on any input: never a panic, and what they accept is what the robot
//! acts on as documented (the robot's `mode_machine`, `mode_pr` 0 or 1, enabled joints inside
//! their ranges, nothing on an undriven slot); arbitrary commands near the example's are both
//! accepted and refused, so the property is not vacuous.

use proptest::prelude::*;
use unitree_proto::g1::{self, G1Variant, JOINT_LIMITS, JOINTS, check_arm_sdk, check_low_cmd, joint_targets};
use unitree_proto::{FromZeros, HgLowCmd, IntoBytes};

const VARIANTS: [G1Variant; 4] = [G1Variant::Dof29, G1Variant::Dof23, G1Variant::Dof29WaistLocked, G1Variant::DualArm];

/// Any bytes as a command.
fn any_bytes() -> impl Strategy<Value = HgLowCmd> {
    proptest::collection::vec(any::<u8>(), 1004).prop_map(|bytes| {
        let mut cmd = HgLowCmd::new_zeroed();
        cmd.as_mut_bytes().copy_from_slice(&bytes);
        cmd
    })
}

/// The example's zero hold with a few fields nudged: near the boundary of what is accepted.
fn near_the_example() -> impl Strategy<Value = (HgLowCmd, usize)> {
    let field = 0..6usize;
    (0..4usize, 0..35usize, field, -4.0f32..4.0, 0u8..3, 0u8..2).prop_map(|(v, slot, field, value, machine, pr)| {
        let variant = VARIANTS[v];
        let mut cmd = g1::hold(&[0.0; JOINTS], variant.mode_machine(), variant);
        cmd.mode_pr = pr;
        if machine == 2 {
            cmd.mode_machine ^= 1;
        }
        let m = &mut cmd.motor_cmd[slot];
        match field {
            0 => m.q = value.into(),
            1 => m.dq = (value * 10.0).into(),
            2 => m.tau = (value * 10.0).into(),
            3 => m.kp = (value * 100.0).into(),
            4 => m.kd = value.into(),
            _ => m.mode = (value.abs() as u8) % 3,
        }
        (cmd, v)
    })
}

/// What an accepted command must be.
fn accepted_is_sound(cmd: &HgLowCmd, mode_machine: u8, variant: G1Variant) -> Result<(), TestCaseError> {
    prop_assert_eq!(cmd.mode_machine, mode_machine);
    prop_assert!(cmd.mode_pr <= 1);
    let q = joint_targets(cmd);
    for (slot, m) in cmd.motor_cmd.iter().enumerate() {
        let values = [m.q, m.dq, m.tau, m.kp, m.kd].map(|v| v.get());
        prop_assert!(values.iter().all(|v| v.is_finite()));
        if !variant.drives(slot) || m.mode == 0 {
            prop_assert!(m.mode == 0 || variant.drives(slot), "slot {} enabled", slot);
            prop_assert!(values.iter().all(|v| *v == 0.0), "slot {} commands something disabled", slot);
            continue;
        }
        let limits = &JOINT_LIMITS[slot];
        prop_assert!(m.tau.get().abs() <= limits.tau_max);
        if m.kp.get() != 0.0 {
            prop_assert!((limits.q_min..=limits.q_max).contains(&q[slot]), "slot {} q {}", slot, q[slot]);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn any_bytes_are_checked_without_a_panic(cmd in any_bytes(), machine in any::<u8>(), v in 0..4usize) {
        let variant = VARIANTS[v];
        if check_low_cmd(&cmd, Some(machine), variant).is_ok() {
            accepted_is_sound(&cmd, machine, variant)?;
        }
        let _ = check_low_cmd(&cmd, None, variant);
        let _ = check_arm_sdk(&cmd, variant);
        let _ = joint_targets(&cmd);
    }

    #[test]
    fn what_is_accepted_near_the_example_is_sound((cmd, v) in near_the_example()) {
        let variant = VARIANTS[v];
        if check_low_cmd(&cmd, Some(variant.mode_machine()), variant).is_ok() {
            accepted_is_sound(&cmd, variant.mode_machine(), variant)?;
        }
    }
}

#[test]
fn near_the_example_both_outcomes_occur() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..500 {
        let (cmd, v) = near_the_example().new_tree(&mut runner).unwrap().current();
        let variant = VARIANTS[v];
        match check_low_cmd(&cmd, Some(variant.mode_machine()), variant) {
            Ok(()) => accepted += 1,
            Err(_) => refused += 1,
        }
    }
    assert!(accepted > 50 && refused > 50, "accepted {accepted}, refused {refused}");
}
