//! The ZSL-1 simulator from the client end of the UDP transport, with the ZSL-1 client codec:
//! strict state, answers at once to a changed command, injected faults seen on the wire.

use std::time::{Duration, Instant};

use robowire_sim::zsl1::{Zsl1Fault, Zsl1Sim, Zsl1SimConfig};
use robowire_udp::{Peer, UdpError, UdpLink};
use zsl_proto::codec::{ClientCodec, StateDecoding};
use zsl_proto::udp::{ControlMode, DatagramError, HighLevelCommand, HighLevelState, Model, ReturnCode};

use crate::hammer;

const WATCHDOG: Duration = Duration::from_secs(10);

type Link = UdpLink<ClientCodec<HighLevelCommand, HighLevelState>>;

async fn client(sim: &Zsl1Sim) -> Link {
    let codec = ClientCodec::new(Model::Zsl1, StateDecoding::Strict);
    UdpLink::bind("127.0.0.1:0".parse().unwrap(), Peer::AnyPortOf(sim.high_level_addr()), codec).await.unwrap()
}

/// Sends `command` until a state satisfies `accept`.
async fn until(link: &mut Link, command: HighLevelCommand, accept: impl Fn(&HighLevelState) -> bool) -> HighLevelState {
    let run = async {
        loop {
            link.send(&command).await.unwrap();
            match link.recv().await {
                Ok(received) if accept(&received.state) => return received.state,
                _ => {}
            }
        }
    };
    tokio::time::timeout(WATCHDOG, run).await.expect("the robot reached the state in time")
}

#[tokio::test]
async fn stands_up_from_lying_with_strictly_decoded_state() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let mut link = client(&sim).await;
    let standing = until(&mut link, HighLevelCommand::stand_up(), |s| s.mode() == ControlMode::Stand).await;
    assert_eq!(standing.error(), None);
    assert!(!standing.has_sdk_mismatch());
    let tall = until(&mut link, HighLevelCommand::stand_up(), |s| s.position[2].get() > 0.29).await;
    assert_eq!(tall.mode(), ControlMode::Stand);
    let stats = link.stats();
    assert_eq!((stats.decode_errors, stats.foreign_dropped), (0, 0));
    let snapshot = sim.snapshot();
    assert_eq!(snapshot.high_level.invalid, 0, "every command decoded strictly by the robot");
    assert_eq!(snapshot.high_level.client, link.local_addr().ok(), "the robot learned whom to answer");
}

#[tokio::test]
async fn faults_show_on_the_wire() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let mut link = client(&sim).await;
    until(&mut link, HighLevelCommand::default(), |_| true).await;

    sim.inject(Zsl1Fault::ErrorWord(ReturnCode::MotorFault));
    let faulted = until(&mut link, HighLevelCommand::default(), |s| s.error().is_some()).await;
    assert_eq!(faulted.error(), Some(ReturnCode::MotorFault));
    sim.clear_faults();

    sim.inject(Zsl1Fault::Garbage);
    let junk = async {
        loop {
            // States already on their way come first.
            if let Err(e) = link.recv().await {
                return e;
            }
        }
    };
    let junk = tokio::time::timeout(WATCHDOG, junk).await.expect("junk in time");
    // Longer than any state: seen as over-long (the transport reads one byte more than it needs).
    assert!(matches!(junk, UdpError::Decode(DatagramError::Length { expected: 560, found: 561 })), "{junk:?}");
    sim.clear_faults();

    sim.inject(Zsl1Fault::Silence);
    // Drain what was already on its way, then nothing more arrives.
    while tokio::time::timeout(Duration::from_millis(50), link.recv()).await.is_ok() {}
    assert!(tokio::time::timeout(Duration::from_millis(100), link.recv()).await.is_err(), "a silent robot");
    sim.clear_faults();
    until(&mut link, HighLevelCommand::default(), |_| true).await;
}

#[test]
fn the_state_stream_keeps_its_ticks_while_the_api_is_hammered() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let api = || {
        let _ = sim.snapshot();
        sim.inject(Zsl1Fault::ErrorWord(ReturnCode::MotorFault));
        sim.set_battery_percent(50.0);
        sim.clear_faults();
    };
    let before = sim.snapshot();
    let after = hammer::while_hammering(api, || {
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        runtime.block_on(async {
            let mut link = client(&sim).await;
            let start = Instant::now();
            loop {
                // A command now and then: the robot streams to whoever commands it.
                link.send(&HighLevelCommand::default()).await.unwrap();
                let _ = tokio::time::timeout(Duration::from_millis(20), link.recv()).await;
                let now = sim.snapshot();
                if now.cycles >= before.cycles + 500 && now.high_level.states_sent >= 250 {
                    return now;
                }
                assert!(start.elapsed() < WATCHDOG, "the stream stalled: {now:?}");
            }
        })
    });
    let (ran, missed) = (after.cycles - before.cycles, after.missed_cycles - before.missed_cycles);
    assert!(missed < ran / 2, "{missed} ticks skipped while {ran} ran");
    // The hammer's last call was a clear, after the battery was set: both in force.
    let last = sim.snapshot().robot;
    assert_eq!(last.faults(), Default::default());
    assert_eq!(last.battery_percent().ceil(), 50.0);
}

/// The module's old name and its `Dog*` types, kept as deprecated aliases for one release:
/// code written against them still builds and drives the same simulator.
#[tokio::test]
#[allow(deprecated)]
async fn the_old_dog_names_still_work() {
    use robowire_sim::dog::{DogFault, DogModel, DogSim, DogSimConfig, DogSnapshot};
    let sim: DogSim = DogSim::spawn(DogSimConfig { model: Model::Zsl1, ..DogSimConfig::loopback() }).unwrap();
    let _: &Zsl1Sim = &sim;
    let mut link = client(&sim).await;
    until(&mut link, HighLevelCommand::default(), |_| true).await;
    sim.inject(DogFault::ErrorWord(ReturnCode::MotorFault));
    let faulted = until(&mut link, HighLevelCommand::default(), |s| s.error().is_some()).await;
    assert_eq!(faulted.error(), Some(ReturnCode::MotorFault));
    let snapshot: DogSnapshot = sim.snapshot();
    let robot: DogModel = snapshot.robot;
    assert_eq!(robot.faults().error_word, Some(ReturnCode::MotorFault));
}

/// The state stream reads both ports itself: every command and every bad datagram is counted,
/// on each port, and the LowLevel port answers a changed command too.
#[tokio::test]
async fn commands_and_junk_on_both_ports_are_counted() {
    use robowire_fixtures::wait::until_async;
    use zsl_proto::udp::{LowLevelCommand, LowLevelState, MotorCommand};
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let mut high = client(&sim).await;
    for _ in 0..5 {
        high.send(&HighLevelCommand::default()).await.unwrap();
    }
    let junk = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    junk.send_to(&[0xEE; 7], sim.high_level_addr()).unwrap();
    junk.send_to(&[0xEE; 7], sim.low_level_addr()).unwrap();

    let codec = ClientCodec::<LowLevelCommand, LowLevelState>::new(Model::Zsl1, StateDecoding::Strict);
    let mut low =
        UdpLink::bind("127.0.0.1:0".parse().unwrap(), Peer::AnyPortOf(sim.low_level_addr()), codec).await.unwrap();
    let hold = LowLevelCommand::new(MotorCommand::pd_hold([[0.0; 4], [0.8; 4], [-1.5; 4]], [80.0; 3], [1.0; 3]));
    low.send(&hold).await.unwrap();
    let answer = tokio::time::timeout(WATCHDOG, low.recv()).await.expect("a LowLevel state in time");
    assert!(answer.is_ok(), "{answer:?}");

    let counted = || {
        let s = sim.snapshot();
        (s.high_level.commands, s.high_level.invalid, s.low_level.commands, s.low_level.invalid) == (5, 1, 1, 1)
    };
    until_async(WATCHDOG, "5 + 1 commands and 2 junk datagrams counted", counted).await;
    assert_eq!(sim.snapshot().low_level.client, low.local_addr().ok(), "the LowLevel port learned whom to answer");
}

#[tokio::test]
async fn a_taken_port_is_a_bind_error_inside_a_task_too() {
    let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).unwrap();
    let taken = Zsl1SimConfig { high_level_port: sim.high_level_addr().port(), ..Zsl1SimConfig::loopback() };
    let error = Zsl1Sim::spawn(taken).unwrap_err();
    assert_eq!(error.kind(), std::io::ErrorKind::AddrInUse, "{error}");
    assert!(error.to_string().contains("cannot bind"), "{error}");
}
