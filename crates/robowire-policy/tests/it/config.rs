//! Deploy configs: Unitree's as they are, and the ones refused, each with one line naming the field.

use robowire_policy::{ImuType, MsgType, PolicyConfig, Term};

/// unitree_rl_gym's `deploy_real/configs/g1.yaml` as Unitree ships it.
pub(crate) const G1_YAML: &str = r#"
control_dt: 0.02
msg_type: "hg"     # "hg" or "go"
imu_type: "pelvis"    # "torso" or "pelvis"
lowcmd_topic: "rt/lowcmd"
lowstate_topic: "rt/lowstate"
policy_path: "{LEGGED_GYM_ROOT_DIR}/deploy/pre_train/g1/motion.pt"
leg_joint2motor_idx: [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]
kps: [100, 100, 100, 150, 40, 40, 100, 100, 100, 150, 40, 40]
kds: [2, 2, 2, 4, 2, 2, 2, 2, 2, 4, 2, 2]
default_angles: [-0.1,  0.0,  0.0,  0.3, -0.2, 0.0,
                  -0.1,  0.0,  0.0,  0.3, -0.2, 0.0]
arm_waist_joint2motor_idx: [12, 13, 14,
                            15, 16, 17, 18, 19, 20, 21,
                            22, 23, 24, 25, 26, 27, 28]
arm_waist_kps: [300, 300, 300,
                100, 100, 50, 50, 20, 20, 20,
                100, 100, 50, 50, 20, 20, 20]
arm_waist_kds: [3, 3, 3,
                2, 2, 2, 2, 1, 1, 1,
                2, 2, 2, 2, 1, 1, 1]
arm_waist_target: [ 0, 0, 0,
                    0, 0, 0, 0, 0, 0, 0,
                    0, 0, 0, 0, 0, 0, 0]
ang_vel_scale: 0.25
dof_pos_scale: 1.0
dof_vel_scale: 0.05
action_scale: 0.25
cmd_scale: [2.0, 2.0, 0.25]
num_actions: 12
num_obs: 47
max_cmd: [0.8, 0.5, 1.57]
"#;

/// unitree_rl_gym's `deploy_mujoco/configs/go2.yaml` as a deploy config: a Go2 policy's joints
/// are FL, FR, RL, RR where the SDK's motors are FR, FL, RR, RL; its observation starts with the
/// base's linear velocity.
pub(crate) const GO2_YAML: &str = r#"
control_dt: 0.02
msg_type: "go"
policy_path: "go2.onnx"
leg_joint2motor_idx: [3, 4, 5, 0, 1, 2, 9, 10, 11, 6, 7, 8]
kps: [20.0, 20.0, 20.0, 20.0, 20.0, 20.0, 20.0, 20.0, 20.0, 20.0, 20.0, 20.0]
kds: [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]
default_angles: [0.1,  0.8,  -1.5,  -0.1, 0.8, -1.5,
                 0.1,  1.0,  -1.5,  -0.1, 1.0, -1.5]
lin_vel_scale: 2.0
ang_vel_scale: 0.25
dof_pos_scale: 1.0
dof_vel_scale: 0.05
action_scale: 0.25
cmd_scale: [2.0, 2.0, 0.25]
num_actions: 12
num_obs: 48
max_cmd: [1.0, 0.5, 1.0]
observation: [base_lin_vel, base_ang_vel, projected_gravity, command, joint_pos, joint_vel, last_action]
"#;

#[test]
fn unitrees_g1_config_reads_as_it_is_with_deploy_reals_defaults() {
    let config = PolicyConfig::parse(G1_YAML).unwrap();
    assert_eq!((config.msg_type, config.imu_type, config.num_obs), (MsgType::Hg, ImuType::Pelvis, 47));
    assert_eq!(config.observation, Term::DEPLOY_REAL);
    assert_eq!((config.gait_period, config.lin_vel_scale, config.max_tilt_rad), (0.8, 1.0, 1.0));
    assert_eq!(config.kps[3], 150.0);
    assert_eq!(config.arm_waist_joint2motor_idx.len(), 17);
}

fn refused(from: &str, to: &str) -> String {
    assert!(G1_YAML.contains(from), "{from}");
    PolicyConfig::parse(&G1_YAML.replacen(from, to, 1)).unwrap_err().to_string()
}

#[test]
fn sizes_that_disagree_are_refused_naming_the_field() {
    assert_eq!(refused("num_obs: 47", "num_obs: 48"), "num_obs: is 48, the observation's terms make 47");
    assert_eq!(refused("kds: [2, 2, 2, 4, 2, 2, ", "kds: [2, 2, 4, 2, 2, "), "kds: has 11 entries, num_actions is 12");
    assert_eq!(
        refused("arm_waist_target: [ 0, 0, 0,", "arm_waist_target: [ 0, 0,"),
        "arm_waist_target: has 16 entries, arm_waist_joint2motor_idx has 17"
    );
    assert_eq!(refused("[12, 13, 14,", "[12, 13, 11,"), "arm_waist_joint2motor_idx: motor 11 is listed twice");
    assert_eq!(refused("control_dt: 0.02", "control_dt: -1"), "control_dt: -1 s is not in (0, 1]");
    assert_eq!(
        refused("max_cmd: [0.8, 0.5, 1.57]", "max_cmd: [0.8, 0.5, 1.57]\nobservation: [joint_pos, joint_pos]"),
        "observation: joint_pos is listed twice"
    );
}

#[test]
fn a_malformed_config_is_one_line_naming_the_field() {
    let unknown = refused("num_obs: 47", "num_obs: 47\nnum_ob: 3");
    assert!(unknown.contains("num_ob"), "{unknown}");
    assert!(!unknown.contains('\n'), "{unknown}");
    let wrong = refused("msg_type: \"hg\"", "msg_type: \"lowcmd\"");
    assert!(wrong.contains("lowcmd"), "{wrong}");
    assert!(!wrong.contains('\n'), "{wrong}");
}

#[test]
fn a_go2_config_with_robowires_observation_terms() {
    let config = PolicyConfig::parse(GO2_YAML).unwrap();
    assert_eq!((config.msg_type, config.observation_len(), config.lin_vel_scale), (MsgType::Go, 48, 2.0));
    assert!(config.arm_waist_joint2motor_idx.is_empty());
    let past = PolicyConfig::parse(&GO2_YAML.replace("[3, 4, 5, 0,", "[3, 4, 20, 0,")).unwrap_err();
    assert_eq!(past.to_string(), "leg_joint2motor_idx: motor 20 is past the LowCmd's 20");
}
