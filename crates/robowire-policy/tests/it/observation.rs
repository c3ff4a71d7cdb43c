//! The observation against vectors computed by hand: frames, the joint mapping, the phase.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use robowire_policy::observation::{ObserveError, gait_phase, projected_gravity, roll_pitch_rad, torso_to_pelvis};
use robowire_policy::{Observer, PolicyConfig, Sensed};

use crate::config::{G1_YAML, GO2_YAML};

const LEVEL: [f32; 4] = [1.0, 0.0, 0.0, 0.0];

fn close(found: &[f32], expected: &[f32]) {
    assert_eq!(found.len(), expected.len(), "{found:?}");
    for (i, (f, e)) in found.iter().zip(expected).enumerate() {
        assert!((f - e).abs() < 1e-6, "[{i}]: {f} against {e}\n{found:?}");
    }
}

/// Motor `m` at `m / 100` rad, turning at `m` rad/s.
fn motors(n: usize) -> (Vec<f32>, Vec<f32>) {
    ((0..n).map(|m| m as f32 / 100.0).collect(), (0..n).map(|m| m as f32).collect())
}

#[test]
fn the_g1_observation_is_deploy_reals() {
    let config = PolicyConfig::parse(G1_YAML).unwrap();
    let mut observer = Observer::new(&config);
    let (q, dq) = motors(35);
    let sensed = Sensed {
        quaternion_wxyz: LEVEL,
        gyroscope_rad_s: [0.4, -0.8, 1.2],
        base_velocity_world_m_s: None,
        motor_q_rad: &q,
        motor_dq_rad_s: &dq,
    };
    let default = [-0.1, 0.0, 0.0, 0.3, -0.2, 0.0, -0.1, 0.0, 0.0, 0.3, -0.2, 0.0];
    let mut expected = vec![0.1, -0.2, 0.3, 0.0, 0.0, -1.0];
    // (2, −1, 5) clamped to max_cmd (0.8, 0.5, 1.57), × cmd_scale (2, 2, 0.25).
    expected.extend([1.6, -1.0, 0.3925]);
    expected.extend((0..12).map(|k| k as f32 / 100.0 - default[k]));
    expected.extend((0..12).map(|k| k as f32 * 0.05));
    expected.extend([0.0; 12]);
    // sin, cos of 2π · 0.02 / 0.8.
    expected.extend([0.156_434_47, 0.987_688_34]);
    close(observer.observe(&sensed, [2.0, -1.0, 5.0]).unwrap(), &expected);

    // The raw actions come back as the last action; the phase moves on a step.
    let action: Vec<f32> = (0..12).map(|k| k as f32 - 6.0).collect();
    observer.act(&action);
    let obs = observer.observe(&sensed, [0.0; 3]).unwrap();
    close(&obs[33..45], &action);
    close(&obs[45..], &[0.309_017, 0.951_056_5]);
    assert_eq!(observer.steps(), 2);
    observer.reset();
    close(
        &observer.observe(&sensed, [0.0; 3]).unwrap()[33..],
        &[[0.0; 12].as_slice(), &[0.156_434_47, 0.987_688_34]].concat(),
    );
}

#[test]
fn a_go2_policys_legs_are_mapped_and_its_velocity_turned_into_the_body() {
    let config = PolicyConfig::parse(GO2_YAML).unwrap();
    let mut observer = Observer::new(&config);
    let (q, dq) = motors(20);
    // Facing +y (yaw 90°), moving along +x of the world: to the robot's right.
    let yaw_90 = [FRAC_1_SQRT_2 as f32, 0.0, 0.0, FRAC_1_SQRT_2 as f32];
    let sensed = Sensed {
        quaternion_wxyz: yaw_90,
        gyroscope_rad_s: [0.0; 3],
        base_velocity_world_m_s: Some([1.0, 0.0, 0.0]),
        motor_q_rad: &q,
        motor_dq_rad_s: &dq,
    };
    let obs = observer.observe(&sensed, [0.0; 3]).unwrap().to_vec();
    close(&obs[0..3], &[0.0, -2.0, 0.0]);
    close(&obs[6..9], &[0.0, 0.0, -1.0]);
    // FL first: the SDK's motors 3, 4, 5; then FR 0, 1, 2; RL 9, 10, 11; RR 6, 7, 8.
    let motor = [3, 4, 5, 0, 1, 2, 9, 10, 11, 6, 7, 8];
    let default = [0.1, 0.8, -1.5, -0.1, 0.8, -1.5, 0.1, 1.0, -1.5, -0.1, 1.0, -1.5];
    close(&obs[12..24], &(0..12).map(|k| motor[k] as f32 / 100.0 - default[k]).collect::<Vec<_>>());
    close(&obs[24..36], &motor.map(|m| m as f32 * 0.05));
    assert_eq!(obs.len(), 48);

    let unknown = Sensed { base_velocity_world_m_s: None, ..sensed };
    assert_eq!(observer.observe(&unknown, [0.0; 3]), Err(ObserveError::NoBaseVelocity));
    let few = [0.0; 4];
    let short = Sensed { motor_q_rad: &few, ..sensed };
    assert_eq!(observer.observe(&short, [0.0; 3]), Err(ObserveError::Motor { motor: 4, motors: 4 }));
}

#[test]
fn gravity_and_tilt_from_the_quaternion() {
    assert_eq!(projected_gravity([1.0, 0.0, 0.0, 0.0]), [0.0, 0.0, -1.0]);
    // Rolled 90° about x: gravity along the body's −y.
    let g = projected_gravity([FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.0, 0.0]);
    assert!((g[0]).abs() < 1e-12 && (g[1] + 1.0).abs() < 1e-12 && g[2].abs() < 1e-12, "{g:?}");
    let (roll, pitch) = roll_pitch_rad(g);
    assert!((roll - PI / 2.0).abs() < 1e-9 && pitch.abs() < 1e-9, "{roll} {pitch}");
    // Pitched 0.3 rad nose down about y.
    let (s, c) = (0.15f64.sin(), 0.15f64.cos());
    let (roll, pitch) = roll_pitch_rad(projected_gravity([c, 0.0, s, 0.0]));
    assert!(roll.abs() < 1e-9 && (pitch - 0.3).abs() < 1e-9, "{roll} {pitch}");
}

#[test]
fn the_phase_runs_from_the_first_step_and_wraps_each_period() {
    let [sin, cos] = gait_phase(20, 0.02, 0.8);
    assert!(sin.abs() < 1e-9 && (cos + 1.0).abs() < 1e-9);
    let (first, after) = (gait_phase(1, 0.02, 0.8), gait_phase(41, 0.02, 0.8));
    assert!((first[0] - after[0]).abs() < 1e-9 && (first[1] - after[1]).abs() < 1e-9);
}

#[test]
fn a_torso_imu_is_turned_into_the_pelvis_frame() {
    // Torso level, waist turned 90°: the pelvis is turned −90° under it.
    let (pelvis, gyro) = torso_to_pelvis([1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0], PI / 2.0, 0.5);
    let expected = [FRAC_1_SQRT_2, 0.0, 0.0, -FRAC_1_SQRT_2];
    assert!(pelvis.iter().zip(expected).all(|(p, e)| (p - e).abs() < 1e-12), "{pelvis:?}");
    assert!((gyro[0]).abs() < 1e-12 && (gyro[1] - 1.0).abs() < 1e-12 && (gyro[2] + 0.5).abs() < 1e-12, "{gyro:?}");
    // Torso turned by the waist alone: the pelvis is level.
    let (s, c) = (0.15f64.sin(), 0.15f64.cos());
    let (pelvis, _) = torso_to_pelvis([c, 0.0, 0.0, s], [0.0; 3], 0.3, 0.0);
    assert!((pelvis[0].abs() - 1.0).abs() < 1e-12, "{pelvis:?}");
}
