//! The deploy sequence and its faults, on caller time, with a tiny model.

use std::time::Duration;

use robowire_core::schedule::Time;
use robowire_policy::control::{HOLD_S, STAND_S};
use robowire_policy::{Controller, Fault, OnnxPolicy, Phase, PolicyConfig, Sensed, Tick};

use crate::config::G1_YAML;
use robowire_policy::tiny::Model;

/// actions = sqrt(obs[0]) on each of the 12 joints: obs[0] is the gyroscope's x × 0.25, so a
/// negative rate makes every action NaN.
fn controller() -> (Controller, PolicyConfig) {
    let config = PolicyConfig::parse(G1_YAML).unwrap();
    let mut w = vec![0.0; 47 * 12];
    w[..12].fill(1.0);
    let model = Model {
        inputs: vec![("obs", vec![1, 47])],
        weight: (vec![47, 12], w),
        nodes: vec![("MatMul", vec!["obs", "w"], vec!["a"]), ("Sqrt", vec!["a"], vec!["actions"])],
        outputs: vec![("actions", vec![1, 12])],
    };
    let policy = OnnxPolicy::load(&model.write(), 47, 12).unwrap();
    // Ankle rolls (slots 5 and 11) within ±0.1 rad.
    let range = |motor: usize| [5, 11].contains(&motor).then_some((-0.1, 0.1));
    (Controller::new(&config, policy, range), config)
}

const ZEROS: [f32; 35] = [0.0; 35];
const FRESH: Duration = Duration::from_millis(2);

fn level(gyro_x: f32) -> Sensed<'static> {
    Sensed {
        quaternion_wxyz: [1.0, 0.0, 0.0, 0.0],
        gyroscope_rad_s: [gyro_x, 0.0, 0.0],
        base_velocity_world_m_s: None,
        motor_q_rad: &ZEROS,
        motor_dq_rad_s: &ZEROS,
    }
}

fn at(s: f64) -> Time {
    Time::ZERO + Duration::from_secs_f64(10.0 + s)
}

fn targets(tick: Tick<'_>) -> Vec<f32> {
    match tick {
        Tick::Command(targets) => targets.iter().map(|t| t.q_rad).collect(),
        Tick::Damp(fault) => panic!("damped: {fault}"),
    }
}

#[test]
fn stand_hold_then_walk_as_deploy_real() {
    let (mut c, config) = controller();
    let sensed = level(4.0);
    c.start(at(0.0), &sensed, true);
    assert_eq!(c.phase(), Phase::Standing);
    // Halfway there: half the default pose, from zeros; legs first, then waist and arms.
    let half = targets(c.tick(at(STAND_S / 2.0), Some((&sensed, FRESH)), [0.0; 3]));
    assert_eq!(half.len(), 29);
    let expected: Vec<f32> = config.default_angles.iter().map(|d| d * 0.5).collect();
    assert!(half[..12].iter().zip(&expected).all(|(h, e)| (h - e).abs() < 1e-6), "{half:?}");
    let held = targets(c.tick(at(STAND_S), Some((&sensed, FRESH)), [0.0; 3]));
    assert_eq!(&held[..12], config.default_angles.as_slice());
    assert_eq!(c.phase(), Phase::Holding);
    targets(c.tick(at(STAND_S + HOLD_S), Some((&sensed, FRESH)), [0.0; 3]));
    assert_eq!(c.phase(), Phase::Walking);
    // sqrt(4 × 0.25) = 1 on every joint: target = 1 × 0.25 + default.
    let walking = targets(c.tick(at(STAND_S + HOLD_S + 0.02), Some((&sensed, FRESH)), [0.3, 0.0, 0.0]));
    // The ankle rolls' 0.25 clamped to their 0.1.
    let expected: Vec<f32> =
        config.default_angles.iter().enumerate().map(|(j, d)| if j % 6 == 5 { 0.1 } else { 0.25 + d }).collect();
    assert!(walking[..12].iter().zip(&expected).all(|(w, e)| (w - e).abs() < 1e-6), "{walking:?}");
    assert_eq!(&walking[12..], config.arm_waist_target.as_slice());
    let report = c.report();
    assert_eq!((report.step, report.action[0], report.command, report.clamped), (1, 1.0, [0.3, 0.0, 0.0], 2));
    assert_eq!(report.obs[6], 0.6);
}

#[test]
fn a_nan_action_damps_at_that_tick() {
    let (mut c, _) = controller();
    c.start(at(0.0), &level(4.0), false);
    targets(c.tick(at(0.02), Some((&level(4.0), FRESH)), [0.0; 3]));
    match c.tick(at(0.04), Some((&level(-1.0), FRESH)), [0.0; 3]) {
        Tick::Damp(Fault::NotFinite { joint: 0, value }) => assert!(value.is_nan()),
        other => panic!("{other:?}"),
    }
    assert_eq!(c.phase(), Phase::Damped);
    assert_eq!(c.tick(at(0.06), Some((&level(4.0), FRESH)), [0.0; 3]), Tick::Damp(Fault::Stopped));
}

#[test]
fn a_stale_or_missing_state_damps_in_every_phase() {
    let (mut c, _) = controller();
    c.start(at(0.0), &level(4.0), true);
    assert_eq!(
        c.tick(at(0.5), Some((&level(4.0), Duration::from_millis(101))), [0.0; 3]),
        Tick::Damp(Fault::StaleState { age_ms: 101 })
    );
    let (mut c, _) = controller();
    c.start(at(0.0), &level(4.0), false);
    assert_eq!(c.tick(at(0.02), None, [0.0; 3]), Tick::Damp(Fault::StaleState { age_ms: u64::MAX }));
}

#[test]
fn a_tilt_past_the_limit_damps() {
    let (mut c, _) = controller();
    c.start(at(0.0), &level(4.0), false);
    // Rolled 1.2 rad about x (the limit is 1.0).
    let (s, co) = (0.6f32.sin(), 0.6f32.cos());
    let rolled = Sensed { quaternion_wxyz: [co, s, 0.0, 0.0], ..level(4.0) };
    match c.tick(at(0.02), Some((&rolled, FRESH)), [0.0; 3]) {
        Tick::Damp(Fault::Tilt { roll_rad, limit_rad, .. }) => {
            assert!((roll_rad - 1.2).abs() < 1e-5 && limit_rad == 1.0, "{roll_rad}")
        }
        other => panic!("{other:?}"),
    }
}
