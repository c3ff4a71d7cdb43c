//! The DDS replay device from a raw reader in a private network (`robowire_dds::netns`): the
//! recorded LowState payloads arrive byte for byte (header, body, CRC: a broken one stays
//! broken; XCDR1 or XCDR2 as recorded), in order, once a reader matched (a reliable one: every
//! payload, none lost); the client's LowCmds are counted; a payload that is not CDR is refused
//! before anything is published.

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_sim::replay::{DdsReplay, DdsTopic, Pace, ReplayError};
use unitree_proto::{CdrEncoding, LowCmd, LowState, Message};

/// Every wait is bounded, so a broken player fails the test instead of hanging it.
const WATCHDOG: Duration = Duration::from_secs(20);

const STATES: DdsTopic<'static> = DdsTopic { name: LowState::TOPIC, type_name: LowState::DDS_TYPE_NAME };
const COMMANDS: DdsTopic<'static> = DdsTopic { name: LowCmd::TOPIC, type_name: LowCmd::DDS_TYPE_NAME };

/// XCDR1 LowState payloads with ticks 0, 2, 4 … ms, `step` apart; the one at `broken` with a
/// flipped bit in its body (its CRC no longer matches).
fn lowstates(count: u32, step: Duration, broken: usize) -> Vec<(Duration, Vec<u8>)> {
    (0..count)
        .map(|i| {
            let mut state = LowState::default();
            state.tick.set(2 * i);
            let mut payload = vec![0u8; LowState::cdr_len(CdrEncoding::Xcdr1)];
            state.encode_cdr(CdrEncoding::Xcdr1, &mut payload).unwrap();
            if i as usize == broken {
                payload[40] ^= 0x10;
            }
            (step * i, payload)
        })
        .collect()
}

#[test]
fn a_reader_receives_every_payload_byte_for_byte_in_order() {
    with_loopback_multicast(|| {
        let lo = ParticipantOptions::new(0, Some("lo"));
        let mut recorded = lowstates(40, Duration::from_millis(2), 7);
        // One recorded as XCDR2 (a Go2 payload from another DDS): sent as it was.
        let mut xcdr2 = vec![0u8; LowState::cdr_len(CdrEncoding::Xcdr2)];
        LowState::default().encode_cdr(CdrEncoding::Xcdr2, &mut xcdr2).unwrap();
        recorded[5].1 = xcdr2;
        let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap();
        runtime.block_on(async {
            let device = DdsReplay::open(lo.clone(), STATES, Some(COMMANDS), recorded.clone()).unwrap();
            assert_eq!((device.frames(), device.matched_readers()), (40, 0));
            let client = Participant::new(lo).unwrap();
            let mut reader = client
                .raw_reader(STATES.name, STATES.type_name, Qos { reliable: true, depth: 64, ..Qos::READER })
                .unwrap();
            let commands = client.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
            tokio::time::timeout(WATCHDOG, device.first_reader(Duration::ZERO))
                .await
                .expect("the reader matched in time");
            // The reader's side has discovered the writer too: what is published from now on reaches it.
            let discovered = || client.discovered_topics().iter().any(|t| t.name == STATES.name && t.writers > 0);
            let began = std::time::Instant::now();
            while !discovered() {
                assert!(began.elapsed() < WATCHDOG, "the reader's side never discovered the writer");
                tokio::time::sleep(Duration::from_millis(5)).await;
            }
            // The command reader is matched once a command goes through: sent until one is counted.
            let play = tokio::spawn(device.play(Pace::Recorded { speed: 1.0 }, Duration::from_millis(300)));
            let mut seen = Vec::new();
            while seen.len() < recorded.len() {
                commands.write(LowCmd::default()).unwrap();
                let sample = tokio::time::timeout(WATCHDOG, reader.recv()).await;
                let sample = sample.unwrap_or_else(|_| panic!("after {} of 40 payloads", seen.len())).unwrap();
                seen.push(sample.value);
            }
            let summary = tokio::time::timeout(WATCHDOG, play).await.expect("played in time").unwrap().unwrap();
            assert_eq!((summary.frames, summary.sent, summary.client), (40, 40, None));
            assert!(summary.commands > 0, "the client's LowCmds counted: {summary:?}");
            for (i, ((_, payload), sample)) in recorded.iter().zip(&seen).enumerate() {
                let encoding = if i == 5 { CdrEncoding::Xcdr2 } else { CdrEncoding::Xcdr1 };
                assert_eq!(sample.encoding, encoding);
                assert_eq!(sample.body, payload[4..], "the body as recorded");
            }
            let checked: Vec<bool> =
                seen.iter().map(|s| LowState::decode_cdr_body(s.encoding, &s.body).is_ok()).collect();
            assert_eq!(checked.iter().filter(|ok| !**ok).count(), 1, "the broken CRC stayed broken");
            assert!(!checked[7]);
        });
    });
}

#[test]
fn a_payload_that_is_not_cdr_is_refused() {
    // No participant is made before the payloads are checked: no network needed.
    let mut recorded = lowstates(3, Duration::ZERO, usize::MAX);
    recorded.insert(2, (Duration::ZERO, vec![0, 3, 0, 0, 1, 0, 0, 0]));
    recorded.push((Duration::ZERO, vec![0, 1]));
    let lo = ParticipantOptions::new(0, Some("lo"));
    match DdsReplay::open(lo.clone(), STATES, None, recorded.clone()) {
        Err(ReplayError::Encapsulation { index: 2, found }) => assert_eq!(found, [0, 3, 0, 0]),
        other => panic!("{other:?}"),
    }
    recorded.remove(2);
    match DdsReplay::open(lo, STATES, None, recorded) {
        Err(ReplayError::Encapsulation { index: 3, found }) => assert_eq!(found, [0, 1]),
        other => panic!("{other:?}"),
    }
}
