//! `cmd_vel` → the command on the device's wire, through `robowire ros2`'s bridge, where loopback
//! carries multicast (`robowire_dds::netns`): a Twist written by a ROS 2 publisher (robowire-dds,
//! another participant) → the HighLevel datagram carrying its vx at a socket standing in for a ZSL-1;
//! beside, sample by sample in the same run, the two legs it is made of: the Twist's DDS delivery
//! alone (writer → a listener in another participant, as the bridge takes it) and the facade's
//! `move_velocity()` call → wire. Figures to `ROBOWIRE_BENCH_META_ROS2` for `cargo xtask bench`.

use std::net::{SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_ros2::{BridgeOptions, DeviceAddress};
use ros2_proto::geometry::{Twist, Vector3};
use serde_json::json;
use zsl::udp::{ClientOptions, HighLevel};
use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelState};

/// p50 and p99 of `samples`, µs.
fn percentiles(mut samples: Vec<f64>) -> (f64, f64) {
    samples.sort_by(f64::total_cmp);
    let at = |p: usize| samples[((p * samples.len()).div_ceil(100)).saturating_sub(1).min(samples.len() - 1)];
    (at(50), at(99))
}

/// A socket on the ZSL-1's HighLevel port, answering as a walking dog (mode 18).
struct Dog {
    socket: UdpSocket,
    walking: Vec<u8>,
}

impl Dog {
    fn bind() -> Self {
        let socket = UdpSocket::bind("127.0.0.1:43997").unwrap();
        socket.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
        let walking = HighLevelState { header: HIGH_LEVEL_STATE_HEADER, control_mode: 18.into(), ..Default::default() };
        Self { socket, walking: walking.encode().to_vec() }
    }

    /// Waits for the first datagram of a client other than `before` (whose last datagrams may
    /// still be queued), then tells it the dog walks.
    fn greet(&self, before: Option<SocketAddr>) -> SocketAddr {
        let mut buf = [0u8; 64];
        let client = loop {
            let (_, client) = self.socket.recv_from(&mut buf).expect("the client streams");
            if Some(client) != before {
                break client;
            }
        };
        for _ in 0..5 {
            self.socket.send_to(&self.walking, client).unwrap();
            std::thread::sleep(Duration::from_millis(20));
        }
        client
    }

    /// Reads until a command datagram carries `vx`.
    fn wait_for_vx(&self, vx: f32) {
        let mut buf = [0u8; 64];
        loop {
            let len = self.socket.recv(&mut buf).expect("a datagram with the new vx within 2 s");
            if len == 40 && buf[4..8] == vx.to_le_bytes() {
                return;
            }
        }
    }

    fn keep_alive(&self, client: SocketAddr) {
        self.socket.send_to(&self.walking, client).unwrap();
    }
}

fn twist(vx: f32) -> Twist {
    Twist { linear: Vector3 { x: vx.into(), y: 0.0, z: 0.0 }, angular: Vector3::default() }
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return; // `cargo test --benches` lists; there is nothing to list
    }
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let n = if quick { 300 } else { 2000 };
    let meta = robowire_dds::netns::for_this_process().run(|| {
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        let lo = ParticipantOptions::new(0, Some("lo"));
        let dog = Dog::bind();
        // The three paths are measured in turn, sample by sample, so that the machine's slow
        // and fast moments fall on all three alike. Each has its own speeds, since the two ZSL-1
        // clients stream their latched commands to the one dog.
        let (bridged_speeds, direct_speeds) = ([0.5f32, 0.6], [0.7f32, 0.8]);

        // 1. Through the bridge: Twist written → datagram at the dog.
        let (stop_tx, stop) = tokio::sync::watch::channel(false);
        let options = BridgeOptions {
            armed: true,
            interface: Some("lo".into()),
            ..BridgeOptions::new(vec!["zsl1:127.0.0.1".parse::<DeviceAddress>().unwrap()])
        };
        let bridge = runtime.spawn(robowire_ros2::run(options, stop, |_| {}));
        let bridge_client = dog.greet(None);
        let publisher = Participant::new(lo.clone()).unwrap();
        let cmd_vel = publisher.writer::<Twist>("rt/cmd_vel", Qos::ROS_DEFAULT).unwrap();

        // 2. The DDS leg alone: Twist written → handed to a listener in another participant (as
        // the bridge takes it) → this thread.
        let subscriber = Participant::new(lo).unwrap();
        let reader = subscriber.reader::<Twist>("rt/bench_twist", Qos::ROS_DEFAULT).unwrap();
        let (arrived, take) = std::sync::mpsc::sync_channel(1);
        let _listener = reader.listen(move |_| {
            let _ = arrived.try_send(());
        });
        let bench_twist = publisher.writer::<Twist>("rt/bench_twist", Qos::ROS_DEFAULT).unwrap();
        let deadline = Instant::now() + Duration::from_secs(10);
        while cmd_vel.matched_readers() == 0 || bench_twist.matched_readers() == 0 {
            assert!(Instant::now() < deadline, "the readers of cmd_vel and bench_twist were not discovered");
            std::thread::sleep(Duration::from_millis(10));
        }

        // 3. The device leg alone: move_velocity() → datagram at the dog.
        let options = ClientOptions::high_level([127, 0, 0, 1].into(), 0, [127, 0, 0, 1].into());
        let robot = {
            let _in_runtime = runtime.enter();
            HighLevel::open(options).unwrap()
        };
        let direct_client = dog.greet(Some(bridge_client));
        assert!(runtime.block_on(robot.wait_connected(Duration::from_secs(2))));

        let (mut bridged, mut dds, mut direct) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n + 50 {
            let time = |samples: &mut Vec<f64>, path: &mut dyn FnMut()| {
                let start = Instant::now();
                path();
                if i >= 50 {
                    samples.push(start.elapsed().as_secs_f64() * 1e6);
                }
            };
            time(&mut bridged, &mut || {
                cmd_vel.write(twist(bridged_speeds[i % 2])).unwrap();
                dog.wait_for_vx(bridged_speeds[i % 2]);
            });
            time(&mut dds, &mut || {
                bench_twist.write(twist(0.1)).unwrap();
                take.recv_timeout(Duration::from_secs(2)).expect("the twist within 2 s");
            });
            time(&mut direct, &mut || {
                robot.move_velocity(direct_speeds[i % 2], 0.0, 0.0).unwrap();
                dog.wait_for_vx(direct_speeds[i % 2]);
            });
            if i % 100 == 0 {
                dog.keep_alive(bridge_client);
                dog.keep_alive(direct_client);
            }
        }
        robot.close();
        stop_tx.send(true).unwrap();
        runtime.block_on(bridge).unwrap().unwrap();
        let (b50, b99) = percentiles(bridged);
        let (d50, d99) = percentiles(dds);
        let (c50, c99) = percentiles(direct);
        json!({
            "cmd_vel_to_wire_p50_us": b50, "cmd_vel_to_wire_p99_us": b99,
            "dds_twist_p50_us": d50, "dds_twist_p99_us": d99,
            "call_to_wire_p50_us": c50, "call_to_wire_p99_us": c99,
            "samples": n,
        })
    });
    let meta = meta.unwrap_or_else(|e| panic!("DDS on one machine needs multicast on lo: {e}"));
    println!("ros2 cmd_vel: {meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_ROS2") {
        std::fs::write(path, meta.to_string()).unwrap();
    }
}
