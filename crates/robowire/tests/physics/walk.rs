//! Unitree's G1 walking policy (`../shared/policies`: its ONNX and its own deploy config) on the
//! physics G1 (feature `mujoco`): `robowire sim g1 --physics --free-base` in one process,
//! `robowire policy run g1_walk.yaml --device g1:lo` in another, and the pelvis watched on
//! `rt/sportmodestate` by a participant of the test's own. A Go2 config (its observation starting
//! with the base's velocity from `rt/sportmodestate`) with a model that holds the default pose, on
//! `sim:go2 --physics` started by `policy run` itself. The policy as the simulators' own
//! locomotion (`robowire sim g1|go2 --physics --walk`): the G1 walked by Unitree's `LocoClient`
//! from its Python SDK (`physics_interop/loco_walk.py`) and by `cmd_vel` through
//! `robowire ros2`, the Go2 stood up by `sport` StandUp and laid down by Damp. Where loopback carries multicast (`robowire_dds::netns`).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::support::{Running, robowire, start_observer};
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_fixtures::{interop, peers};
use unitree_proto::sport_state::SportModeState;

/// The pelvis as `rt/sportmodestate` said: x, y, z (m) and yaw (rad), in order.
#[derive(Default)]
struct Track(Mutex<Vec<[f32; 4]>>);

/// Watches `rt/sportmodestate` on `lo` until `done`.
fn watch(done: Arc<AtomicBool>) -> (Arc<Track>, std::thread::JoinHandle<()>) {
    let track = Arc::new(Track::default());
    let thread = std::thread::spawn({
        let track = track.clone();
        move || {
            let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
            runtime.block_on(async {
                let options = ParticipantOptions { interface: Some("lo".into()), ..ParticipantOptions::default() };
                let participant = Participant::new(options).unwrap();
                let mut reader = participant.reader::<SportModeState>("rt/sportmodestate", Qos::READER).unwrap();
                while !done.load(Ordering::Acquire) {
                    if let Ok(Ok(sample)) = tokio::time::timeout(Duration::from_millis(100), reader.recv()).await {
                        let s = sample.value;
                        let [x, y, z] = s.position.map(|v| v.get());
                        track.0.lock().unwrap().push([x, y, z, s.imu_state.rpy[2].get()]);
                    }
                }
            });
        }
    });
    (track, thread)
}

/// Runs the policy at `cmd` for 10 s on a free physics G1; the pelvis's track.
fn walk(cmd: &str) -> Vec<[f32; 4]> {
    let Some(dir) = interop::require(peers::policies_dir()) else { return Vec::new() };
    let track = Arc::new(Mutex::new(Vec::new()));
    robowire_dds::netns::with_loopback_multicast(|| {
        let sim =
            Running::start(&["sim", "g1", "--physics", "--free-base", "--interface", "lo", "--report-every-s", "0"]);
        assert!(sim.first_line.starts_with("g1 domain 0 lo"), "{}", sim.first_line);
        let done = Arc::new(AtomicBool::new(false));
        let (seen, watcher) = watch(done.clone());
        let out = robowire()
            .args(["policy", "run"])
            .arg(dir.join("g1_walk.yaml"))
            .args(["--device", "g1:lo", "--cmd", cmd, "--duration", "10"])
            .output()
            .unwrap();
        done.store(true, Ordering::Release);
        watcher.join().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        eprintln!("{stderr}");
        assert!(out.status.success() && stderr.contains("ended: the duration ran out"), "{stderr}");
        *track.lock().unwrap() = std::mem::take(&mut *seen.0.lock().unwrap());
        drop(sim);
    });
    std::mem::take(&mut *track.lock().unwrap())
}

/// The lowest pelvis on the track, m.
fn lowest(track: &[[f32; 4]]) -> f32 {
    track.iter().map(|p| p[2]).fold(f32::MAX, f32::min)
}

#[test]
fn unitrees_g1_policy_walks_the_physics_g1_forward() {
    let track = walk("0.5,0,0");
    let (Some(first), Some(last)) = (track.first(), track.last()) else { return };
    let forward = last[0] - first[0];
    eprintln!("{} states: from {first:?} to {last:?}, lowest {:.3} m", track.len(), lowest(&track));
    assert!(track.len() > 1000, "rt/sportmodestate through the run: {}", track.len());
    assert!(forward >= 2.0, "walked {forward:.2} m forward in 10 s at 0.5 m/s");
    assert!(lowest(&track) >= 0.5, "the pelvis stayed above 0.5 m: {:.3}", lowest(&track));
}

#[test]
fn unitrees_g1_policy_turns_the_physics_g1_in_place() {
    let track = walk("0,0,0.5");
    let (Some(first), Some(last)) = (track.first(), track.last()) else { return };
    // The yaw unwrapped along the track.
    let turned: f32 = track
        .windows(2)
        .map(|w| {
            let d = w[1][3] - w[0][3];
            (d + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI
        })
        .sum();
    let moved = ((last[0] - first[0]).powi(2) + (last[1] - first[1]).powi(2)).sqrt();
    eprintln!("turned {turned:.2} rad, moved {moved:.2} m, lowest {:.3} m", lowest(&track));
    assert!(turned >= 2.0, "turned {turned:.2} rad in 10 s at 0.5 rad/s");
    assert!(lowest(&track) >= 0.5, "the pelvis stayed above 0.5 m: {:.3}", lowest(&track));
}

/// unitree_rl_gym's Go2 deploy values; the observation starts with the base's velocity.
const GO2_YAML: &str = "control_dt: 0.02\nmsg_type: go\npolicy_path: zeros.onnx\n\
leg_joint2motor_idx: [3, 4, 5, 0, 1, 2, 9, 10, 11, 6, 7, 8]\nkps: [20, 20, 20, 20, 20, 20, 20, 20, 20, 20, 20, 20]\n\
kds: [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5]\n\
default_angles: [0.1, 0.8, -1.5, -0.1, 0.8, -1.5, 0.1, 1.0, -1.5, -0.1, 1.0, -1.5]\n\
lin_vel_scale: 2.0\nang_vel_scale: 0.25\ndof_pos_scale: 1.0\ndof_vel_scale: 0.05\naction_scale: 0.25\n\
cmd_scale: [2.0, 2.0, 0.25]\nnum_actions: 12\nnum_obs: 48\nmax_cmd: [1.0, 0.5, 1.0]\n\
observation: [base_lin_vel, base_ang_vel, projected_gravity, command, joint_pos, joint_vel, last_action]\n";

#[test]
fn a_go2_policy_stands_the_physics_go2_on_its_default_pose() {
    let dir = std::env::temp_dir().join(format!("robowire-go2-policy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = robowire_policy::tiny::matmul(48, 12, vec![0.0; 48 * 12]).write();
    std::fs::copy(model, dir.join("zeros.onnx")).unwrap();
    std::fs::write(dir.join("go2.yaml"), GO2_YAML).unwrap();
    // `policy run` finds multicast on loopback for its simulator itself.
    let out = robowire()
        .args(["policy", "run"])
        .arg(dir.join("go2.yaml"))
        .args(["--device", "sim:go2", "--physics", "--cmd", "0.5,0,0", "--duration", "2", "--record"])
        .arg(dir.join("go2.mcap"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && stderr.contains("ended: the duration ran out"), "{stderr}");
    assert!(stderr.contains("walking: step"), "the policy ran: {stderr}");
    // The capture: the Go2's LowCmds and LowStates, and the policy's steps at 50 Hz.
    let decoded = robowire().args(["decode", "--mcap"]).arg(dir.join("go2.mcap")).output().unwrap();
    let summary = String::from_utf8_lossy(&decoded.stdout);
    let count = |channel: &str| -> u64 {
        let line = summary.lines().find(|l| l.starts_with(channel)).unwrap_or_else(|| panic!("{channel}: {summary}"));
        line.split_whitespace().nth(2).and_then(|n| n.parse().ok()).unwrap_or(0)
    };
    assert!(count("/go2/low_level/sent ") > 1000 && count("/go2/low_level/received ") > 1000, "{summary}");
    let steps = count("/go2/policy/sent/robowire.PolicyStep ");
    // At most 2 s of steps on the 50 Hz grid (a loaded machine misses some, never adds).
    assert!((1..=101).contains(&steps), "policy steps recorded: {steps}\n{summary}");
}

#[test]
fn unitrees_loco_client_walks_the_physics_g1_under_its_policy() {
    let Some(dir) = interop::require(peers::policies_dir()) else { return };
    let Some(python) = interop::require(peers::unitree_python()) else { return };
    robowire_dds::netns::with_loopback_multicast(|| {
        let config = dir.join("g1_walk.yaml");
        let config = config.to_str().unwrap();
        let sim =
            Running::start(&["sim", "g1", "--physics", "--walk", config, "--interface", "lo", "--report-every-s", "0"]);
        assert!(sim.first_line.starts_with("g1 domain 0 lo"), "{}", sim.first_line);
        // LocoClient.Move(0.5, 0, 0) every 0.1 s for 12 s (the first 3 s the robot stands up
        // under the policy's stand sequence), then StopMove and Damp.
        let walker = start_observer(&python, "tests/physics_interop/loco_walk.py", &["lo", "0.5", "0", "0", "12"]);
        let seen = crate::support::observer_summary(walker.0, walker.1);
        let log = sim.interrupt().stdout;
        assert_eq!(seen["timed_out"], false, "{seen}\n{log}");
        assert_eq!(seen["fsm"], serde_json::json!([0, 500]), "GetFsmId: the walking controller\n{log}");
        let coordinate = |at: &str, i: usize| seen[at][i].as_f64().unwrap_or_else(|| panic!("{at}: {seen}"));
        let forward = coordinate("last", 0) - coordinate("first", 0);
        let lowest = seen["lowest"].as_f64().unwrap();
        eprintln!("walked {forward:.2} m, lowest {lowest:.3} m: {seen}");
        assert!(forward >= 2.0, "walked {forward:.2} m under LocoClient.Move(0.5, 0, 0)\n{log}");
        assert!(lowest >= 0.5, "the pelvis stayed above 0.5 m: {lowest:.3}\n{log}");
        assert!(log.contains("walker: standing up, then walking"), "{log}");
        assert!(log.contains("loco SetFsmId 1") && log.contains("walker: stopped"), "Damp stops the walker: {log}");
    });
}

/// Polls (every 10 ms, up to 20 s) until the last body height on `track` passes `reached`; the
/// heights seen.
fn wait_for_height(track: &Track, reached: impl Fn(f32) -> bool) -> Vec<f32> {
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    loop {
        let heights: Vec<f32> = track.0.lock().unwrap().iter().map(|p| p[2]).collect();
        if heights.last().is_some_and(|z| reached(*z)) || std::time::Instant::now() > deadline {
            return heights;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn a_go2_walking_policy_stands_the_physics_go2_on_sport_stand_up_and_damp_lays_it_down() {
    use unitree_proto::api::sport;
    let dir = std::env::temp_dir().join(format!("robowire-go2-walk-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let model = robowire_policy::tiny::matmul(48, 12, vec![0.0; 48 * 12]).write();
    std::fs::copy(model, dir.join("zeros.onnx")).unwrap();
    std::fs::write(dir.join("go2.yaml"), GO2_YAML).unwrap();
    let config = dir.join("go2.yaml");
    robowire_dds::netns::with_loopback_multicast(|| {
        let sim = Running::start(&[
            "sim",
            "go2",
            "--physics",
            "--walk",
            config.to_str().unwrap(),
            "--interface",
            "lo",
            "--report-every-s",
            "0",
        ]);
        let done = Arc::new(AtomicBool::new(false));
        let (track, watcher) = watch(done.clone());
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        let options = ParticipantOptions { interface: Some("lo".into()), ..ParticipantOptions::default() };
        let participant = Participant::new(options).unwrap();
        let _on = runtime.enter();
        let client = unitree::services::ServiceClient::new(&participant, sport::SERVICE).unwrap();
        let call = |api: i64, parameter: &str| {
            runtime.block_on(client.call(api, parameter, Duration::from_secs(3))).map(|a| a.code)
        };
        // Lying on its floor until the sport service stands it up through the walker.
        let lying = wait_for_height(&track, |z| z > 0.0);
        eprintln!("lying at {:?}", lying.last());
        assert!(lying.iter().all(|z| *z < 0.15), "booted lying");
        assert_eq!(call(sport::STAND_UP, "{}").unwrap(), 0);
        let standing = wait_for_height(&track, |z| z > 0.18);
        assert!(standing.last().is_some_and(|z| *z > 0.18), "stood up under the policy: {:?}", standing.last());
        assert_eq!(call(sport::MOVE, r#"{"x":0.3,"y":0,"z":0}"#).unwrap(), 0, "Move is taken with --walk");
        assert_eq!(call(sport::DAMP, "{}").unwrap(), 0);
        let lying = wait_for_height(&track, |z| z < 0.15);
        eprintln!("standing at {:?}, damped to {:?}", standing.last(), lying.last());
        assert!(lying.last().is_some_and(|z| *z < 0.15), "sinks once damped: {:?}", lying.last());
        done.store(true, Ordering::Release);
        watcher.join().unwrap();
        let log = sim.interrupt().stdout;
        assert!(log.contains("walker: standing up, then walking") && log.contains("walker: stopped"), "{log}");
    });
}

#[test]
fn cmd_vel_through_the_ros2_bridge_walks_the_physics_g1_under_its_policy() {
    use ros2_proto::geometry::{Twist, Vector3};
    let Some(dir) = interop::require(peers::policies_dir()) else { return };
    robowire_dds::netns::with_loopback_multicast(|| {
        let config = dir.join("g1_walk.yaml");
        let mut bridge = robowire()
            .args(["ros2", "--device", "sim:g1", "--physics", "--walk"])
            .arg(&config)
            .args(["--interface", "lo", "--namespace", "g1", "--arm", "--duration", "16", "--json"])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let done = Arc::new(AtomicBool::new(false));
        let (track, watcher) = watch(done.clone());
        // A teleop's twist, 20 Hz, while the bridge runs (it ends on its --duration).
        let options = ParticipantOptions { interface: Some("lo".into()), ..ParticipantOptions::default() };
        let participant = Participant::new(options).unwrap();
        let writer = participant.writer::<Twist>("rt/g1/cmd_vel", Qos::ROS_DEFAULT).unwrap();
        let forward = Twist { linear: Vector3 { x: 0.5, y: 0.0, z: 0.0 }, angular: Vector3::default() };
        while bridge.try_wait().unwrap().is_none() {
            let _ = writer.write(forward);
            std::thread::sleep(Duration::from_millis(50));
        }
        let out = bridge.wait_with_output().unwrap();
        done.store(true, Ordering::Release);
        watcher.join().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        let counters: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let cmd_vel = &counters[0]["cmd_vel"];
        assert!(cmd_vel["applied"].as_u64().unwrap() > 100, "{counters}");
        let track = std::mem::take(&mut *track.0.lock().unwrap());
        let (Some(first), Some(last)) = (track.first(), track.last()) else { panic!("no rt/sportmodestate") };
        let walked = last[0] - first[0];
        eprintln!("walked {walked:.2} m, lowest {:.3} m", lowest(&track));
        assert!(walked >= 2.0, "walked {walked:.2} m under cmd_vel 0.5 m/s for 16 s (3 s standing up)\n{stderr}");
        assert!(lowest(&track) >= 0.5, "the pelvis stayed above 0.5 m: {:.3}", lowest(&track));
    });
}
