use super::*;
use unitree_proto::HgMotorCmd;

fn hold(q: &[f32; JOINTS], variant: G1Variant) -> HgLowCmd {
    g1::hold(q, variant.mode_machine(), variant)
}

/// `seconds` of 2 ms steps, `each` called before every step.
fn run(body: &mut G1Body, seconds: f32, mut each: impl FnMut(&mut G1Body, f32)) {
    let steps = (seconds * 500.0).round() as u32;
    for i in 0..steps {
        each(body, i as f32 * 0.002);
        body.step(0.002);
        body.advance_tick(2);
    }
}

fn near(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() < tolerance
}

#[test]
fn it_stands_under_its_controller_and_ignores_lowcmds_until_released() {
    let mut body = G1Body::new(G1Variant::Dof29, 5);
    run(&mut body, 1.0, |b, _| b.command(&hold(&[0.0; JOINTS], G1Variant::Dof29)));
    assert_eq!(body.joint_positions(), STAND_POSE_RAD, "held where it stands");
    let state = body.low_state();
    assert_eq!((state.mode_machine, state.mode_pr, state.tick.get()), (5, 0, 1000));
    assert!(state.motor_state[..JOINTS].iter().all(|m| m.mode == 1 && m.vol.get() == SUPPLY_V));
    body.set_controller(false);
    run(&mut body, 1.0, |b, _| b.command(&hold(&[0.0; JOINTS], G1Variant::Dof29)));
    assert!(body.joint_positions().iter().all(|q| q.abs() < 0.01), "{:?}", body.joint_positions());
}

#[test]
fn a_stale_or_disabled_command_leaves_the_motors_passive() {
    let mut body = G1Body::new(G1Variant::Dof29, 5);
    body.set_controller(false);
    let mut cmd = hold(&[0.0; JOINTS], G1Variant::Dof29);
    cmd.motor_cmd[slot::LEFT_KNEE].mode = 0;
    assert!(has_disabled_motor(&cmd, G1Variant::Dof29));
    run(&mut body, 1.0, |b, _| b.command(&cmd));
    let q = body.joint_positions();
    assert!(near(q[slot::LEFT_KNEE], 0.3, 1e-6), "mode 0: no torque, the knee stays: {q:?}");
    assert!(near(q[slot::RIGHT_KNEE], 0.0, 0.01), "mode 1 motors of the frame are applied: {q:?}");
    // No command for longer than the hold: passive, no torque.
    run(&mut body, 0.2, |_, _| {});
    assert!(body.low_state().motor_state[..JOINTS].iter().all(|m| m.tau_est.get() == 0.0));
}

#[test]
fn pr_and_ab_both_move_the_ankle_and_the_state_reports_the_mode() {
    let variant = G1Variant::Dof29;
    let mut body = G1Body::new(variant, 5);
    body.set_controller(false);
    let mut target = [0.0; JOINTS];
    (target[slot::LEFT_ANKLE_PITCH], target[slot::LEFT_ANKLE_ROLL]) = (0.3, 0.1);
    let pr = hold(&target, variant);
    run(&mut body, 1.0, |b, _| b.command(&pr));
    let q = body.joint_positions();
    assert!(near(q[4], 0.3, 0.01) && near(q[5], 0.1, 0.01), "{q:?}");
    // The same pose as A and B motors; the state then says A and B too.
    let mut ab = hold(&[0.0; JOINTS], variant);
    ab.mode_pr = ModePr::Ab as u8;
    let (a, b) = pr_to_ab(-0.2, 0.15);
    (ab.motor_cmd[slot::LEFT_ANKLE_ROLL].q, ab.motor_cmd[slot::LEFT_ANKLE_PITCH].q) = (a.into(), b.into());
    run(&mut body, 1.0, |body, _| body.command(&ab));
    let q = body.joint_positions();
    assert!(near(q[4], -0.2, 0.01) && near(q[5], 0.15, 0.01), "pitch and roll: {q:?}");
    let state = body.low_state();
    assert_eq!(state.mode_pr, ModePr::Ab as u8);
    assert!(near(state.motor_state[5].q.get(), a, 0.02) && near(state.motor_state[4].q.get(), b, 0.02));
}

#[test]
fn joints_stop_at_their_range_and_undriven_slots_do_nothing() {
    let variant = G1Variant::Dof23;
    let mut body = G1Body::new(variant, 4);
    body.set_controller(false);
    let mut cmd = hold(&[0.0; JOINTS], variant);
    cmd.motor_cmd[slot::LEFT_ANKLE_ROLL].q = 1.0.into();
    cmd.motor_cmd[20] = HgMotorCmd::servo(1.0, 0.0, 40.0, 1.0, 0.0);
    run(&mut body, 1.0, |b, _| b.command(&cmd));
    let q = body.joint_positions();
    assert_eq!(q[slot::LEFT_ANKLE_ROLL], g1::JOINT_LIMITS[5].q_max, "at its stop");
    assert_eq!(q[20], 0.0, "the 23-dof G1 has no wrist pitch");
    let state = body.low_state();
    assert_eq!((state.motor_state[20].mode, state.motor_state[20].q.get()), (0, 0.0));
    body.set_motor_fault(3, true);
    let state = body.low_state();
    assert_eq!((state.motor_state[3].mode, state.motor_state[3].motorstate.get()), (0, 1));
}

#[test]
fn arm_sdk_blends_by_its_weight_and_a_silent_arm_sdk_fades_out() {
    let variant = G1Variant::Dof29;
    let mut body = G1Body::new(variant, 5);
    let mut arm = HgLowCmd::default();
    for &j in &ARM_SDK_JOINTS {
        arm.motor_cmd[j].kp = 60.0.into();
        arm.motor_cmd[j].kd = 1.5.into();
    }
    arm.motor_cmd[slot::LEFT_ELBOW].q = 1.0.into();
    arm.motor_cmd[slot::LEFT_KNEE].q = 1.0.into(); // not an arm_sdk joint
    arm.motor_cmd[slot::ARM_SDK_WEIGHT].q = 0.5.into();
    run(&mut body, 2.0, |b, _| b.arm_sdk(&arm));
    let q = body.joint_positions();
    // Elbow: kp (0.5·50 + 0.5·60) toward 0.5·0 + 0.5·1.0.
    assert!(near(q[slot::LEFT_ELBOW], 0.5, 0.01), "{q:?}");
    assert!(near(q[slot::LEFT_KNEE], 0.3, 1e-3), "the legs stay the controller's: {q:?}");
    arm.motor_cmd[slot::ARM_SDK_WEIGHT].q = 2.0.into();
    run(&mut body, 2.0, |b, _| b.arm_sdk(&arm));
    assert_eq!(body.arm_sdk_weight(), 1.0, "clamped");
    assert!(near(body.joint_positions()[slot::LEFT_ELBOW], 1.0, 0.01));
    // Silent: after the hold the weight decays at its rate, never a jump.
    let mut last = body.arm_sdk_weight();
    run(&mut body, 3.0, |b, _| {
        let w = b.arm_sdk_weight();
        assert!(last - w <= ARM_SDK_WEIGHT_RATE_PER_S * 0.002 + 1e-6, "{last} → {w}");
        last = w;
    });
    assert_eq!(body.arm_sdk_weight(), 0.0);
    assert!(near(body.joint_positions()[slot::LEFT_ELBOW], 0.0, 0.01), "back to the controller's pose");
    // Released: arm_sdk does nothing.
    body.set_controller(false);
    body.arm_sdk(&arm);
    assert_eq!(body.arm_sdk_weight(), 0.0);
}
