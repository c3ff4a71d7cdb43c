//! The HighLevel and LowLevel clients against robowire's dog simulator and scripted peers on
//! loopback: motion, argument checks, the watchdog and reconnect, source filtering, faults,
//! lenient decoding, both interfaces at once. 127.0.0.2 (loopback on Linux) plays a foreign host.
//! Conditions are awaited with a generous timeout; nothing here asserts how long anything took
//! (the stream's timing is `zsl-proto`'s fake-clock tests).

use std::net::{SocketAddr, UdpSocket};
use std::time::Duration;

use robowire_fixtures::wait::until_async;
use robowire_sim::zsl1::{Activity, Zsl1Fault, Zsl1Sim, Zsl1SimConfig};
use zsl::udp::{
    CallError, ClientOptions, Connection, ControlMode, Device, HighLevel, Latched, LowLevel, MotorCommand, Placement,
    Refusal, ReturnCode,
};
use zsl_proto::rules::ArgumentError;
use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelState};

/// Generous: a condition not reached within this is a failure, not slowness.
const WAIT: Duration = Duration::from_secs(20);

fn options_to(dog: SocketAddr) -> ClientOptions {
    ClientOptions { dog, ..ClientOptions::high_level([127, 0, 0, 1].into(), 0, dog.ip()) }
}

async fn standing_dog(sim: &Zsl1Sim, options: ClientOptions) -> HighLevel {
    let client = HighLevel::open(options).unwrap();
    assert!(client.wait_connected(WAIT).await, "state from the simulator");
    // The dog starts lying (51); the client's idle stream (mode 0) makes it passive at once.
    let mode = client.control_mode().unwrap();
    assert!(matches!(mode, ControlMode::LieDown | ControlMode::Passive), "the simulated dog lies: {mode:?}");
    client.stand_up().unwrap();
    assert!(client.wait_for_mode(ControlMode::Stand, WAIT).await.is_some());
    until_async(WAIT, "sim.snapshot().robot.activity() == Activity::Standing", || {
        sim.snapshot().robot.activity() == Activity::Standing
    })
    .await;
    client
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn stands_walks_and_lies_down_on_the_simulator() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let client = standing_dog(&sim, options_to(sim.high_level_addr())).await;
    let start = client.position().unwrap();

    client.move_velocity(0.5, 0.0, 0.0).unwrap();
    assert!(client.wait_for_mode(ControlMode::Move, WAIT).await.is_some());
    let moving = client.wait_for_state(WAIT, move |s| s.body.body_velocity_mps[0] > 0.45).await;
    assert!(moving.is_some(), "the body reaches the commanded speed");
    let walking = client.position().unwrap()[0];
    assert!(
        client.wait_for_state(WAIT, move |s| s.body.position_m[0] > walking + 0.1).await.is_some(),
        "the position integrates the walk"
    );
    assert_eq!(
        client.lie_down().map_err(|e| e.return_code()),
        Err(ReturnCode::SwitchFailed),
        "lying down while walking is refused (robot is running)"
    );
    client.move_velocity(0.0, 0.0, 0.0).unwrap();
    assert!(client.wait_for_state(WAIT, move |s| s.body.body_velocity_mps[0].abs() < 0.05).await.is_some());
    let walked = client.position().unwrap()[0] - start[0];
    assert!(walked > 0.1, "the dog moved forward: {walked} m");
    let sideways = client.position().unwrap()[1] - start[1];
    assert!(sideways.abs() < 0.01, "straight ahead: {sideways} m sideways");

    client.lie_down().unwrap();
    assert!(client.wait_for_mode(ControlMode::LieDown, WAIT).await.is_some());
    until_async(WAIT, "sim.snapshot().robot.activity() == Activity::Lying", || {
        sim.snapshot().robot.activity() == Activity::Lying
    })
    .await;
    let body = client.body().unwrap();
    assert!(body.battery_percent <= 100 && body.error.is_none());
    let stats = client.stats();
    assert_eq!((stats.link.decode_errors, stats.link.foreign_dropped, stats.disconnects), (0, 0, 0));
    assert!(stats.link.sent > 100, "the 2 ms stream runs: {stats:?}");
    assert_eq!(sim.snapshot().high_level.invalid, 0, "every command decoded strictly on the dog");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn arguments_are_checked_before_anything_is_sent() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let client = standing_dog(&sim, options_to(sim.high_level_addr())).await;
    let latched = client.wire_command();
    let refused = |r: Result<Latched, CallError>| matches!(r, Err(CallError::Refused(Refusal::Argument(_))));
    for (vx, vy, wz) in [
        (0.04, 0.0, 0.0),
        (3.01, 0.0, 0.0),
        (0.0, 0.05, 0.0),
        (0.0, 1.01, 0.0),
        (0.0, 0.0, 0.019),
        (f32::NAN, 0.0, 0.0),
        (0.0, f32::INFINITY, 0.0),
        (0.0, 0.0, f32::NEG_INFINITY),
    ] {
        let result = client.move_velocity(vx, vy, wz);
        assert!(refused(result), "move({vx}, {vy}, {wz}) is refused");
    }
    assert!(matches!(
        client.move_velocity(f32::NAN, 0.0, 0.0),
        Err(CallError::Refused(Refusal::Argument(ArgumentError::NonFinite(_))))
    ));
    assert!(refused(client.attitude_control(0.0, 0.61, 0.0, 0.0)));
    assert!(refused(client.two_leg_stand(0.1, 0.0)));
    assert_eq!(client.wire_command(), latched, "nothing was latched");
    assert_eq!(client.move_velocity(f32::NAN, 0.0, 0.0).unwrap_err().return_code(), ReturnCode::SpeedTooLarge);

    // The band edges are inside; |v| ≤ 1e-6 is zero.
    for (vx, vy, wz) in [(0.05, 0.1, 0.02), (-3.0, -1.0, -3.0), (1e-6, 0.0, -1e-6)] {
        client.move_velocity(vx, vy, wz).unwrap_or_else(|e| panic!("move({vx}, {vy}, {wz}): {e}"));
    }
    client.move_velocity(0.0, 0.0, 0.0).unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn watchdog_disconnects_zeroes_motion_and_reconnects() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let watchdog = Duration::from_millis(300);
    let client = standing_dog(&sim, options_to(sim.high_level_addr()).with_watchdog(watchdog)).await;
    let mut events = client.connection_events();
    assert_eq!(*events.borrow_and_update(), Connection::Connected);
    client.move_velocity(0.5, 0.0, 0.3).unwrap();

    sim.inject(Zsl1Fault::Silence);
    tokio::time::timeout(WAIT, events.changed()).await.unwrap().unwrap();
    assert_eq!(*events.borrow_and_update(), Connection::Disconnected);
    assert!(!client.check_connection());
    assert_eq!(client.state(), None, "no state instead of stale or zero values");
    let latched = client.wire_command();
    assert_eq!(latched.control_mode(), ControlMode::Move, "same mode");
    assert_eq!((latched.vx.get(), latched.yaw_rate.get()), (0.0, 0.0), "the latched motion became a stop");
    let sent = client.stats().link.sent;
    until_async(WAIT, "client.stats().link.sent > sent + 5", || client.stats().link.sent > sent + 5).await; // the stop keeps streaming while disconnected

    sim.clear_faults();
    tokio::time::timeout(WAIT, events.changed()).await.unwrap().unwrap();
    assert_eq!(*events.borrow_and_update(), Connection::Connected);
    assert!(client.wait_connected(WAIT).await);
    let stats = client.stats();
    assert_eq!((stats.disconnects, stats.reconnects), (1, 1));
    assert!(
        u128::from(stats.state_gap.max_us) >= watchdog.as_micros(),
        "the silence shows as the largest gap between states: {:?}",
        stats.state_gap
    );
    assert_eq!(client.wire_command().vx.get(), 0.0, "a stale motion never resumes");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_default_watchdog_is_the_vendors_three_seconds() {
    assert_eq!(ClientOptions::default().watchdog, Duration::from_secs(3));
    assert_eq!(ClientOptions::default().dog, "192.168.234.1:43997".parse().unwrap());
    assert_eq!(ClientOptions::default().local.port(), 43988);
}

fn state(mode: u32) -> Vec<u8> {
    HighLevelState { header: HIGH_LEVEL_STATE_HEADER, control_mode: mode.into(), ..HighLevelState::default() }
        .encode()
        .to_vec()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn spoofed_state_from_another_ip_is_dropped_and_never_feeds_the_watchdog() {
    let dog = UdpSocket::bind("127.0.0.1:0").unwrap();
    let spoofer = UdpSocket::bind("127.0.0.2:0").expect("127.0.0.2 is loopback on Linux");
    let client =
        HighLevel::open(options_to(dog.local_addr().unwrap()).with_watchdog(Duration::from_millis(300))).unwrap();
    let to = client.local_addr();
    let mut events = client.connection_events();
    let mut spoofed = 0;
    // Spoof until the watchdog, which nothing fed, expires.
    while *events.borrow_and_update() != Connection::Disconnected {
        spoofer.send_to(&state(21), to).unwrap();
        spoofed += 1;
        let _ = tokio::time::timeout(Duration::from_millis(20), events.changed()).await;
    }
    until_async(WAIT, "client.stats().link.foreign_dropped == spoofed", || {
        client.stats().link.foreign_dropped == spoofed
    })
    .await;
    assert_eq!(client.state(), None, "a spoofed state never lands");
    assert_eq!(client.connection(), Connection::Disconnected, "nor keeps the connection alive");
    assert_eq!(client.stats().states, 0);

    dog.send_to(&state(1), to).unwrap();
    assert!(client.wait_connected(WAIT).await);
    assert_eq!(client.control_mode(), Some(ControlMode::Stand));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn lenient_decoding_merges_short_datagrams_and_counts_anomalies() {
    let dog = UdpSocket::bind("127.0.0.1:0").unwrap();
    let client = HighLevel::open(options_to(dog.local_addr().unwrap())).unwrap();
    let to = client.local_addr();
    dog.send_to(&[], to).unwrap();
    tokio::time::timeout(WAIT, client.connection_events().wait_for(|c| *c == Connection::Connected))
        .await
        .unwrap()
        .unwrap();
    assert_eq!(client.state(), None, "a 0-byte datagram feeds the watchdog, it is not a state");

    dog.send_to(&state(18), to).unwrap();
    assert!(client.wait_for_mode(ControlMode::Move, WAIT).await.is_some());
    let mut short = vec![0xde, 0xad, 0xbe, 0xef];
    short.extend_from_slice(&1.0f32.to_le_bytes());
    dog.send_to(&short, to).unwrap();
    let merged = client.wait_for_state(WAIT, move |s| s.body.imu.quaternion_wxyz[0] == 1.0).await.unwrap();
    assert_eq!(merged.body.mode, ControlMode::Move, "the rest of the state is kept");
    dog.send_to(&[0u8; 561], to).unwrap();
    until_async(WAIT, "client.stats().link.decode_errors == 1", || client.stats().link.decode_errors == 1).await; // longer than the state is an error
    let stats = client.stats();
    assert_eq!((stats.states, stats.short_states, stats.header_anomalies), (3, 2, 1), "{stats:?}");
    assert_eq!(stats.link.decode_errors, 1, "longer than the state is an error");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn faults_error_word_garbage_and_sdk_mismatch() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let client = standing_dog(&sim, options_to(sim.high_level_addr()).with_watchdog(Duration::from_millis(300))).await;

    sim.inject(Zsl1Fault::ErrorWord(ReturnCode::MotorFault));
    assert!(client.wait_for_state(WAIT, move |s| s.body.error == Some(ReturnCode::MotorFault)).await.is_some());
    assert!(matches!(client.jump(), Err(CallError::Refused(Refusal::SelfCheck(ReturnCode::MotorFault)))));
    // The stream forces passive.
    until_async(WAIT, "client.wire_command().control_mode() == ControlMode::Passive", || {
        client.wire_command().control_mode() == ControlMode::Passive
    })
    .await;
    until_async(WAIT, "sim.snapshot().robot.mode() == ControlMode::Passive", || {
        sim.snapshot().robot.mode() == ControlMode::Passive
    })
    .await;
    sim.clear_faults();

    sim.inject(Zsl1Fault::Garbage);
    tokio::time::timeout(WAIT, client.connection_events().wait_for(|c| *c == Connection::Disconnected))
        .await
        .unwrap()
        .unwrap();
    assert!(client.stats().link.decode_errors > 10, "junk is counted, not taken as state");
    sim.clear_faults();
    assert!(client.wait_connected(WAIT).await);

    sim.inject(Zsl1Fault::SdkMismatch);
    assert!(client.wait_for_state(WAIT, move |s| s.sdk_mismatch).await.is_some());
    until_async(WAIT, "client.halted()", || client.halted()).await; // the stream stops for good, like the vendor's
    assert!(matches!(client.stand_up(), Err(CallError::SdkMismatch)));
    // Halted, the stream's schedule has no next deadline and its thread ends after the run that
    // halted it (the flag is set after that run's sends): nothing can be sent from now on.
    let sent = client.stats().link.sent;
    until_async(WAIT, "sim.snapshot().high_level.commands == sent", || sim.snapshot().high_level.commands == sent)
        .await; // everything sent arrived
    assert_eq!(client.stats().link.sent, sent);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn high_level_and_low_level_at_once_on_different_local_ports() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let high = HighLevel::open(options_to(sim.high_level_addr())).unwrap();
    let low_options = ClientOptions { dog: sim.low_level_addr(), ..options_to(sim.low_level_addr()) };
    let low = LowLevel::open(low_options).unwrap();
    assert_ne!(high.local_addr(), low.local_addr());
    assert!(high.wait_connected(WAIT).await);
    assert!(low.wait_for_state(WAIT, move |_| true).await.is_some());
    assert!(low.has_motor_data());

    let refused = low.send_motor_command(&MotorCommand::default());
    assert!(
        matches!(refused, Err(CallError::Refused(Refusal::Argument(ArgumentError::Position { .. })))),
        "knee 0 is out of range"
    );

    let stand = MotorCommand::pd_hold([[0.0; 4], [0.8; 4], [-1.5; 4]], [80.0; 3], [1.0; 3]);
    low.send_motor_command(&stand).unwrap();
    let near = |legs: &[f32; 4], target: f32| legs.iter().all(|q| (q - target).abs() < 0.02);
    let reached =
        low.wait_for_state(WAIT, move |s| near(&s.motor.q_rad[1], 0.8) && near(&s.motor.q_rad[2], -1.5)).await;
    assert!(reached.is_some(), "the PD joints reach the targets: {:?}", low.motor_state());
    assert!(
        high.wait_for_state(WAIT, move |s| (s.joints.position_rad.knee[0] + 1.5).abs() < 0.02).await.is_some(),
        "the HighLevel state shows the same joints"
    );
    let mut nan = stand;
    nan.kp[0][0] = f32::NAN;
    assert!(matches!(
        low.send_motor_command(&nan),
        Err(CallError::Refused(Refusal::Argument(ArgumentError::NonFinite(_))))
    ));
    assert_eq!(MotorCommand::from(&low.wire_command().motor), stand);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_zsl1w_crawls_and_its_wheels_turn() {
    let config = Zsl1SimConfig { model: zsl::udp::Model::Zsl1W, ..Zsl1SimConfig::loopback() };
    let sim = Zsl1Sim::spawn(config).unwrap();
    let options = options_to(sim.high_level_addr()).with_model(zsl::udp::Model::Zsl1W);
    let client = standing_dog(&sim, options).await;
    client.crawl(0.5, 0.0, 0.0).unwrap();
    let rolling = client.wait_for_state(WAIT, move |s| s.joints.position_rad.foot[0] > 1.0).await;
    assert!(rolling.is_some(), "the foot (wheel) joints integrate the forward speed");
    assert_eq!(client.wire_command().action_code(), zsl::udp::Action::Crawl);
    client.cancel_crawl().unwrap();
    assert_eq!(client.wire_command().action_code(), zsl::udp::Action::None);
    client.move_velocity(0.0, 0.0, 0.0).unwrap();
    assert!(!client.state().unwrap().sdk_mismatch, "the right magic raises no mismatch");

    let zsl1 = HighLevel::open(options_to(sim.high_level_addr())).unwrap();
    assert!(matches!(zsl1.crawl(0.5, 0.0, 0.0), Err(CallError::Refused(Refusal::WrongModel { .. }))));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn low_level_watchdog_zeroes_velocity_targets_and_keeps_the_hold() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let options = options_to(sim.low_level_addr()).with_watchdog(Duration::from_millis(300));
    let low = LowLevel::open(options).unwrap();
    assert!(low.wait_for_state(WAIT, move |_| true).await.is_some());
    let mut moving = MotorCommand::pd_hold([[0.0; 4], [0.8; 4], [-1.5; 4]], [80.0; 3], [1.0; 3]);
    moving.qd_des_radps[1] = [0.5; 4];
    moving.tau_ff_nm[2] = [2.0; 4];
    low.send_motor_command(&moving).unwrap();

    sim.inject(Zsl1Fault::Silence);
    tokio::time::timeout(WAIT, low.connection_events().wait_for(|c| *c == Connection::Disconnected))
        .await
        .unwrap()
        .unwrap();
    assert_eq!(low.motor_state(), None);
    let latched = MotorCommand::from(&low.wire_command().motor);
    assert!(latched.qd_des_radps.iter().flatten().all(|&v| v == 0.0), "velocity targets zeroed");
    assert_eq!(
        (latched.q_des_rad, latched.kp, latched.tau_ff_nm),
        (moving.q_des_rad, moving.kp, moving.tau_ff_nm),
        "hold kept"
    );
    sim.clear_faults();
    assert!(low.wait_for_state(WAIT, move |_| true).await.is_some(), "reconnects");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn bad_options_and_placement_are_typed_errors() {
    use zsl::udp::ConnectError;
    let dog: SocketAddr = "127.0.0.1:9".parse().unwrap();
    let base = options_to(dog);
    let too_fast = ClientOptions { period: Duration::from_micros(10), ..base.clone() };
    assert!(matches!(HighLevel::open(too_fast), Err(ConnectError::Option { name: "period", .. })));
    let short_watchdog = ClientOptions { watchdog: Duration::from_millis(1), ..base.clone() };
    assert!(matches!(HighLevel::open(short_watchdog), Err(ConnectError::Option { name: "watchdog", .. })));
    let priority = ClientOptions { placement: Placement::realtime(0, None), ..base.clone() };
    assert!(matches!(LowLevel::open(priority), Err(ConnectError::Thread(zsl::udp::RtError::RealtimePriority { .. }))));
    let nowhere = ClientOptions { placement: Placement { cpu: Some(1 << 20), ..Placement::default() }, ..base };
    match HighLevel::open(nowhere) {
        Err(ConnectError::Thread(zsl::udp::RtError::CpuAffinity { cpu, .. })) => assert_eq!(cpu, 1 << 20),
        other => panic!("{other:?}"),
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn close_frees_the_local_port_at_once() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let high = HighLevel::open(options_to(sim.high_level_addr())).unwrap();
    let port = high.local_addr().port();
    assert!(high.wait_connected(WAIT).await);
    high.close();
    let again = ClientOptions {
        dog: sim.high_level_addr(),
        ..ClientOptions::high_level([127, 0, 0, 1].into(), port, [127, 0, 0, 1].into())
    };
    let high = HighLevel::open(again).expect("the port of a closed client binds again");
    assert!(high.wait_connected(WAIT).await);

    let low_options = ClientOptions { dog: sim.low_level_addr(), ..options_to(sim.low_level_addr()) };
    let low = LowLevel::open(low_options).unwrap();
    let port = low.local_addr().port();
    low.close();
    UdpSocket::bind(("127.0.0.1", port)).expect("the port of a closed LowLevel client binds again");
}
