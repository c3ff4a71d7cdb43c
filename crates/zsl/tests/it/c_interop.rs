//! Interop with C: a C program declares the packed layout from the spec, and runs as a second
//! process against real shared memory, as the client of a Rust daemon and as the daemon of a
//! Rust client.

use std::mem::{offset_of, size_of};
use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use robowire_fixtures::wait::one_at_a_time;
use robowire_shm::CreateOptions;
use robowire_sim::spline::{CommandUpdate, SplineDaemon};
use zsl::spline::SplineError;
use zsl::{JointControl, JointFlags, JointIndex, Leg, SplineClient, SplineCommandBlock};
use zsl_proto::shm::{JointState, LegControl, LegState, NavImu, NavImuSample, SplineData, SplineStateBlock};

/// Builds tests/c/spline_peer.c with the system C compiler (`$CC`, else `cc`), once for all
/// tests of this file (they run in parallel and must not rebuild it under each other's feet).
fn peer() -> PathBuf {
    static PEER: OnceLock<PathBuf> = OnceLock::new();
    PEER.get_or_init(build_peer).clone()
}

fn build_peer() -> PathBuf {
    let source = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/c/spline_peer.c");
    let out = std::env::temp_dir().join(format!("robowire-spline-peer-{}", std::process::id()));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&cc)
        .args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", "-o"])
        .arg(&out)
        .arg(source)
        .arg("-lrt")
        .status()
        .unwrap_or_else(|e| panic!("the C compiler {cc:?} is needed for this test: {e}"));
    assert!(status.success(), "compiling {source} failed");
    out
}

fn name(tag: &str) -> String {
    format!("/robowire-c-{tag}-{}", std::process::id())
}

#[test]
fn c_layout_matches_rust_layout() {
    let output = Command::new(peer()).arg("layout").output().unwrap();
    assert!(output.status.success());
    let text = String::from_utf8(output.stdout).unwrap();
    let jc = size_of::<JointControl>();
    let js = size_of::<JointState>();
    let joints = offset_of!(LegControl, joints);
    let expected: Vec<(&str, isize, usize)> = vec![
        ("joint_control", -1, jc),
        ("joint_control.p_des", offset_of!(JointControl, p_des) as isize, 4),
        ("joint_control.v_des", offset_of!(JointControl, v_des) as isize, 4),
        ("joint_control.kp", offset_of!(JointControl, kp) as isize, 4),
        ("joint_control.kd", offset_of!(JointControl, kd) as isize, 4),
        ("joint_control.t_ff", offset_of!(JointControl, t_ff) as isize, 4),
        ("leg_control", -1, size_of::<LegControl>()),
        ("leg_control.abad", joints as isize, jc),
        ("leg_control.hip", (joints + jc) as isize, jc),
        ("leg_control.knee", (joints + 2 * jc) as isize, jc),
        ("leg_control.foot", (joints + 3 * jc) as isize, jc),
        ("leg_control.flags", offset_of!(LegControl, flags) as isize, 4),
        ("spline_cmd_data", -1, size_of::<SplineCommandBlock>()),
        ("spline_cmd_data.legs", offset_of!(SplineCommandBlock, legs) as isize, 4 * size_of::<LegControl>()),
        ("spline_cmd_data.consumer_flags", offset_of!(SplineCommandBlock, consumer_flags) as isize, 8),
        ("joint_state", -1, js),
        ("joint_state.flags", offset_of!(JointState, flags) as isize, 4),
        ("joint_state.p", offset_of!(JointState, p) as isize, 4),
        ("joint_state.v", offset_of!(JointState, v) as isize, 4),
        ("joint_state.t", offset_of!(JointState, t) as isize, 4),
        ("leg_state", -1, size_of::<LegState>()),
        ("leg_state.abad", 0, js),
        ("leg_state.hip", js as isize, js),
        ("leg_state.knee", 2 * js as isize, js),
        ("leg_state.foot", 3 * js as isize, js),
        ("spline_state_data", -1, size_of::<SplineStateBlock>()),
        ("spline_state_data.legs", offset_of!(SplineStateBlock, legs) as isize, 4 * size_of::<LegState>()),
        ("spline_state_data.consumer_flags", offset_of!(SplineStateBlock, consumer_flags) as isize, 8),
        ("spline_data", -1, size_of::<SplineData>()),
        ("spline_data.cmd", offset_of!(SplineData, cmd) as isize, size_of::<SplineCommandBlock>()),
        ("spline_data.state", offset_of!(SplineData, state) as isize, size_of::<SplineStateBlock>()),
        ("nav_imu", -1, size_of::<NavImu>()),
        ("nav_imu.timestamp", offset_of!(NavImu, timestamp_ns) as isize, 8),
        ("nav_imu.acc", (offset_of!(NavImu, sample) + offset_of!(NavImuSample, acc)) as isize, 12),
        ("nav_imu.gyro", (offset_of!(NavImu, sample) + offset_of!(NavImuSample, gyro)) as isize, 12),
        ("nav_imu.q", (offset_of!(NavImu, sample) + offset_of!(NavImuSample, q)) as isize, 16),
    ];
    let got: Vec<(String, isize, usize)> = text
        .lines()
        .map(|line| {
            let mut it = line.split_whitespace();
            (it.next().unwrap().to_string(), it.next().unwrap().parse().unwrap(), it.next().unwrap().parse().unwrap())
        })
        .collect();
    assert_eq!(got.len(), expected.len());
    for ((name, offset, size), (c_name, c_offset, c_size)) in expected.iter().zip(&got) {
        assert_eq!((*name, *offset, *size), (c_name.as_str(), *c_offset, *c_size));
    }
}

#[test]
fn c_client_against_the_rust_daemon() {
    // One 1 kHz spline daemon at a time in this binary, as `spline_sim`'s (two cores).
    let _turn = one_at_a_time();
    let peer = peer();
    let name = name("client");
    let mut daemon = SplineDaemon::create(&name, &CreateOptions::default()).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let received = Arc::new(Mutex::new(None::<SplineCommandBlock>));
    let thread = {
        let (stop, received) = (stop.clone(), received.clone());
        std::thread::spawn(move || {
            let deadline = Instant::now() + Duration::from_secs(10);
            while !stop.load(Ordering::Relaxed) && Instant::now() < deadline {
                if daemon.take_command().unwrap() == CommandUpdate::Fresh {
                    *received.lock().unwrap() = Some(*daemon.command());
                }
                // State echoes the command: position = p_des, torque = kp.
                let mut state = SplineStateBlock::default();
                for leg in Leg::ALL {
                    for joint in JointIndex::ALL {
                        let c = daemon.command().joint(leg, joint);
                        let s = state.joint_mut(leg, joint);
                        s.flags = 0x0030_4101.into();
                        s.p = c.p_des;
                        s.t = c.kp;
                    }
                }
                daemon.publish_state(&state).unwrap();
                std::thread::sleep(Duration::from_millis(1));
            }
        })
    };
    let output = Command::new(&peer).args(["client", &name]).output().unwrap();
    stop.store(true, Ordering::Relaxed);
    thread.join().unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let command = received.lock().unwrap().expect("the C client's command reached the daemon");
    for leg in Leg::ALL {
        for joint in JointIndex::ALL {
            let c = command.joint(leg, joint);
            let expected = 0.1f32 * (4 * leg.index() + joint as usize) as f32;
            assert_eq!((c.p_des.get(), c.kp.get(), c.kd.get()), (expected, 7.0, 0.5));
        }
        assert_eq!(command.legs[leg.index()].flags.get(), 1);
    }
    let text = String::from_utf8(output.stdout).unwrap();
    assert_eq!(text.lines().count(), 16);
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let (leg, joint): (usize, usize) = (f[1].parse().unwrap(), f[2].parse().unwrap());
        assert_eq!(f[3], "00304101");
        let p: f32 = f[4].parse().unwrap();
        assert!((p - 0.1 * (4 * leg + joint) as f32).abs() < 1e-6, "{line}");
    }
}

#[test]
fn rust_client_against_the_c_daemon() {
    // One 1 kHz spline daemon at a time in this binary, as `spline_sim`'s (two cores).
    let _turn = one_at_a_time();
    let peer = peer();
    let name = name("daemon");
    let mut c_daemon = Command::new(&peer).args(["daemon", &name, "3000"]).spawn().unwrap();
    let deadline = Instant::now() + Duration::from_secs(5);
    let mut client = loop {
        match SplineClient::open(&name) {
            Ok(client) => break client,
            Err(SplineError::DaemonNotRunning { .. } | SplineError::Shm(_)) if Instant::now() < deadline => {
                std::thread::sleep(Duration::from_millis(2));
            }
            Err(e) => panic!("{e}"),
        }
    };
    let mut command = SplineCommandBlock::default();
    for leg in Leg::ALL {
        for joint in JointIndex::ALL {
            *command.joint_mut(leg, joint) =
                JointControl::new(-0.05 * (4 * leg.index() + joint as usize) as f32, 0.0, 3.0, 0.2, 0.0);
        }
    }
    client.write_command(&command).unwrap();
    // The C daemon echoes p_des once it has consumed the command.
    let state = loop {
        let state = client.wait_state(Duration::from_millis(500)).unwrap();
        let echoed = state.joint(Leg::RearLeft, JointIndex::Foot).p.get() == -0.05 * 15.0;
        if echoed || Instant::now() > deadline {
            break state;
        }
    };
    c_daemon.kill().ok();
    c_daemon.wait().ok();
    for leg in Leg::ALL {
        for joint in JointIndex::ALL {
            let s = state.joint(leg, joint);
            assert_eq!(s.p.get(), -0.05 * (4 * leg.index() + joint as usize) as f32);
            assert_eq!(s.t.get(), 3.0);
            let flags = JointFlags(s.flags.get());
            assert_eq!((flags.voltage_v(), flags.temperature_c(), flags.enabled()), (48, 25, true));
        }
    }
    let _ = robowire_shm::MappedRegion::unlink(&name);
}
