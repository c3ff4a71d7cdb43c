//! The ONNX model: loaded and checked against the config, run, recurrent state fed back.

use robowire_policy::{ModelError, OnnxPolicy};

use robowire_policy::tiny::{Model, linear, summing};

const W: [f32; 6] = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];

#[test]
fn a_feed_forward_model_maps_the_observation_to_actions() {
    let mut policy = OnnxPolicy::load(&linear(W).write(), 3, 2).unwrap();
    assert_eq!(policy.num_obs(), 3);
    assert_eq!(policy.recurrent_inputs().count(), 0);
    // [1 2 3] · [[1 2] [3 4] [5 6]]
    assert_eq!(policy.step(&[1.0, 2.0, 3.0]).unwrap(), [22.0, 28.0]);
    assert_eq!(policy.step(&[0.0, 0.0, 1.0]).unwrap(), [5.0, 6.0]);
}

#[test]
fn recurrent_state_starts_at_zeros_and_is_fed_back() {
    let mut policy = OnnxPolicy::load(&summing(W).write(), 3, 2).unwrap();
    assert_eq!(policy.recurrent_inputs().collect::<Vec<_>>(), ["h_in"]);
    // The test inference at load left no state behind.
    assert_eq!(policy.step(&[1.0, 0.0, 0.0]).unwrap(), [1.0, 2.0]);
    assert_eq!(policy.step(&[1.0, 0.0, 0.0]).unwrap(), [2.0, 4.0]);
    assert_eq!(policy.step(&[0.0, 1.0, 0.0]).unwrap(), [5.0, 8.0]);
    policy.reset();
    assert_eq!(policy.step(&[1.0, 0.0, 0.0]).unwrap(), [1.0, 2.0]);
}

#[test]
fn recurrent_pairs_are_found_by_name_whatever_the_order() {
    let mut model = summing(W);
    model.outputs.reverse();
    let mut policy = OnnxPolicy::load(&model.write(), 3, 2).unwrap();
    policy.step(&[1.0, 0.0, 0.0]).unwrap();
    assert_eq!(policy.step(&[1.0, 0.0, 0.0]).unwrap(), [2.0, 4.0]);
}

fn refused(model: &Model, num_obs: usize, num_actions: usize) -> String {
    let error = OnnxPolicy::load(&model.write(), num_obs, num_actions).unwrap_err();
    assert!(matches!(error, ModelError::Shape { .. }), "{error:?}");
    let line = error.to_string();
    assert!(!line.contains('\n'), "{line}");
    line
}

#[test]
fn sizes_that_disagree_with_the_config_are_refused_naming_the_field() {
    let line = refused(&linear(W), 4, 2);
    assert!(line.ends_with("num_obs: the config says 4, input obs takes 3"), "{line}");
    let line = refused(&linear(W), 3, 12);
    assert!(line.ends_with("num_actions: the config says 12, output actions has shape [1, 2]"), "{line}");
}

#[test]
fn a_model_that_gives_no_finite_action_is_refused_at_load() {
    // actions = log(obs · w): −inf for the zero observation.
    let mut model = linear(W);
    model.nodes = vec![("MatMul", vec!["obs", "w"], vec!["a"]), ("Log", vec!["a"], vec!["actions"])];
    let line = refused(&model, 3, 2);
    assert!(line.ends_with("the test inference gave actions that are not finite"), "{line}");
}

#[test]
fn a_file_that_is_not_onnx_is_one_line() {
    let path = std::env::temp_dir().join(format!("robowire-policy-{}-garbage.onnx", std::process::id()));
    std::fs::write(&path, b"\xff\xfe not a model").unwrap();
    let error = OnnxPolicy::load(&path, 3, 2).unwrap_err();
    assert!(matches!(error, ModelError::Load { .. }), "{error:?}");
    assert!(!error.to_string().contains('\n'), "{error}");
    let missing = OnnxPolicy::load(&path.with_extension("absent"), 3, 2).unwrap_err();
    assert!(missing.to_string().contains("absent"), "{missing}");
}

#[test]
fn an_observation_of_the_wrong_length_is_an_error() {
    let mut policy = OnnxPolicy::load(&linear(W).write(), 3, 2).unwrap();
    assert!(matches!(policy.step(&[1.0; 4]), Err(ModelError::Observation { expected: 3, found: 4 })));
}
