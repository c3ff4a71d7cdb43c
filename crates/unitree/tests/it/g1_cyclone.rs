//! The G1 client against CycloneDDS itself (the `cyclonedds` Python binding 0.10.2 with
//! Unitree's HG IDL classes and CRC, in CPython 3.10; see `robowire_fixtures::peers`), where
//! loopback carries multicast (`robowire_dds::netns`): Unitree's code publishes a LowState with
//! mode_machine 5, our client reads it (its CRC checked) and streams a known `set_joints` pattern,
//! which arrives field for field with the robot's mode_machine and a CRC Unitree's code accepts;
//! then the client's damping, mode_machine kept.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use robowire_dds::netns::with_loopback_multicast;
use robowire_fixtures::wait::one_at_a_time;
use serde_json::Value;
use unitree::g1::{CommandError, Device, G1, G1Error, G1Options, JOINTS};

use crate::common::{WAIT, pattern};

fn f32s(value: &Value) -> Vec<f32> {
    value.as_array().unwrap().iter().map(|v| v.as_f64().unwrap() as f32).collect()
}

#[test]
fn cyclonedds_robot_gets_our_lowcmds_field_for_field_with_unitree_crc_and_its_mode_machine() {
    // Alone, as when it was a binary of its own: no simulator of the other modules beside
    // CycloneDDS's robot on the two cores, nor on its domain.
    let _turn = one_at_a_time();
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let g1 = G1::open(G1Options::on(Some("lo"), 0)).expect("client");
            let joints = pattern();
            assert!(matches!(g1.set_joints(&joints), Err(G1Error::Command(CommandError::NoModeMachine))));

            let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop/cyclone_hg_robot.py");
            let mut child = Command::new(&python)
                .arg(&script)
                .arg("lo")
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("running Python");
            // The script's lines, as they come.
            let (lines_tx, lines) = std::sync::mpsc::channel();
            let stdout = child.stdout.take().unwrap();
            let reading = std::thread::spawn(move || {
                for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                    let _ = lines_tx.send(line);
                }
            });

            let state = g1.wait_state(WAIT, |s| s.mode_machine == 5).await;
            assert!(
                state.is_some(),
                "Unitree's HG LowState read, its CRC checked: {:?}",
                g1.stats().low_level.lowstate
            );
            assert_eq!(g1.mode_machine(), Some(5));
            // Refresh the pattern until the robot's side has enough of it, then stop: damping.
            let start = Instant::now();
            let mut output = Vec::new();
            loop {
                g1.set_joints(&joints).unwrap();
                if let Ok(line) = lines.try_recv() {
                    output.push(line);
                    break;
                }
                assert!(start.elapsed() < WAIT, "the robot's side did not see the pattern: {output:?}");
                tokio::time::sleep(Duration::from_millis(2)).await;
            }
            let status = child.wait().expect("the script");
            reading.join().unwrap();
            output.extend(lines.try_iter());
            let mut stderr = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
            assert!(status.success(), "{status}: {output:?}\n{stderr}");
            let last = output.last().map(String::as_str).unwrap_or_default();
            let summary: Value = serde_json::from_str(last).unwrap_or_else(|e| panic!("{e}: {output:?}"));
            eprintln!("cyclone_hg_robot.py: {summary}");

            assert_eq!(output.first().map(String::as_str), Some("pattern"));
            assert!(summary["lowcmds"].as_u64().unwrap() > 0);
            assert_eq!(summary["crc_bad"], 0, "every LowCmd's CRC is Unitree's: {summary}");
            assert_eq!(summary["crc_ok"], summary["lowcmds"]);
            assert_eq!(summary["mode_machines"], serde_json::json!([5]), "the robot's, in every LowCmd");
            assert!(summary["pattern_frames"].as_u64().unwrap() >= 200);
            assert!(summary["damping_frames"].as_u64().unwrap() >= 20);

            let sent = &summary["last_pattern"];
            assert_eq!((sent["mode_pr"].as_u64(), sent["mode_machine"].as_u64()), (Some(0), Some(5)));
            let expected = |f: fn(&unitree::g1::JointCommand) -> f32| -> Vec<f32> {
                joints.iter().map(f).chain(std::iter::repeat_n(0.0, 35 - JOINTS)).collect()
            };
            assert_eq!(f32s(&sent["q"]), expected(|j| j.q_rad), "bit for bit as f32");
            assert_eq!(f32s(&sent["dq"]), expected(|j| j.dq_radps));
            assert_eq!(f32s(&sent["kp"]), expected(|j| j.kp));
            assert_eq!(f32s(&sent["kd"]), expected(|j| j.kd));
            assert_eq!(f32s(&sent["tau"]), expected(|j| j.tau_nm));
            let modes: Vec<u64> = sent["mode"].as_array().unwrap().iter().map(|m| m.as_u64().unwrap()).collect();
            assert_eq!(modes, [vec![1; JOINTS], vec![0; 35 - JOINTS]].concat());
            assert!(sent["motor_reserve"].as_array().unwrap().iter().all(|r| r == 0));
            assert_eq!(sent["reserve"], serde_json::json!([0, 0, 0, 0]));

            let damping = &summary["last_damping"];
            assert_eq!(damping["mode_machine"], 5, "damping keeps the robot's mode_machine");
            assert_eq!(f32s(&damping["kd"]), [vec![1.0; JOINTS], vec![0.0; 35 - JOINTS]].concat());
            assert!(f32s(&damping["kp"]).iter().all(|&kp| kp == 0.0));
            assert_eq!(g1.stats().low_level.command_timeouts, 1);
        })
    });
}
