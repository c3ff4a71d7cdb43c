//! `robowire sim go2|g1 --physics` (feature `mujoco`) driven by Unitree's own software,
//! unchanged: the Go2 stand example stands the physics Go2 up and lays it down (its body height
//! from `rt/sportmodestate`, watched by an observer on Unitree's SDK,
//! `physics_interop/observe_body.py`); `robowire go2 stand` ends in the damping of
//! `robowire go2 damp`, under which the robot sinks; the G1 low-level example brings the
//! hanging physics G1 to its zero posture and swings its ankles. Each where loopback carries
//! multicast (`robowire_dds::netns`). `robowire status sim:go2 --physics` reads a LowState of
//! the body in MuJoCo. The sans-IO physics checks (a tenth of the gains, the damped and silent
//! robot, a user's model) are robowire-sim's `tests/physics.rs`; `sim:go2` and `sim:g1` with
//! physics by address, robowire-devices' `tests/physics.rs`. Unitree's G1 walking policy on the
//! free physics G1: [`walk`].

#[path = "../it/support.rs"]
mod support;
mod walk;

use serde_json::Value;
use support::{Running, observer_summary, robowire, start_example, start_observer, with_unitree_examples};

/// `robowire sim ROBOT --physics --interface lo`, started and waited for.
fn start_sim(robot: &str) -> Running {
    let sim = Running::start(&["sim", robot, "--physics", "--interface", "lo", "--report-every-s", "0"]);
    assert!(sim.first_line.starts_with(&format!("{robot} domain 0 lo")), "{}", sim.first_line);
    sim
}

/// The observer's phase `name`: (samples, lowest, highest, last) body height, m.
fn phase(seen: &Value, name: &str) -> (u64, f64, f64, f64) {
    let p = &seen["phases"][name];
    let f = |key: &str| p[key].as_f64().unwrap_or_else(|| panic!("no {name}.{key} in {seen}"));
    (p["samples"].as_u64().unwrap_or(0), f("min"), f("max"), f("last"))
}

/// Closes the observer's stdin (it then prints its summary) and reads the summary.
fn finish(mut observer: (std::process::Child, std::io::BufReader<std::process::ChildStdout>)) -> Value {
    drop(observer.0.stdin.take());
    observer_summary(observer.0, observer.1)
}

#[test]
fn unitree_go2_stand_example_stands_the_physics_go2_and_lays_it_down() {
    with_unitree_examples(robowire_fixtures::peers::unitree_go2_examples, |python, examples| {
        let sim = start_sim("go2");
        let observer = start_observer(python, "tests/physics_interop/observe_body.py", &["lo"]);
        let example = start_example(python, examples, "go2_stand_example.py");
        let out = example.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(stdout.contains("Done!"), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
        let seen = finish(observer);
        assert_eq!(seen["timed_out"], false, "{seen}");
        // Its third stage holds the stand pose for 2 s (1000 commands), its last one lies down
        // and holds that pose until it prints Done! a second later.
        let stand = phase(&seen, "stand");
        let lie = phase(&seen, "lie");
        eprintln!("stand: {stand:?}; lie: {lie:?}");
        assert!(stand.0 > 500, "body states through the hold: {seen}");
        assert!(stand.1 > 0.25, "the body stays above 0.25 m through the hold: {stand:?}");
        assert!(lie.0 > 100 && lie.3 < 0.15, "lying after the last stage, below 0.15 m: {lie:?}");
        let log = sim.interrupt().stdout;
        let last = log.lines().last().unwrap_or_default();
        assert!(last.contains("bad CRC 0 bad head 0"), "every LowCmd had Unitree's CRC: {last}");
    });
}

#[test]
fn a_standing_physics_go2_sinks_under_robowire_go2_damp() {
    with_unitree_examples(robowire_fixtures::peers::unitree_go2_examples, |python, _| {
        let _sim = start_sim("go2");
        let observer = start_observer(python, "tests/physics_interop/observe_body.py", &["lo"]);
        // `stand` ends with the damping `robowire go2 damp` sends (kp 0, kd 1, for 0.5 s).
        let out = robowire()
            .args(["go2", "--interface", "lo", "stand", "--duration", "1.5", "--hold", "1.5"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let seen = finish(observer);
        let (stand, damp) = (phase(&seen, "stand"), phase(&seen, "damp"));
        eprintln!("stand: {stand:?}; damp: {damp:?}");
        assert!(stand.1 > 0.25, "standing through the hold: {stand:?}");
        assert!(damp.1 < 0.15, "sinks under the damping: {damp:?}");
    });
}

#[test]
fn unitree_g1_low_level_example_brings_the_hanging_physics_g1_to_its_zero_posture() {
    with_unitree_examples(robowire_fixtures::peers::unitree_g1_examples, |python, examples| {
        let sim = start_sim("g1");
        let observer = start_observer(python, "tests/g1_interop/observe_lowstate.py", &["lo", "low_level_hanging"]);
        let mut example = start_example(python, &examples.join("low_level"), "g1_low_level_example.py");
        // The observer ends once the AB stage swung the ankle's A motor; the example never ends.
        let seen = observer_summary(observer.0, observer.1);
        let _ = example.kill();
        let out = example.wait_with_output().unwrap();
        let context = format!("{seen}\nexample: {}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(seen["timed_out"], false, "{context}");
        assert_eq!(seen["bad_crc"], 0, "every LowState passes Unitree's CRC: {context}");
        // The zero posture: every joint within 0.05 rad, the waist pitch (the upper body on the
        // example's kp 40) within 0.35; then the ankles swing in PR and AB.
        let zero: Vec<f64> = seen["zero"]["q"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        eprintln!("zero posture at state {}: {zero:?}", seen["zero"]["sample"]);
        let ab = &seen["ab"];
        let (min, max) = (ab["min"][5].as_f64().unwrap(), ab["max"][5].as_f64().unwrap());
        assert!(max > 0.3 && min < -0.3, "{ab}");
        let log = sim.interrupt().stdout;
        assert!(log.contains("ReleaseMode: sport mode \"ai\" released"), "{log}");
    });
}

#[test]
fn robowire_status_sim_go2_physics_reads_the_body_in_mujoco() {
    // The CLI finds multicast on loopback for its simulator and client itself.
    let out = robowire().args(["status", "sim:go2", "--physics", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let state: Value = serde_json::from_slice(&out.stdout).unwrap();
    // The kinematic body has no feet on a floor and holds its lying pose exactly (hips at 0).
    let feet: Vec<u64> = state["foot_force"].as_array().unwrap().iter().map(|f| f.as_u64().unwrap()).collect();
    assert!(feet.iter().all(|f| *f > 0), "MuJoCo's contacts on every foot: {feet:?}");
    let hip = state["motor_state"][0]["q"].as_f64().unwrap();
    assert!(hip.abs() > 0.01, "the FR hip splays under the body's weight: {hip}");
}
