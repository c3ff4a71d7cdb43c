//! `sim:g1`: the G1 simulator and `unitree::g1` in one process, by address, where loopback
//! carries multicast (`robowire_dds::netns`): the joints by their names, the battery from
//! `rt/lf/bmsstate`, the LowState passed through, the facade and the simulator underneath.

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_devices::{DeviceAddress, DeviceKind, OpenOptions, Simulator, open};

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

#[test]
fn a_simulated_g1_by_address() {
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let address: DeviceAddress = "sim:g1".parse().unwrap();
            let g1 = open(&address, &OpenOptions::default()).unwrap();
            assert_eq!(g1.kind(), DeviceKind::G1);
            assert!(g1.wait_state(WAIT).await, "rt/lowstate from the simulator");
            assert!(matches!(g1.simulator(), Some(Simulator::G1(_))));
            let client = g1.g1().expect("the g1 facade underneath");
            assert_eq!(client.mode_machine(), Some(5));

            // The battery comes once a second beside rt/lowstate.
            let mut observations = g1.observations();
            let seen = tokio::time::timeout(WAIT, async {
                loop {
                    let seen = observations.next().await.expect("the device is open");
                    if seen.battery.is_some() {
                        return seen;
                    }
                }
            })
            .await
            .expect("an observation with the battery");
            let joints = seen.joints.unwrap();
            assert_eq!(joints.names, unitree::g1::JOINT_NAMES, "29 joints by their URDF names");
            assert!(joints.position_rad[3] > 0.1, "standing: a bent knee, {:?}", joints.position_rad);
            let battery = seen.battery.unwrap();
            let charge = battery.charge_fraction.unwrap();
            assert!((0.5..=1.0).contains(&charge), "{battery:?}");
            assert_eq!(battery.cells_v.len(), 13, "{battery:?}");
            let pack: f32 = battery.cells_v.iter().sum();
            assert!((battery.voltage_v.unwrap() - pack).abs() < 0.01, "{battery:?}");
            assert!(battery.current_a.unwrap() < 0.0, "discharging: {battery:?}");
            assert_eq!(seen.imu.unwrap().acc_mps2[2] as f32, 9.81);
            let raw = seen.passthrough.unwrap();
            assert_eq!((raw.topic, raw.type_name), ("lowstate", "unitree_hg::msg::dds_::LowState_"));

            let text = g1.status_text().unwrap();
            assert!(text.starts_with("tick ") && text.contains("mode_machine 5 (Dof29) mode_pr 0"), "{text}");
            assert!(text.contains("  left_knee_joint") && text.contains("  battery: soc "), "{text}");
            assert_eq!(g1.status_json().unwrap()["mode_machine"], 5);
            assert!(g1.stats_line().contains("bmsstate received "), "{}", g1.stats_line());
            g1.close().unwrap();
        });
    });
}

#[test]
fn a_g1_is_driven_through_its_loco_service_and_stopped_when_dropped() {
    use robowire_sim::g1::{G1Sim, G1SimConfig};
    with_loopback_multicast(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let participant = robowire_dds::ParticipantOptions { interface: Some("lo".into()), ..Default::default() };
            let sim = G1Sim::spawn(G1SimConfig { participant, ..G1SimConfig::default() }).unwrap();
            let g1 = open(&"g1:lo".parse().unwrap(), &OpenOptions::default()).unwrap();
            assert!(g1.wait_state(WAIT).await, "rt/lowstate from the simulator");
            assert!(g1.can_drive());
            assert!(g1.drive(f32::NAN, 0.0, 0.0).is_err(), "checked before anything is sent");
            assert!(g1.drive(3.0, 0.0, 0.0).is_err(), "past robowire's 1 m/s");
            g1.drive(0.3, 0.0, 0.2).unwrap();
            until(|| sim.snapshot().loco_velocity == [0.3, 0.0, 0.2], "the loco service asked 0.3, 0, 0.2").await;
            assert!(g1.stats_line().contains("velocity asked 1 refused 0"), "{}", g1.stats_line());

            // Released, the loco service refuses: counted, and said in the stats line.
            g1.g1().unwrap().release().await.unwrap();
            g1.drive(0.3, 0.0, 0.0).unwrap();
            until(|| g1.stats_line().contains("refused 1 (last: "), "the refusal counted").await;
            g1.g1().unwrap().select_mode(robowire_sim::g1::BOOT_MODE).await.unwrap();
            g1.drive(0.2, 0.0, 0.0).unwrap();
            until(|| sim.snapshot().loco_velocity == [0.2, 0.0, 0.0], "asked again once selected").await;
            // Its last word: zero velocity.
            drop(g1);
            assert_eq!(sim.snapshot().loco_velocity, [0.0; 3], "stopped when the client was dropped");
        });
    });
}

/// Polls `reached` (every 5 ms, up to [`WAIT`]) until it holds, else fails saying `what`.
async fn until(reached: impl Fn() -> bool, what: &str) {
    let deadline = tokio::time::Instant::now() + WAIT;
    while !reached() {
        assert!(tokio::time::Instant::now() < deadline, "{what}: not within {WAIT:?}");
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
}
