//! unitree-proto's kinematic tables against robowire's models as MuJoCo computes them: at a few
//! pseudo-random joint positions under a tilted base, every body of each table is where MuJoCo
//! puts it, and turned as MuJoCo turns it.

use robowire_core::kinematics::{Kinematics, Pose};
use unitree_proto::kinematics::{G1, GO2};

use super::*;

/// A rig of `robot` driving every motor, for `mjcf`.
fn rig(robot: &'static str, mjcf: &'static str, names: &[&'static str]) -> Rig {
    Rig {
        robot,
        mjcf,
        joints: names.iter().map(|&name| Some(name)).collect(),
        tau_max_nm: vec![1.0; names.len()],
        start_pose_rad: vec![0.0; names.len()],
        base_height_m: 0.5,
        feet: Vec::new(),
    }
}

fn check(table: &Kinematics, rig: &Rig, mut seed: u64) {
    let mut physics = Physics::load(rig, &PhysicsOptions::default()).expect("robowire's model loads");
    // A pseudo-random pose: joints within ±1.5 rad, the base tilted and turned.
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 3.0 - 1.5
    };
    let base = physics.base_qpos;
    let (h, k) = (0.3f64, 0.2f64);
    let base_pose = [0.1, -0.2, 0.6, h.cos() * k.cos(), h.sin() * k.cos(), h.cos() * k.sin(), h.sin() * k.sin()];
    let q: Vec<f64> = (0..rig.joints.len()).map(|_| next()).collect();
    {
        let qpos = physics.data.qpos_mut();
        qpos[base..base + 7].copy_from_slice(&base_pose);
        for (motor, q) in physics.motors.iter().zip(&q) {
            qpos[motor.expect("every motor driven").qpos] = *q;
        }
    }
    physics.data.forward();
    let model = physics.data.model();
    let world = |name: &str| {
        let id = model.name_to_id(MjtObjBase::mjOBJ_BODY, name).unwrap_or_else(|| panic!("no body {name}"));
        (physics.data.xpos()[id], physics.data.xquat()[id])
    };
    let root = model.body_parentid()[model.jnt_bodyid()[0] as usize] as usize;
    assert_eq!(root, 0, "the free joint's body hangs from the world");
    let (position, rotation) = world(model.id_to_name(MjtObjBase::mjOBJ_BODY, model.jnt_bodyid()[0] as usize).unwrap());
    let mut placed = vec![("base", Pose { translation_m: position, rotation })];
    for body in table.bodies {
        let parent = placed.iter().find(|(n, _)| *n == body.parent).expect("parents first").1;
        let pose = parent.then(&body.pose(body.hinge.map(|h| q[h.motor])));
        let (position, rotation) = world(body.name);
        for i in 0..3 {
            assert!((pose.translation_m[i] - position[i]).abs() < 1e-9, "{}: {pose:?} vs {position:?}", body.name);
        }
        // q and −q are one rotation.
        let sign = if (0..4).map(|i| pose.rotation[i] * rotation[i]).sum::<f64>() < 0.0 { -1.0 } else { 1.0 };
        for i in 0..4 {
            assert!((sign * pose.rotation[i] - rotation[i]).abs() < 1e-9, "{}: {pose:?} vs {rotation:?}", body.name);
        }
        placed.push((body.name, pose));
    }
}

#[test]
fn the_go2_and_g1_tables_place_every_body_where_mujoco_does() {
    use unitree_proto::robot::GO2_JOINT_NAMES;
    let go2 = rig("Go2", include_str!("../../models/go2.xml"), &GO2_JOINT_NAMES);
    let g1 = rig("G1", include_str!("../../models/g1.xml"), &unitree_proto::g1::JOINT_NAMES);
    for seed in [0x2545_f491_4f6c_dd1d, 0x9e37_79b9_7f4a_7c15, 0xbf58_476d_1ce4_e5b9] {
        check(&GO2, &go2, seed);
        check(&G1, &g1, seed);
    }
}
