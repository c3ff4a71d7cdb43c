//! The real-time factor of robowire's MuJoCo models (feature `mujoco`): each body stepped as the
//! state stream steps it, 2 ms of simulated time per LowState (two 1 ms physics steps under the
//! 1 kHz motor model), the LowState built and encoded and `rt/sportmodestate` built, on one
//! thread, as fast as it goes; beside the kinematic joint model of the same robot in the same
//! loop. The Go2 holds its stand pose under Unitree's stand gains (from lying: the first
//! second stands it up), the G1 hangs at its zero posture under Unitree's example gains.
//! Figures (simulated seconds per wall second) to `ROBOWIRE_BENCH_META_PHYSICS` for
//! `cargo xtask bench`.

use std::time::Instant;

use robowire_core::cdr::CdrType;
use robowire_sim::g1::{G1Body, JOINTS as G1_JOINTS};
use robowire_sim::go2::{Go2Body, JOINTS, STAND_POSE_RAD};
use robowire_sim::physics::PhysicsOptions;
use serde_json::json;
use unitree_proto::g1::{self, G1Variant};
use unitree_proto::go2::MotorCmd;
use unitree_proto::{HgLowCmd, LowCmd};

const DT_S: f32 = 0.002;

/// Runs `tick` (one LowState period) for `sim_s` simulated seconds: simulated seconds per wall
/// second.
fn real_time_factor(sim_s: f32, mut tick: impl FnMut()) -> f64 {
    let ticks = (sim_s / DT_S).round() as u32;
    let start = Instant::now();
    for _ in 0..ticks {
        tick();
    }
    f64::from(sim_s) / start.elapsed().as_secs_f64()
}

/// The Go2 `body` standing: commanded, stepped, its states built and encoded, for `sim_s`.
fn go2(mut body: Go2Body, sim_s: f32) -> f64 {
    let mut stand = LowCmd::default();
    for (m, cmd) in stand.motor_cmd.iter_mut().take(JOINTS).enumerate() {
        *cmd = MotorCmd::servo(STAND_POSE_RAD[m % 3], 0.0, 60.0, 5.0, 0.0);
    }
    let mut buf = vec![0u8; body.low_state().body_len()];
    real_time_factor(sim_s, || {
        body.command(&stand);
        body.step(DT_S);
        let state = body.low_state();
        std::hint::black_box(state.encode_body(&mut buf).unwrap());
        std::hint::black_box(body.sport_state());
    })
}

/// The G1 `body` released and held at zero: commanded, stepped, its states built and encoded.
fn g1(mut body: G1Body, sim_s: f32) -> f64 {
    body.set_controller(false);
    let zero: HgLowCmd = g1::hold(&[0.0; G1_JOINTS], 5, G1Variant::Dof29);
    let mut buf = vec![0u8; body.low_state().body_len()];
    real_time_factor(sim_s, || {
        body.command(&zero);
        body.step(DT_S);
        let state = body.low_state();
        std::hint::black_box(state.encode_body(&mut buf).unwrap());
        std::hint::black_box(body.sport_state());
    })
}

fn main() {
    let sim_s = if std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some() { 5.0 } else { 20.0 };
    let variant = G1Variant::Dof29;
    let hanging = PhysicsOptions { hanging: true, ..PhysicsOptions::default() };
    let figures = json!({
        "sim_seconds": sim_s,
        "go2_physics_rtf": go2(Go2Body::physics(&PhysicsOptions::default()).expect("the Go2 model"), sim_s),
        "go2_kinematic_rtf": go2(Go2Body::new(), sim_s),
        "g1_physics_rtf": g1(G1Body::physics(variant, 5, &hanging).expect("the G1 model"), sim_s),
        "g1_kinematic_rtf": g1(G1Body::new(variant, 5), sim_s),
    });
    println!("{figures}");
    if let Some(path) = std::env::var_os("ROBOWIRE_BENCH_META_PHYSICS") {
        std::fs::write(path, figures.to_string()).expect("writing the bench metadata");
    }
}
