//! Every vendor call in `fixtures/zsl1/frames.json` puts exactly its captured datagram on the
//! wire through robowire's facade, with the vendor's return value, against a scripted dog on
//! loopback that reports the mode the capture recorded. Where robowire deliberately differs
//! (spec decision 1: NaN is refused), the test checks the difference.

use std::net::{SocketAddr, UdpSocket};
use std::time::{Duration, Instant};

use robowire_fixtures::zsl1::{frames, motor_command, vendor_call};
use serde_json::Value;
use zsl::udp::{
    CallError, ClientOptions, ControlMode, HighLevel, Latched, LowLevel, Model, MotorCommand, ReturnCode, StateDecoding,
};
use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelState};

fn fixtures() -> Vec<Value> {
    frames().unwrap()
}

fn hex(s: &str) -> Vec<u8> {
    robowire_fixtures::hex_bytes(s).unwrap()
}

/// A scripted dog: receives commands, sends the state it is told to.
struct ScriptedDog {
    socket: UdpSocket,
}

impl ScriptedDog {
    fn new() -> Self {
        let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
        socket.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
        Self { socket }
    }

    fn addr(&self) -> SocketAddr {
        self.socket.local_addr().unwrap()
    }

    fn recv(&self) -> Vec<u8> {
        let mut buf = [0u8; 600];
        let (n, _) = self.socket.recv_from(&mut buf).expect("a command datagram within 2 s");
        buf[..n].to_vec()
    }

    fn drain(&self) {
        self.socket.set_nonblocking(true).unwrap();
        let mut buf = [0u8; 600];
        while self.socket.recv_from(&mut buf).is_ok() {}
        self.socket.set_nonblocking(false).unwrap();
    }

    /// Datagrams until one differs from `previous`, within 1 s.
    fn next_different(&self, previous: &[u8]) -> Vec<u8> {
        let deadline = Instant::now() + Duration::from_secs(1);
        loop {
            let d = self.recv();
            if d != previous || Instant::now() > deadline {
                return d;
            }
        }
    }

    fn send(&self, bytes: &[u8], to: SocketAddr) {
        self.socket.send_to(bytes, to).unwrap();
    }
}

fn high_state(mode: u32, error_word: u32) -> HighLevelState {
    HighLevelState {
        header: HIGH_LEVEL_STATE_HEADER,
        control_mode: mode.into(),
        error_word: error_word.into(),
        ..HighLevelState::default()
    }
}

async fn high_level(dog: &ScriptedDog, model: Model) -> HighLevel {
    let options = ClientOptions::high_level([127, 0, 0, 1].into(), 0, [127, 0, 0, 1].into())
        .with_model(model)
        .with_state_decoding(StateDecoding::Strict);
    let options = ClientOptions { dog: dog.addr(), ..options };
    HighLevel::open(options).unwrap()
}

/// Makes the client see `mode` (and `error_word`), waiting until it has.
async fn report(dog: &ScriptedDog, client: &HighLevel, mode: u32, error_word: u32) {
    dog.send(&high_state(mode, error_word).encode(), client.local_addr());
    let seen = client
        .wait_for_state(Duration::from_secs(2), move |s| {
            s.body.mode == ControlMode::from_raw(mode) && s.body.error.map_or(0, ReturnCode::raw) == error_word
        })
        .await;
    assert!(seen.is_some(), "the client sees mode {mode}");
}

fn call(client: &HighLevel, name: &str, a: [f32; 4]) -> Result<Latched, CallError> {
    match name {
        "standUp" => client.stand_up(),
        "lieDown" => client.lie_down(),
        "passive" => client.passive(),
        "move" => client.move_velocity(a[0], a[1], a[2]),
        "jump" => client.jump(),
        "frontJump" => client.front_jump(),
        "backflip" => client.backflip(),
        "shakeHand" => client.shake_hand(),
        "twoLegStand" => client.two_leg_stand(a[0], a[1]),
        "cancelTwoLegStand" => client.cancel_two_leg_stand(),
        "attitudeControl" => client.attitude_control(a[0], a[1], a[2], a[3]),
        "crawl" => client.crawl(a[0], a[1], a[2]),
        "climb" => client.climb(a[0], a[1], a[2]),
        "cancelCrawl" => client.cancel_crawl(),
        "cancelClimb" => client.cancel_climb(),
        other => panic!("no facade call for {other}"),
    }
}

/// The vendor's return code of a call: a refusal's, or the latched call's (0, or 0x3007 after 11
/// unacknowledged calls).
fn return_code(result: &Result<Latched, CallError>) -> u32 {
    result.as_ref().map_or_else(|e| e.return_code().raw(), |latched| latched.return_code.raw())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_high_level_call_in_the_fixtures_puts_its_captured_datagram_on_the_wire() {
    let entries = fixtures();
    let mut checked = 0;
    for (i, entry) in entries.iter().enumerate() {
        let api = entry["api"].as_str().unwrap();
        if entry["direction"] != "sdk->dog" || !api.contains("HighLevel") {
            continue;
        }
        let expected = hex(entry["hex"].as_str().unwrap());
        let model = if api.starts_with("ZSL-1W") { Model::Zsl1W } else { Model::Zsl1 };
        let dog = ScriptedDog::new();
        let client = high_level(&dog, model).await;

        if api.contains("idle stream") {
            assert_eq!(dog.recv(), expected, "#{i} {api}: the idle stream starts at once");
            checked += 1;
            continue;
        }
        if api.contains("error word") {
            report(&dog, &client, 18, 0).await;
            client.move_velocity(0.5, 0.0, 0.0).unwrap();
            report(&dog, &client, 18, 0x3012).await;
            dog.drain();
            assert_eq!(dog.recv(), expected, "#{i} {api}: the stream forces mode 0");
            let refused = client.move_velocity(0.5, 0.0, 0.0);
            assert_eq!(return_code(&refused), 0x3012, "#{i}: the call returns the error word");
            checked += 1;
            continue;
        }
        let (name, args, _) = vendor_call(api).unwrap_or_else(|| panic!("#{i}: cannot parse {api}"));
        // The ZSL-1W captures record no dog mode: the dog stands.
        let mode = entry["dog_state_ctrl_mode"].as_u64().unwrap_or(1) as u32;
        report(&dog, &client, mode, 0).await;
        let idle = dog.recv();
        let result = call(&client, name, args);
        let vendor_return = entry["return_value"].as_u64();

        if args.iter().any(|a| a.is_nan()) {
            // Spec decision 1: the vendor sends NaN and returns 0; robowire refuses it and sends
            // nothing new.
            assert!(
                matches!(result, Err(CallError::Refused(zsl::udp::Refusal::Argument(_)))),
                "#{i} {api}: {result:?}"
            );
            dog.drain();
            assert_eq!(dog.recv(), idle, "#{i}: the previous command keeps streaming");
            checked += 1;
            continue;
        }
        if let Some(code) = vendor_return {
            assert_eq!(u64::from(return_code(&result)), code, "#{i} {api}: return value {result:?}");
        }
        if vendor_return == Some(u64::from(ReturnCode::SpeedTooLarge.raw())) {
            // Refused: the wire carries the previous command the note names, still latched.
            let note = entry["note"].as_str().unwrap();
            let previous_call = format!("HighLevel.{}", note.split("previous command, ").nth(1).unwrap());
            let (previous, args, _) = vendor_call(&previous_call).unwrap();
            let fresh = dog_for_previous(model, previous, args).await;
            assert_eq!(fresh, expected, "#{i}: the previous command's datagram");
            dog.drain();
            assert_eq!(dog.recv(), idle, "#{i}: nothing new was sent");
            checked += 1;
            continue;
        }
        let sent = dog.next_different(&idle);
        if api.contains("frame group 2") {
            // After the automatic clear: count the datagrams with the action first.
            let mut with_action = 1;
            let mut d = dog.recv();
            while d == sent {
                with_action += 1;
                d = dog.recv();
            }
            assert_eq!(with_action, 6, "#{i} {api}: the action goes out in exactly 6 datagrams");
            assert_eq!(d, expected, "#{i} {api}");
        } else {
            assert_eq!(sent, expected, "#{i} {api}");
        }
        checked += 1;
    }
    assert_eq!(checked, 27, "every HighLevel command fixture was exercised");
}

/// The datagram of `name(args)` from a fresh client standing in mode 1 (for the refused call's
/// "previous command").
async fn dog_for_previous(model: Model, name: &str, args: [f32; 4]) -> Vec<u8> {
    let dog = ScriptedDog::new();
    let client = high_level(&dog, model).await;
    report(&dog, &client, 1, 0).await;
    let idle = dog.recv();
    call(&client, name, args).unwrap();
    dog.next_different(&idle)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_low_level_call_in_the_fixtures_puts_its_captured_datagram_on_the_wire() {
    let mut checked = 0;
    for entry in fixtures() {
        let api = entry["api"].as_str().unwrap();
        if entry["direction"] != "sdk->dog" || !api.contains("LowLevel") {
            continue;
        }
        let expected = hex(entry["hex"].as_str().unwrap());
        let dog = ScriptedDog::new();
        let options = ClientOptions::low_level([127, 0, 0, 1].into(), 0, [127, 0, 0, 1].into());
        let client = LowLevel::open(ClientOptions { dog: dog.addr(), ..options }).unwrap();
        let idle = dog.recv();
        if api.contains("idle stream") {
            assert_eq!(idle, expected, "{api}");
        } else {
            assert!(vendor_call(api).is_some_and(|(name, ..)| name == "sendMotorCmd"));
            let motor = MotorCommand::from(&motor_command(api).unwrap());
            client.send_motor_command(&motor).unwrap();
            assert_eq!(dog.next_different(&idle), expected, "{api}");
        }
        checked += 1;
    }
    assert_eq!(checked, 3);
}
