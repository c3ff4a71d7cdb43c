//! The Go2's and the G1's bodies as frames turned by their motors
//! ([`Kinematics`](robowire_core::kinematics::Kinematics)): each body's place and orientation
//! in its parent's frame and its hinge's axis are those of robowire's MuJoCo models
//! (`robowire-sim/models`, from Unitree's URDFs) as MuJoCo compiles them; robowire-sim's physics
//! tests check every body's pose against MuJoCo's at pseudo-random joint positions. Bodies are named
//! as in those models; the base (the Go2's trunk, the G1's pelvis) is `base`.

use robowire_core::kinematics::{Body, Hinge, Kinematics};

use crate::{HgLowState, LowState, Message};

const X: [f64; 3] = [1.0, 0.0, 0.0];
const Y: [f64; 3] = [0.0, 1.0, 0.0];
const Z: [f64; 3] = [0.0, 0.0, 1.0];
/// No rotation (w, x, y, z).
const LEVEL: [f64; 4] = [1.0, 0.0, 0.0, 0.0];

const fn hinge(
    name: &'static str,
    parent: &'static str,
    origin_m: [f64; 3],
    rotation: [f64; 4],
    motor: usize,
    axis: [f64; 3],
) -> Body {
    Body { name, parent, origin_m, rotation, hinge: Some(Hinge { motor, axis }) }
}

const fn welded(name: &'static str, parent: &'static str, origin_m: [f64; 3]) -> Body {
    Body { name, parent, origin_m, rotation: LEVEL, hinge: None }
}

/// The Go2: hip about x, thigh and calf about y, in `motor_cmd` order; the feet at the calves'
/// ends.
pub static GO2: Kinematics = Kinematics {
    robot: "go2",
    state_schema: <LowState as Message>::DDS_TYPE_NAME,
    motor_states_pointer: "/motor_state",
    bodies: &[
        hinge("FR_hip", "base", [0.1934, -0.0465, 0.0], LEVEL, 0, X),
        hinge("FR_thigh", "FR_hip", [0.0, -0.0955, 0.0], LEVEL, 1, Y),
        hinge("FR_calf", "FR_thigh", [0.0, 0.0, -0.213], LEVEL, 2, Y),
        hinge("FL_hip", "base", [0.1934, 0.0465, 0.0], LEVEL, 3, X),
        hinge("FL_thigh", "FL_hip", [0.0, 0.0955, 0.0], LEVEL, 4, Y),
        hinge("FL_calf", "FL_thigh", [0.0, 0.0, -0.213], LEVEL, 5, Y),
        hinge("RR_hip", "base", [-0.1934, -0.0465, 0.0], LEVEL, 6, X),
        hinge("RR_thigh", "RR_hip", [0.0, -0.0955, 0.0], LEVEL, 7, Y),
        hinge("RR_calf", "RR_thigh", [0.0, 0.0, -0.213], LEVEL, 8, Y),
        hinge("RL_hip", "base", [-0.1934, 0.0465, 0.0], LEVEL, 9, X),
        hinge("RL_thigh", "RL_hip", [0.0, 0.0955, 0.0], LEVEL, 10, Y),
        hinge("RL_calf", "RL_thigh", [0.0, 0.0, -0.213], LEVEL, 11, Y),
        welded("FR_foot", "FR_calf", [0.0, 0.0, -0.213]),
        welded("FL_foot", "FL_calf", [0.0, 0.0, -0.213]),
        welded("RR_foot", "RR_calf", [0.0, 0.0, -0.213]),
        welded("RL_foot", "RL_calf", [0.0, 0.0, -0.213]),
    ],
};

/// The hip roll links' pitch of −0.1749 rad (the URDF's `rpy`).
const HIP_ROLL_TILT: [f64; 4] = [0.9961786849744957, 0.0, -0.08733858026373247, 0.0];
/// The knees' pitch of +0.1749 rad.
const KNEE_TILT: [f64; 4] = [0.9961786849744957, 0.0, 0.08733858026373247, 0.0];
/// The shoulders' mounting (the URDF's `rpy` of the shoulder pitch and roll links).
const LEFT_SHOULDER_PITCH: [f64; 4] =
    [0.9902640743722195, 0.13920148374281427, 1.3872204401988457e-05, -9.868683842420437e-05];
const LEFT_SHOULDER_ROLL: [f64; 4] = [0.9902682552548409, -0.1391717738427347, 0.0, 0.0];
const RIGHT_SHOULDER_PITCH: [f64; 4] =
    [0.9902640743722195, -0.13920148374281427, 1.3872204401988457e-05, 9.868683842420437e-05];
const RIGHT_SHOULDER_ROLL: [f64; 4] = [0.9902682552548409, 0.1391717738427347, 0.0, 0.0];

/// The G1 (29 joints, in `motor_cmd` order: legs, waist, arms); a 23-joint G1 reports its
/// absent joints at 0, where they stand. The hands and the head are welded.
pub static G1: Kinematics = Kinematics {
    robot: "g1",
    state_schema: <HgLowState as Message>::DDS_TYPE_NAME,
    motor_states_pointer: "/motor_state",
    bodies: &[
        hinge("left_hip_pitch_link", "base", [0.0, 0.064452, -0.1027], LEVEL, 0, Y),
        hinge("left_hip_roll_link", "left_hip_pitch_link", [0.0, 0.052, -0.030465], HIP_ROLL_TILT, 1, X),
        hinge("left_hip_yaw_link", "left_hip_roll_link", [0.025001, 0.0, -0.12412], LEVEL, 2, Z),
        hinge("left_knee_link", "left_hip_yaw_link", [-0.078273, 0.0021489, -0.17734], KNEE_TILT, 3, Y),
        hinge("left_ankle_pitch_link", "left_knee_link", [0.0, -9.4445e-05, -0.30001], LEVEL, 4, Y),
        hinge("left_ankle_roll_link", "left_ankle_pitch_link", [0.0, 0.0, -0.017558], LEVEL, 5, X),
        hinge("right_hip_pitch_link", "base", [0.0, -0.064452, -0.1027], LEVEL, 6, Y),
        hinge("right_hip_roll_link", "right_hip_pitch_link", [0.0, -0.052, -0.030465], HIP_ROLL_TILT, 7, X),
        hinge("right_hip_yaw_link", "right_hip_roll_link", [0.025001, 0.0, -0.12412], LEVEL, 8, Z),
        hinge("right_knee_link", "right_hip_yaw_link", [-0.078273, -0.0021489, -0.17734], KNEE_TILT, 9, Y),
        hinge("right_ankle_pitch_link", "right_knee_link", [0.0, 9.4445e-05, -0.30001], LEVEL, 10, Y),
        hinge("right_ankle_roll_link", "right_ankle_pitch_link", [0.0, 0.0, -0.017558], LEVEL, 11, X),
        hinge("waist_yaw_link", "base", [0.0, 0.0, 0.0], LEVEL, 12, Z),
        hinge("waist_roll_link", "waist_yaw_link", [-0.0039635, 0.0, 0.044], LEVEL, 13, X),
        hinge("torso_link", "waist_roll_link", [0.0, 0.0, 0.0], LEVEL, 14, Y),
        hinge("left_shoulder_pitch_link", "torso_link", [0.0039563, 0.10022, 0.24778], LEFT_SHOULDER_PITCH, 15, Y),
        hinge(
            "left_shoulder_roll_link",
            "left_shoulder_pitch_link",
            [0.0, 0.038, -0.013831],
            LEFT_SHOULDER_ROLL,
            16,
            X,
        ),
        hinge("left_shoulder_yaw_link", "left_shoulder_roll_link", [0.0, 0.00624, -0.1032], LEVEL, 17, Z),
        hinge("left_elbow_link", "left_shoulder_yaw_link", [0.015783, 0.0, -0.080518], LEVEL, 18, Y),
        hinge("left_wrist_roll_link", "left_elbow_link", [0.1, 0.00188791, -0.01], LEVEL, 19, X),
        hinge("left_wrist_pitch_link", "left_wrist_roll_link", [0.038, 0.0, 0.0], LEVEL, 20, Y),
        hinge("left_wrist_yaw_link", "left_wrist_pitch_link", [0.046, 0.0, 0.0], LEVEL, 21, Z),
        hinge("right_shoulder_pitch_link", "torso_link", [0.0039563, -0.10021, 0.24778], RIGHT_SHOULDER_PITCH, 22, Y),
        hinge(
            "right_shoulder_roll_link",
            "right_shoulder_pitch_link",
            [0.0, -0.038, -0.013831],
            RIGHT_SHOULDER_ROLL,
            23,
            X,
        ),
        hinge("right_shoulder_yaw_link", "right_shoulder_roll_link", [0.0, -0.00624, -0.1032], LEVEL, 24, Z),
        hinge("right_elbow_link", "right_shoulder_yaw_link", [0.015783, 0.0, -0.080518], LEVEL, 25, Y),
        hinge("right_wrist_roll_link", "right_elbow_link", [0.1, -0.00188791, -0.01], LEVEL, 26, X),
        hinge("right_wrist_pitch_link", "right_wrist_roll_link", [0.038, 0.0, 0.0], LEVEL, 27, Y),
        hinge("right_wrist_yaw_link", "right_wrist_pitch_link", [0.046, 0.0, 0.0], LEVEL, 28, Z),
        welded("head_link", "torso_link", [0.0039635, 0.0, -0.044]),
        welded("left_rubber_hand", "left_wrist_yaw_link", [0.0415, 0.003, 0.0]),
        welded("right_rubber_hand", "right_wrist_yaw_link", [0.0415, -0.003, 0.0]),
    ],
};

/// Every robot of the family with a table.
pub static ROBOTS: [&Kinematics; 2] = [&GO2, &G1];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::g1::JOINT_NAMES;
    use crate::robot::GO2_JOINT_NAMES;

    #[test]
    fn every_motor_turns_one_named_body_and_every_parent_comes_first() {
        for (robot, names) in [(&GO2, &GO2_JOINT_NAMES[..]), (&G1, &JOINT_NAMES[..])] {
            let motors: Vec<usize> = robot.bodies.iter().filter_map(|b| b.hinge.map(|h| h.motor)).collect();
            assert_eq!(motors, (0..names.len()).collect::<Vec<_>>(), "{}", robot.robot);
            for (at, body) in robot.bodies.iter().enumerate() {
                if let Some(hinge) = body.hinge {
                    // The model's joint names: the Go2's `FR_hip` turns `FR_hip`, the G1's
                    // `left_knee_joint` turns `left_knee_link`; the waist's last turns the torso.
                    let joint = names[hinge.motor].trim_end_matches("_joint");
                    assert!(body.name.starts_with(joint) || joint == "waist_pitch", "{} {}", body.name, joint);
                    assert_eq!(hinge.axis.iter().map(|c| c * c).sum::<f64>(), 1.0);
                }
                let norm: f64 = body.rotation.iter().map(|c| c * c).sum();
                assert!((norm - 1.0).abs() < 1e-12, "{}: {norm}", body.name);
                let earlier = robot.bodies[..at].iter().any(|b| b.name == body.parent);
                assert!(body.parent == "base" || earlier, "{}: parent {} not before it", body.name, body.parent);
            }
        }
    }
}
