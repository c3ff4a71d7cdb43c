//! `sim:go2` and `sim:g1` by address with MuJoCo physics (`OpenOptions::sim_physics`, feature
//! `mujoco`), where loopback carries multicast (`robowire_dds::netns`): the client's states come
//! from the body in MuJoCo (the simulator reports a base pose and simulated time; the IMU reads
//! the physics' specific force, not the kinematic body's exact gravity; the joints settle from
//! the pose the kinematic body holds); the Go2 lies on its floor, the G1 hangs by its pelvis
//! unless its base is set free, and then it stands on the floor, held on its band; a user's model
//! is the one loaded.

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_devices::{AnyDevice, OpenOptions, SimPhysics, Simulator, open};
use robowire_sim::go2::{BasePose, LYING_POSE_RAD};

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

/// Opens `address` with physics (`hanging`: as `SimPhysics::hanging`) and waits for its first
/// state and for `sim_time_s` of simulated time.
async fn open_with_physics(address: &str, hanging: Option<bool>, sim_time_s: f64) -> AnyDevice {
    let options =
        OpenOptions { sim_physics: Some(SimPhysics { model: None, hanging, walk: None }), ..OpenOptions::default() };
    let device = open(&address.parse().unwrap(), &options).unwrap();
    assert!(device.wait_state(WAIT).await, "{address}: rt/lowstate from the simulator");
    tokio::time::timeout(WAIT, async {
        while body(&device).1 < sim_time_s {
            tokio::time::sleep(Duration::from_millis(10)).await;
        }
    })
    .await
    .unwrap_or_else(|_| panic!("{address}: {sim_time_s} s of simulated time"));
    device
}

/// The simulator's base pose and simulated time.
fn body(device: &AnyDevice) -> (Option<BasePose>, f64) {
    match device.simulator() {
        Some(Simulator::Go2(sim)) => {
            let s = sim.snapshot();
            (s.base, s.sim_time_s)
        }
        Some(Simulator::G1(sim)) => {
            let s = sim.snapshot();
            (s.base, s.stream.sim_time_s)
        }
        other => panic!("a Go2 or G1 simulator, not {other:?}"),
    }
}

/// The client's latest IMU specific force, m/s².
fn acc(device: &AnyDevice) -> [f64; 3] {
    device.observe().expect("a state").imu.expect("an IMU").acc_mps2
}

#[test]
fn a_physics_go2_by_address_lies_on_its_floor() {
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let go2 = open_with_physics("sim:go2", None, 0.2).await;
            let base = body(&go2).0.expect("a base pose: the body is MuJoCo's");
            assert!(base.position_m[2] < 0.15, "lying on its floor: {base:?}");
            let acc = acc(&go2);
            assert!(acc != [0.0, 0.0, 9.81] && (acc[2] - 9.81).abs() < 1.0, "the physics' IMU: {acc:?}");
            // The joints the client reads are the body's, settled under gravity from the pose
            // the kinematic body holds exactly.
            let joints = go2.observe().unwrap().joints.unwrap().position_rad;
            let Some(Simulator::Go2(sim)) = go2.simulator() else { unreachable!() };
            let body_q = sim.snapshot().joints_rad;
            assert!(joints.iter().zip(body_q).all(|(q, b)| (q - f64::from(b)).abs() < 0.01), "{joints:?} {body_q:?}");
            let settled = joints.iter().zip(LYING_POSE_RAD).map(|(q, l)| (q - f64::from(l)).abs()).fold(0.0, f64::max);
            assert!(settled > 0.05, "not the kinematic lying pose: {joints:?}");
            go2.close().unwrap();

            // A user's model is the one loaded.
            let model = SimPhysics { model: Some("/robowire-no-such/scene.xml".into()), hanging: None, walk: None };
            let options = OpenOptions { sim_physics: Some(model), ..OpenOptions::default() };
            let error = open(&"sim:go2".parse().unwrap(), &options).unwrap_err();
            let chain = robowire_devices::error_chain(&error);
            assert!(chain.contains("cannot load the MJCF model /robowire-no-such/scene.xml"), "{chain}");
        });
    });
}

#[test]
fn a_physics_g1_by_address_hangs_by_its_pelvis_or_stands_on_its_band() {
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let g1 = open_with_physics("sim:g1", None, 1.0).await;
            let base = body(&g1).0.expect("a base pose: the body is MuJoCo's");
            assert!(base.position_m[2] > 0.85, "hanging, as `robowire sim g1`: {base:?}");
            let acc = acc(&g1);
            assert!(acc != [0.0, 0.0, 9.81], "the physics' IMU: {acc:?}");
            g1.close().unwrap();

            // Free: settled on the floor and held there as on Unitree's elastic band, until a
            // LowCmd stream drives its legs (robowire-sim's tests/physics.rs lets it go).
            let g1 = open_with_physics("sim:g1", Some(false), 2.0).await;
            let base = body(&g1).0.unwrap();
            assert!(base.position_m[2] > 0.7 && base.position_m[2] < 0.85, "standing on the floor: {base:?}");
            g1.close().unwrap();
        });
    });
}
