//! Unitree's G1 walking policy (`../shared/policies`), loaded with its own deploy config.

use robowire_fixtures::{interop, peers};
use robowire_policy::{Observer, OnnxPolicy, PolicyConfig, Sensed};

#[test]
fn unitrees_g1_policy_loads_with_its_deploy_config_and_its_lstm_state() {
    let Some(dir) = interop::require(peers::policies_dir()) else { return };
    let config = PolicyConfig::load(&dir.join("g1_walk.yaml")).unwrap();
    assert_eq!(config.policy_path, dir.join("g1_walk.onnx"));
    let mut policy = OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions).unwrap();
    assert_eq!(policy.recurrent_inputs().collect::<Vec<_>>(), ["h_in", "c_in"]);
    let mut observer = Observer::new(&config);
    let q: Vec<f32> = (0..35).map(|m| config.default_angles.get(m).copied().unwrap_or(0.0)).collect();
    let dq = [0.0; 35];
    let sensed = Sensed {
        quaternion_wxyz: [1.0, 0.0, 0.0, 0.0],
        gyroscope_rad_s: [0.0; 3],
        base_velocity_world_m_s: None,
        motor_q_rad: &q,
        motor_dq_rad_s: &dq,
    };
    let obs = observer.observe(&sensed, [0.5, 0.0, 0.0]).unwrap().to_vec();
    let first = policy.step(&obs).unwrap().to_vec();
    assert!(first.iter().all(|a| a.is_finite() && a.abs() < 10.0), "{first:?}");
    // The LSTM's state moved: the same observation gives other actions, until it is reset.
    let second = policy.step(&obs).unwrap().to_vec();
    assert_ne!(first, second);
    policy.reset();
    assert_eq!(policy.step(&obs).unwrap(), first);
}
