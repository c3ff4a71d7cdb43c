//! `robowire policy run`'s refusals, each one line before anything is sent: a kinematic
//! simulator, a device that is not a Unitree robot, a config for the other robot family, a config
//! whose sizes disagree, a model that is not there. The walks themselves (MuJoCo) are
//! `tests/walk.rs`.

use crate::support::robowire;

/// Unitree's G1 deploy config with its fields unchanged, beside a model path that does not exist.
const G1_YAML: &str = "control_dt: 0.02\nmsg_type: \"hg\"\nimu_type: \"pelvis\"\nlowcmd_topic: \"rt/lowcmd\"\n\
lowstate_topic: \"rt/lowstate\"\npolicy_path: \"absent.onnx\"\nleg_joint2motor_idx: [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]\n\
kps: [100, 100, 100, 150, 40, 40, 100, 100, 100, 150, 40, 40]\nkds: [2, 2, 2, 4, 2, 2, 2, 2, 2, 4, 2, 2]\n\
default_angles: [-0.1, 0.0, 0.0, 0.3, -0.2, 0.0, -0.1, 0.0, 0.0, 0.3, -0.2, 0.0]\n\
ang_vel_scale: 0.25\ndof_pos_scale: 1.0\ndof_vel_scale: 0.05\naction_scale: 0.25\ncmd_scale: [2.0, 2.0, 0.25]\n\
num_actions: 12\nnum_obs: 47\nmax_cmd: [0.8, 0.5, 1.57]\n";

/// `robowire policy run CONFIG ARGS` with `yaml` as CONFIG: its exit failed, its one line.
fn refused(yaml: &str, args: &[&str]) -> String {
    let dir = std::env::temp_dir().join(format!("robowire-policy-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let config = dir.join(format!("{}.yaml", args.join("_").replace([':', '/', ','], "-")));
    std::fs::write(&config, yaml).unwrap();
    let out = robowire().args(["policy", "run"]).arg(&config).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "one line: {stderr}");
    lines[0].to_owned()
}

#[test]
fn a_kinematic_simulator_is_refused() {
    let line = refused(G1_YAML, &["--device", "sim:g1"]);
    assert!(line.contains("sim:g1 is the kinematic simulator") && line.contains("--physics"), "{line}");
}

#[test]
fn a_device_that_is_not_a_unitree_robot_is_refused() {
    let line = refused(G1_YAML, &["--device", "sim:kmc"]);
    assert!(line.contains("a policy drives a Unitree robot"), "{line}");
}

#[test]
fn a_g1_config_on_a_go2_is_refused() {
    let line = refused(G1_YAML, &["--device", "go2:lo"]);
    assert!(line.contains("msg_type") && line.contains("go2:lo"), "{line}");
}

#[test]
fn a_config_whose_sizes_disagree_is_one_line_naming_the_field() {
    let line = refused(&G1_YAML.replace("num_obs: 47", "num_obs: 48"), &["--device", "g1:lo"]);
    assert!(line.ends_with("num_obs: is 48, the observation's terms make 47"), "{line}");
}

#[test]
fn a_missing_model_is_one_line() {
    let line = refused(G1_YAML, &["--device", "g1:lo"]);
    assert!(line.contains("absent.onnx"), "{line}");
}

#[test]
fn a_command_that_is_not_three_finite_values_is_refused() {
    let out =
        robowire().args(["policy", "run", "any.yaml", "--device", "g1:lo", "--cmd", "0.5,nan,0"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("finite"));
}
