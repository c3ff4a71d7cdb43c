//! The simulated bodies in MuJoCo (feature `mujoco`), without I/O: robowire's Go2 stands under
//! the gains of Unitree's stand example and not under a tenth of them, sinks when damped, lies
//! down again; robowire's G1, hanging, reaches the zero posture under Unitree's example gains;
//! a user's MJCF without a motor's joint is refused by name; the free G1 stands on its band until
//! a LowCmd stream drives its legs for `LET_GO_AFTER_S`, then it is let go and, under passive
//! joints, falls. Each in simulated time (2 ms
//! steps, as the state stream gives them), so the same on any machine.

use robowire_sim::g1::{G1Body, JOINTS as G1_JOINTS, LET_GO_AFTER_S};
use robowire_sim::go2::{Go2Body, JOINTS, LYING_POSE_RAD};
use robowire_sim::physics::{PhysicsError, PhysicsOptions};
use unitree_proto::g1::{self, G1Variant};
use unitree_proto::go2::MotorCmd;
use unitree_proto::{HgLowCmd, LowCmd};

/// The stand pose of Unitree's Go2 stand example, per motor.
const STAND: [f32; JOINTS] = [0.0, 0.67, -1.3, 0.0, 0.67, -1.3, 0.0, 0.67, -1.3, 0.0, 0.67, -1.3];
/// The pose its last stage lies down to.
const LIE: [f32; JOINTS] = [-0.35, 1.36, -2.65, 0.35, 1.36, -2.65, -0.5, 1.36, -2.65, 0.5, 1.36, -2.65];
const DT_S: f32 = 0.002;

fn servo(q: &[f32; JOINTS], kp: f32, kd: f32) -> LowCmd {
    let mut cmd = LowCmd::default();
    for (m, q) in q.iter().enumerate() {
        cmd.motor_cmd[m] = MotorCmd::servo(*q, 0.0, kp, kd, 0.0);
    }
    cmd
}

fn lerp(a: &[f32; JOINTS], b: &[f32; JOINTS], t: f32) -> [f32; JOINTS] {
    core::array::from_fn(|m| (1.0 - t) * a[m] + t * b[m])
}

fn height(body: &Go2Body) -> f32 {
    body.sport_state().expect("a body with a base").body_height.get()
}

/// `ticks` commands at 500 Hz, `pose(i)` the i-th; the lowest and highest base height seen.
fn drive(body: &mut Go2Body, ticks: u32, gains: (f32, f32), pose: impl Fn(u32) -> [f32; JOINTS]) -> (f32, f32) {
    let (mut low, mut high) = (f32::INFINITY, f32::NEG_INFINITY);
    for i in 1..=ticks {
        body.command(&servo(&pose(i), gains.0, gains.1));
        body.step(DT_S);
        let h = height(body);
        (low, high) = (low.min(h), high.max(h));
    }
    (low, high)
}

/// Unitree's go2_stand_example, stage by stage, at `scale` × its gains (Kp 60, Kd 5): the base
/// heights (lowest, highest) of the stand-up, the 2 s hold, and the height 1 s after lying down.
fn stand_example(scale: f32) -> ((f32, f32), (f32, f32), f32) {
    let mut body = Go2Body::physics(&PhysicsOptions::default()).expect("robowire's Go2 loads");
    let gains = (60.0 * scale, 5.0 * scale);
    let start = body.joint_positions();
    drive(&mut body, 500, gains, |i| lerp(&start, &LYING_POSE_RAD, i as f32 / 500.0));
    let up = drive(&mut body, 500, gains, |i| lerp(&LYING_POSE_RAD, &STAND, i as f32 / 500.0));
    let hold = drive(&mut body, 1000, gains, |_| STAND);
    drive(&mut body, 900, gains, |i| lerp(&STAND, &LIE, i as f32 / 900.0));
    drive(&mut body, 500, gains, |_| LIE);
    (up, hold, height(&body))
}

#[test]
fn the_go2_stands_under_unitree_s_stand_example_and_lies_down_after_it() {
    let (up, hold, lying) = stand_example(1.0);
    assert!(up.0 < 0.15, "it starts lying: {up:?}");
    assert!(hold.0 > 0.25, "through the 2 s hold the body stays above 0.25 m: {hold:?}");
    assert!(lying < 0.15, "after the last stage it lies below 0.15 m: {lying}");
}

#[test]
fn a_tenth_of_the_gains_does_not_lift_the_go2() {
    let (up, hold, _) = stand_example(0.1);
    assert!(up.1.max(hold.1) < 0.25, "never above 0.25 m: {up:?} {hold:?}");
}

#[test]
fn a_damped_go2_sinks_and_a_silent_one_too() {
    for damping in [Some(servo(&STAND, 0.0, 5.0)), None] {
        let mut body = Go2Body::physics(&PhysicsOptions::default()).unwrap();
        let start = body.joint_positions();
        drive(&mut body, 1000, (60.0, 5.0), |i| lerp(&start, &STAND, (i as f32 / 500.0).min(1.0)));
        drive(&mut body, 500, (60.0, 5.0), |_| STAND);
        assert!(height(&body) > 0.25, "standing: {}", height(&body));
        for _ in 0..1500 {
            if let Some(cmd) = &damping {
                body.command(cmd);
            }
            body.step(DT_S);
        }
        let state = body.low_state();
        assert!(height(&body) < 0.15, "{damping:?} sinks: {}", height(&body));
        assert!(state.motor_state[..JOINTS].iter().all(|m| m.tau_est.get().abs() <= 5.0 * 20.0));
    }
}

#[test]
fn the_go2_s_state_comes_from_the_physics() {
    let mut body = Go2Body::physics(&PhysicsOptions::default()).unwrap();
    // Settled before its time starts: lying at rest, the motors passive.
    let lying = body.sport_state().unwrap();
    let speed = lying.velocity.iter().map(|v| v.get().powi(2)).sum::<f32>().sqrt();
    assert!(lying.body_height.get() < 0.15 && speed < 0.05, "{lying:?}");
    assert_eq!(lying.stamp.sec.get(), 0);
    let start = body.joint_positions();
    drive(&mut body, 1000, (60.0, 5.0), |i| lerp(&start, &STAND, (i as f32 / 500.0).min(1.0)));
    let state = body.low_state();
    let q: Vec<f32> = state.motor_state[..JOINTS].iter().map(|m| m.q.get()).collect();
    // The calves sag under the weight by their torque over kp (about 6 N·m / 60).
    assert!(q.iter().zip(STAND).all(|(q, s)| (q - s).abs() < 0.15), "near the stand pose: {q:?}");
    // Standing still: gravity along the IMU's z, level, the feet carrying the weight.
    let acc = state.imu_state.accelerometer.map(|a| a.get());
    assert!((acc[2] - 9.81).abs() < 0.5 && acc[0].abs() < 0.5 && acc[1].abs() < 0.5, "{acc:?}");
    let feet: i32 = state.foot_force.iter().map(|f| i32::from(f.get())).sum();
    assert!((100..250).contains(&feet), "about the robot's weight in N on the feet: {feet}");
    // The calves carry load: their torques are what the physics needed, not zero.
    assert!(state.motor_state[2].tau_est.get().abs() > 1.0, "{:?}", state.motor_state[2]);
    // A NaN target exerts no torque (a real drive refuses it) and the body does not explode.
    body.command(&servo(&[f32::NAN; JOINTS], 60.0, 5.0));
    body.step(DT_S);
    let state = body.low_state();
    assert!(state.motor_state[..JOINTS].iter().all(|m| m.tau_est.get() == 0.0 && m.q.get().is_finite()));
}

/// The hanging G1 after Unitree's g1_low_level_example's first stage (3 s from where it is to
/// zero, its gains, the waist pitch's kp times `waist_pitch_gain`): the joints, the pelvis height.
fn g1_zero_posture(waist_pitch_gain: f32) -> ([f32; G1_JOINTS], f32) {
    let variant = G1Variant::Dof29;
    let options = PhysicsOptions { hanging: true, ..PhysicsOptions::default() };
    let mut body = G1Body::physics(variant, 5, &options).expect("robowire's G1 loads");
    body.set_controller(false);
    let start = body.joint_positions();
    let zero: HgLowCmd = g1::hold(&[0.0; G1_JOINTS], 5, variant);
    for i in 1..=1500 {
        let t = (i as f32 / 1500.0).min(1.0);
        let mut cmd = zero;
        for (slot, q0) in start.iter().enumerate() {
            cmd.motor_cmd[slot].q = ((1.0 - t) * q0).into();
        }
        let kp = cmd.motor_cmd[g1::slot::WAIST_PITCH].kp.get();
        cmd.motor_cmd[g1::slot::WAIST_PITCH].kp = (kp * waist_pitch_gain).into();
        body.command(&cmd);
        body.step(DT_S);
    }
    (body.joint_positions(), body.sport_state().unwrap().body_height.get())
}

#[test]
fn the_free_g1_stands_on_its_band_until_a_lowcmd_stream_drives_its_legs() {
    let variant = G1Variant::Dof29;
    let mut body = G1Body::physics(variant, 5, &PhysicsOptions::default()).expect("robowire's G1 loads");
    let pelvis = |body: &G1Body| body.sport_state().unwrap().position[2].get();
    // Settled on the floor, standing, held: its controller's stand and 3 s of nothing after it.
    body.set_controller(false);
    for _ in 0..1500 {
        body.step(DT_S);
    }
    assert!(body.held() && pelvis(&body) > 0.7, "held standing: {}", pelvis(&body));
    // A stream holding the stand pose with stiffness on every leg joint lets it go after
    // LET_GO_AFTER_S, not before.
    let hold = g1::hold(&body.joint_positions(), 5, variant);
    let ticks = (LET_GO_AFTER_S / DT_S).round() as u32;
    for tick in 0..ticks + 2 {
        // Held through the time (to a step: the time is summed in f32).
        assert!(body.held() || tick >= ticks - 1, "let go at tick {tick} of {ticks}");
        body.command(&hold);
        body.step(DT_S);
    }
    assert!(!body.held(), "let go after {ticks} ticks");
    // Let go and left passive (no LowCmd), it falls.
    for _ in 0..1500 {
        body.step(DT_S);
    }
    assert!(pelvis(&body) < 0.5, "fallen: {}", pelvis(&body));
}

#[test]
fn the_hanging_g1_reaches_the_zero_posture_under_unitree_s_example_gains() {
    let (q, pelvis_m) = g1_zero_posture(1.0);
    assert!(pelvis_m > 0.85, "held up by its hanging spring: {pelvis_m}");
    let waist = g1::slot::WAIST_PITCH;
    // The joints carry their links: each within 0.05 rad of 0, but the waist pitch, which holds
    // the 15 kg upper body (its centre of mass ahead of the axis, and above it: gravity's
    // toppling stiffness, about 30 N·m/rad, against the example's kp 40) and bows forward.
    assert!(q.iter().enumerate().all(|(s, q)| s == waist || q.abs() < 0.05), "zero posture: {q:?}");
    assert!(q[waist] > 0.05 && q[waist] < 0.35, "the upper body bows under gravity: {}", q[waist]);
    // That is gravity against the gain, not the model: at 5 × kp the waist is upright too.
    let (q, _) = g1_zero_posture(5.0);
    assert!(q.iter().all(|q| q.abs() < 0.05), "{q:?}");
}

#[test]
fn a_model_without_a_motor_s_joint_is_refused_by_name() {
    let dir = std::env::temp_dir().join(format!("robowire-physics-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("one_leg.xml");
    std::fs::write(
        &path,
        r#"<mujoco><worldbody><body name="base"><freejoint/><geom type="box" size=".1 .1 .1"/>
           <body name="FR_hip"><joint name="FR_hip_joint" axis="1 0 0"/><geom type="sphere" size=".02"/></body>
           </body></worldbody></mujoco>"#,
    )
    .unwrap();
    let err = Go2Body::physics(&PhysicsOptions { model: Some(path.clone()), hanging: false }).unwrap_err();
    assert!(matches!(err, PhysicsError::MissingJoint { joint: "FR_thigh", motor: 1, .. }), "{err}");
    assert!(err.to_string().contains("FR_thigh") && err.to_string().contains("one_leg.xml"), "{err}");
    let missing = dir.join("nowhere.xml");
    let err = Go2Body::physics(&PhysicsOptions { model: Some(missing), hanging: false }).unwrap_err();
    assert!(matches!(err, PhysicsError::Load { .. }) && err.to_string().contains("nowhere.xml"), "{err}");
    std::fs::write(&path, "<mujoco><worldbody><body><geom type='sphere' size='1'/></body></worldbody></mujoco>")
        .unwrap();
    let err = Go2Body::physics(&PhysicsOptions { model: Some(path), hanging: false }).unwrap_err();
    assert!(matches!(err, PhysicsError::NoFloatingBase { .. }), "{err}");
    std::fs::remove_dir_all(dir).unwrap();
}
