//! `robowire sim g1` driven by Unitree's own software: the G1 examples of
//! `unitree_sdk2_python`, unchanged, on CycloneDDS (see `robowire_fixtures::peers`), watched by
//! a small observer on Unitree's SDK (`g1_interop/observe_lowstate.py`: Unitree's CRC of every
//! `rt/lowstate` sample, the joints by phase). Each where loopback carries multicast
//! (`robowire_dds::netns`).

use std::io::BufReader;
use std::path::Path;
use std::process::{Child, Stdio};

use robowire_dds::netns::with_loopback_multicast;
use serde_json::Value;

use crate::support::{Running, robowire, start_example, with_unitree_examples};

/// The stand pose of the simulator's controller, by slot (unitree_rl_gym's default angles).
const STAND: [f64; 12] = [-0.1, 0.0, 0.0, 0.3, -0.2, 0.0, -0.1, 0.0, 0.0, 0.3, -0.2, 0.0];

/// `robowire sim g1 --interface lo`, started and waited for.
fn start_sim() -> Running {
    let sim = Running::start(&["sim", "g1", "--interface", "lo", "--report-every-s", "0"]);
    assert!(sim.first_line.starts_with("g1 domain 0 lo dof 29 mode_machine 5"), "{}", sim.first_line);
    sim
}

/// The observer on `lo` in `mode`, once it saw a first state.
fn start_observer(python: &Path, mode: &str) -> (Child, BufReader<std::process::ChildStdout>) {
    crate::support::start_observer(python, "tests/g1_interop/observe_lowstate.py", &["lo", mode])
}

fn f64s(value: &Value) -> Vec<f64> {
    value.as_array().unwrap_or_else(|| panic!("not an array: {value}")).iter().map(|v| v.as_f64().unwrap()).collect()
}

/// The number after `name` in the sim's last line (`lowcmd accepted N …`).
fn number(last: &str, name: &str) -> f64 {
    let rest = last.split(name).nth(1).unwrap_or_else(|| panic!("no {name:?} in {last}"));
    rest.split_whitespace().next().and_then(|n| n.trim_end_matches([';', ',']).parse().ok()).unwrap()
}

/// A counter of the sim's last line.
fn counter(last: &str, name: &str) -> u64 {
    number(last, name) as u64
}

#[test]
fn unitree_g1_low_level_example_runs_unchanged_against_the_simulator() {
    with_unitree_examples(robowire_fixtures::peers::unitree_g1_examples, |python, examples| {
        let sim = start_sim();
        let (observer, observed) = start_observer(python, "low_level");
        let mut example = start_example(python, &examples.join("low_level"), "g1_low_level_example.py");
        // The observer ends once the example's third (AB) stage swung the ankle; the example
        // itself never ends.
        let seen = crate::support::observer_summary(observer, observed);
        let _ = example.kill();
        let out = example.wait_with_output().unwrap();
        let context = format!("{seen}\nexample: {}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(seen["timed_out"], false, "{context}");
        assert_eq!(seen["bad_crc"], 0, "every LowState passes Unitree's CRC: {context}");
        assert!(seen["samples"].as_u64().unwrap() > 1000, "{context}");
        assert_eq!(seen["mode_machine"], serde_json::json!([5]));
        let first = f64s(&seen["first"]);
        assert!(first[..12].iter().zip(STAND).all(|(q, s)| (q - s).abs() < 1e-6), "booted standing: {first:?}");

        // Stage 1 (3 s): every joint to zero. Stage 2 (PR): only the ankles move, pitch ±30°,
        // roll ±10°, left and right pitch together, roll mirrored; every other joint stays at 0.
        let zero = f64s(&seen["zero"]["q"]);
        assert!(zero.iter().all(|q| q.abs() < 0.05), "{zero:?}");
        let pr = &seen["pr"];
        let (min, max) = (f64s(&pr["min"]), f64s(&pr["max"]));
        for slot in (0..29).filter(|s| ![4, 5, 10, 11].contains(s)) {
            assert!(min[slot] > -0.05 && max[slot] < 0.05, "slot {slot} moved in stage 2: {min:?} {max:?}");
        }
        for pitch in [4, 10] {
            assert!(max[pitch] > 0.45 && min[pitch] < -0.45, "ankle pitch ±0.52: {} {}", min[pitch], max[pitch]);
        }
        for roll in [5, 11] {
            assert!(max[roll] > 0.15 && min[roll] < -0.15, "ankle roll ±0.17: {} {}", min[roll], max[roll]);
        }
        assert!(pr["max_abs"]["pitch_difference"].as_f64().unwrap() < 0.05, "{pr}");
        assert!(pr["max_abs"]["roll_sum"].as_f64().unwrap() < 0.05, "{pr}");
        // Stage 3 (AB): the state reports the A and B motors; A swings, the wrist rolls too.
        let ab = &seen["ab"];
        let (min, max) = (f64s(&ab["min"]), f64s(&ab["max"]));
        assert!(max[5] > 0.3 && min[5] < -0.3 && max[19] > 0.3, "{ab}");
        eprintln!(
            "observed {} states, bad CRC 0; zero at state {}; PR: L ankle pitch {:+.3}..{:+.3} roll {:+.3}..{:+.3}; \
             AB: A {:+.3}..{:+.3}",
            seen["samples"],
            seen["zero"]["sample"],
            pr["min"][4].as_f64().unwrap_or(f64::NAN),
            pr["max"][4].as_f64().unwrap_or(f64::NAN),
            pr["min"][5].as_f64().unwrap_or(f64::NAN),
            pr["max"][5].as_f64().unwrap_or(f64::NAN),
            min[5],
            max[5]
        );

        let log = sim.interrupt().stdout;
        assert!(log.contains("ReleaseMode: sport mode \"ai\" released"), "{log}");
        let last = log.lines().last().unwrap_or_default();
        eprintln!("sim: {}", last.split("; final").next().unwrap_or_default());
        assert!(counter(last, "lowcmd accepted ") > 2000, "the example's 500 Hz LowCmds were accepted: {last}");
        assert_eq!(counter(last, "bad CRC "), 0, "{last}");
        assert_eq!(counter(last, "bad mode_machine "), 0, "the example copied mode_machine 5: {last}");
        assert_eq!(counter(last, "disabled motors "), 0, "{last}");
    });
}

#[test]
fn unitree_g1_arm_sdk_example_lifts_the_arms_on_the_simulator() {
    with_unitree_examples(robowire_fixtures::peers::unitree_g1_examples, |python, examples| {
        let sim = start_sim();
        let (mut observer, observed) = start_observer(python, "arm");
        let example = start_example(python, &examples.join("high_level"), "g1_arm7_sdk_dds_example.py");
        // It lowers the weight to 0 in its last stage, prints "Done!" and exits (with -1).
        let out = example.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(stdout.contains("Done!"), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
        drop(observer.stdin.take());
        let seen = crate::support::observer_summary(observer, observed);
        assert_eq!((seen["timed_out"].as_bool(), seen["bad_crc"].as_u64()), (Some(false), Some(0)), "{seen}");
        // Stage 2: the left shoulder roll and both elbows to π/2, the right shoulder roll to −π/2.
        let all = &seen["all"];
        let (min, max) = (f64s(&all["min"]), f64s(&all["max"]));
        for slot in [16, 18, 25] {
            assert!(max[slot] > 1.4, "slot {slot} lifted: {}", max[slot]);
        }
        assert!(min[23] < -1.4, "right shoulder roll: {}", min[23]);
        eprintln!(
            "observed {} states, bad CRC 0; max L shoulder roll {:+.3}, elbows {:+.3} {:+.3}, min R shoulder roll {:+.3}",
            seen["samples"], max[16], max[18], max[25], min[23]
        );
        // Then back to zero; the legs stayed the controller's all along.
        let last = f64s(&seen["last"]);
        assert!(last[15..29].iter().all(|q| q.abs() < 0.05), "arms back: {last:?}");
        for (slot, stand) in STAND.iter().enumerate() {
            assert!((min[slot] - stand).abs() < 0.01 && (max[slot] - stand).abs() < 0.01, "leg slot {slot} moved");
        }

        let log = sim.interrupt().stdout;
        assert!(!log.contains("ReleaseMode"), "the example never releases: {log}");
        let last = log.lines().last().unwrap_or_default();
        eprintln!("sim: {}", last.split("; final").next().unwrap_or_default());
        assert!(counter(last, "arm_sdk accepted ") > 500, "its 50 Hz frames for 21 s: {last}");
        assert_eq!(counter(last, "unsealed "), 0, "Unitree's Python example seals them: {last}");
        // Its last frames say 1 − 0.993; silent, the weight decays from there to 0.
        assert!(number(last, "weight ") <= 0.01, "the example lowered the weight to 0: {last}");
    });
}

/// One `rt/lowstate` sample as `robowire dds echo` prints it (JSON).
fn one_state() -> Value {
    let echo = robowire().args(["dds", "--interface", "lo", "echo", "rt/lowstate", "--count", "1"]).output().unwrap();
    let text = String::from_utf8_lossy(&echo.stdout);
    serde_json::from_str(text.lines().next().unwrap_or_default()).unwrap_or_else(|e| panic!("{e}: {text}"))
}

#[test]
fn sim_g1_takes_its_variant_and_warns_about_a_mode_machine_it_does_not_know() {
    with_loopback_multicast(|| {
        let sim = Running::start(&["sim", "g1", "--interface", "lo", "--dof", "23", "--report-every-s", "0"]);
        assert!(sim.first_line.starts_with("g1 domain 0 lo dof 23 mode_machine 4"), "{}", sim.first_line);
        let state = one_state();
        assert_eq!(state["mode_machine"], 4, "{state}");
        assert_eq!(state["motor_state"][13]["mode"], 0, "no waist roll on the 23-dof G1: {state}");
        let log = sim.interrupt().stdout;
        assert!(log.contains("booted standing (Dof23, mode_machine 4)"), "{log}");
        let odd = Running::spawn(
            robowire().args(["sim", "g1", "--interface", "lo", "--mode-machine", "9"]).stderr(Stdio::piped()),
        );
        assert!(odd.first_line.ends_with("dof 29 mode_machine 9"), "{}", odd.first_line);
        assert_eq!(one_state()["mode_machine"], 9);
        let ended = odd.interrupt();
        assert!(ended.stderr.contains("warning: mode_machine 9 names a DualArm G1"), "{}", ended.stderr);
        let bad = robowire().args(["sim", "g1", "--dof", "12"]).output().unwrap();
        assert!(!bad.status.success());
        assert!(String::from_utf8_lossy(&bad.stderr).contains("possible values: 29, 23"));
    });
}
