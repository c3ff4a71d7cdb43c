//! Participants discovering, matching and exchanging samples in an in-memory world on a fake
//! clock, with seeded loss, duplication and reordering.

mod net;

use std::time::Duration;

use net::{Faults, World};
use rtps_proto::discovery::{Durability, History, Qos, Reliability};
use rtps_proto::endpoint::{SampleIdentity, WriteError, WriteMode, WriteOptions};
use rtps_proto::participant::{Event, LostReason, MatchError, Written};
use rtps_proto::types::DdsDuration;
use rtps_proto::wire::{Message, Submessage};
use rtps_proto::{EntityId, Guid, SequenceNumber, Timestamp};

const TOPIC: &str = "rt/lowstate";
const TYPE: &str = "unitree_go::msg::dds_::LowState_";

fn reliable(depth: u32) -> Qos {
    Qos {
        reliability: Reliability::Reliable { max_blocking_time: DdsDuration::ZERO },
        history: History::KeepLast { depth },
        ..Qos::default()
    }
}

fn best_effort(depth: u32) -> Qos {
    Qos { reliability: Reliability::BestEffort, ..reliable(depth) }
}

fn transient_local(depth: u32) -> Qos {
    Qos { durability: Durability::TransientLocal, ..reliable(depth) }
}

/// A CDR payload (XCDR1 little-endian header) carrying `n` and `len - 8` filler bytes (`len` a
/// multiple of 4).
fn payload(n: u32, len: usize) -> Vec<u8> {
    let mut p = vec![0, 1, 0, 0];
    p.extend(n.to_le_bytes());
    p.extend((8..len.max(8)).map(|i| (i as u32 ^ n) as u8));
    p
}

fn samples(w: &World, node: usize, reader: EntityId) -> Vec<Vec<u8>> {
    w.nodes[node]
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Sample(s) if s.info.reader == reader => Some(s.payload.clone()),
            _ => None,
        })
        .collect()
}

fn matched(w: &World, node: usize, local: EntityId) -> usize {
    w.nodes[node].events.iter().filter(|e| matches!(e, Event::Matched { local: l, .. } if *l == local)).count()
}

/// Writes through the participant and sends its own datagram as a stream thread would.
fn write(
    w: &mut World,
    node: usize,
    writer: EntityId,
    bytes: &[u8],
    options: &WriteOptions,
) -> Result<Written, WriteError> {
    let mut buf = vec![0u8; 65_536];
    let now = w.now;
    let written = w.nodes[node].participant.write(now, writer, bytes, options, &mut buf)?;
    if let Some(t) = written.transmit {
        w.inject(node, &buf[..t.len], t.destinations());
    }
    Ok(written)
}

#[test]
fn two_to_five_participants_discover_each_other_and_match() {
    for n in 2..=5 {
        let mut w = World::new(n, n as u64);
        let now = w.now;
        let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(1)).unwrap();
        let readers: Vec<EntityId> =
            (1..n).map(|i| w.nodes[i].participant.create_reader(now, TOPIC, TYPE, reliable(1)).unwrap()).collect();
        let ok = w.run(Duration::from_secs(5), |w| {
            w.all_discovered() && matched(w, 0, writer) == n - 1 && (1..n).all(|i| matched(w, i, readers[i - 1]) == 1)
        });
        assert!(ok, "{n} participants did not all discover and match in 5 s of fake time");
        assert_eq!(w.nodes[0].participant.matched_readers(writer).count(), n - 1);
    }
}

#[test]
fn reliable_samples_arrive_once_and_in_order_under_loss_duplication_and_reordering() {
    for seed in 1..=12 {
        let mut w = World::new(2, seed);
        let now = w.now;
        // Deep enough that no sample is replaced before it is acknowledged.
        let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(256)).unwrap();
        let reader = w.nodes[1].participant.create_reader(now, TOPIC, TYPE, reliable(256)).unwrap();
        assert!(w.run(Duration::from_secs(5), |w| matched(w, 0, writer) == 1 && matched(w, 1, reader) == 1));
        w.faults = Faults { loss: 0.2, duplicate: 0.1, reorder: 0.2, max_delay: Duration::from_millis(5) };
        let sent: Vec<Vec<u8>> = (0..200).map(|i| payload(i, 100)).collect();
        for s in &sent {
            write(&mut w, 0, writer, s, &WriteOptions::default()).unwrap();
            w.advance(Duration::from_millis(2));
        }
        let ok = w.run(Duration::from_secs(30), |w| samples(w, 1, reader).len() >= sent.len());
        assert!(
            ok,
            "seed {seed}: {} of 200 samples arrived; writer {:?}; reader {:?}; {:?} / {:?}",
            samples(&w, 1, reader).len(),
            w.nodes[0].participant.writer_counters(writer),
            w.nodes[1].participant.reader_counters(reader),
            w.nodes[0].participant.counters(),
            w.nodes[1].participant.counters(),
        );
        assert_eq!(samples(&w, 1, reader), sent, "seed {seed}: every sample once, in order");
        let c = w.nodes[1].participant.reader_counters(reader).unwrap();
        assert_eq!(c.delivered, 200);
    }
}

#[test]
fn best_effort_samples_arrive_in_order_and_losses_are_counted() {
    let mut w = World::new(2, 7);
    let now = w.now;
    let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, best_effort(1)).unwrap();
    let reader = w.nodes[1].participant.create_reader(now, TOPIC, TYPE, best_effort(1)).unwrap();
    assert!(w.run(Duration::from_secs(5), |w| matched(w, 0, writer) == 1 && matched(w, 1, reader) == 1));
    w.faults = Faults { loss: 0.3, duplicate: 0.2, ..Faults::default() };
    for i in 0..300 {
        write(&mut w, 0, writer, &payload(i, 64), &WriteOptions::default()).unwrap();
        w.advance(Duration::from_millis(2));
    }
    w.advance(Duration::from_millis(100));
    let got: Vec<u32> =
        samples(&w, 1, reader).iter().map(|p| u32::from_le_bytes(p[4..8].try_into().unwrap())).collect();
    assert!(got.windows(2).all(|p| p[0] < p[1]), "in order, no duplicates");
    assert!(got.len() > 100 && got.len() < 300, "about 70 % of 300 arrived: {}", got.len());
    let c = w.nodes[1].participant.reader_counters(reader).unwrap();
    assert_eq!(c.delivered as usize, got.len());
    assert!(c.lost > 0 && c.duplicates > 0, "{c:?}");
}

#[test]
fn fragmented_samples_are_reassembled_when_fragments_are_lost_and_reordered() {
    for seed in 1..=12 {
        fragments_with_seed(seed);
    }
}

fn fragments_with_seed(seed: u64) {
    // Two fragments to a datagram, so that a sample can arrive in part.
    let mut w = World::configured(2, seed, |c| c.max_message_size = 3000);
    let now = w.now;
    let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(16)).unwrap();
    let reader = w.nodes[1].participant.create_reader(now, TOPIC, TYPE, reliable(16)).unwrap();
    assert!(w.run(Duration::from_secs(5), |w| matched(w, 0, writer) == 1 && matched(w, 1, reader) == 1));
    w.faults = Faults { loss: 0.15, duplicate: 0.05, reorder: 0.3, max_delay: Duration::from_millis(3) };
    let sent: Vec<Vec<u8>> = (0..10).map(|i| payload(i, 5000 + i as usize * 8)).collect();
    for s in &sent {
        let written = write(&mut w, 0, writer, s, &WriteOptions::default()).unwrap();
        assert!(written.transmit.is_none(), "a sample above the fragment size goes out through poll_transmit");
        w.advance(Duration::from_millis(5));
    }
    let ok = w.run(Duration::from_secs(30), |w| samples(w, 1, reader).len() >= sent.len());
    assert!(
        ok,
        "seed {seed}: {} of 10 arrived; writer {:?}; reader {:?}",
        samples(&w, 1, reader).len(),
        w.nodes[0].participant.writer_counters(writer),
        w.nodes[1].participant.reader_counters(reader),
    );
    assert_eq!(samples(&w, 1, reader), sent);
}

#[test]
fn a_fragmented_sample_goes_in_as_few_datagrams_as_the_message_size_allows() {
    for (max_message_size, datagrams) in [(14720, vec![3]), (3000, vec![2, 1])] {
        let mut w = World::configured(2, 1, |c| c.max_message_size = max_message_size);
        let now = w.now;
        let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(4)).unwrap();
        let reader = w.nodes[1].participant.create_reader(now, TOPIC, TYPE, reliable(4)).unwrap();
        assert!(w.run(Duration::from_secs(5), |w| matched(w, 0, writer) == 1 && matched(w, 1, reader) == 1));
        // An HG LowState's size: three 1344-byte fragments.
        let sample = payload(1, 2096 + 1344);
        let mut buf = vec![0u8; 65_536];
        let now = w.now;
        let written = w.nodes[0].participant.write(now, writer, &sample, &WriteOptions::default(), &mut buf).unwrap();
        assert!(written.transmit.is_none());
        let mut fragments_per_datagram = Vec::new();
        while let Some(t) = w.nodes[0].participant.poll_transmit(now, &mut buf) {
            let message = Message::parse(&buf[..t.len]).unwrap();
            let fragments = message.submessages().filter(|s| matches!(s, Ok(Submessage::DataFrag(_)))).count();
            if fragments > 0 {
                fragments_per_datagram.push(fragments);
            }
            w.inject(0, &buf[..t.len], t.destinations());
        }
        assert_eq!(fragments_per_datagram, datagrams, "max message size {max_message_size}");
        assert!(w.run(Duration::from_secs(1), |w| samples(w, 1, reader) == [sample.clone()]));
    }
}

#[test]
fn a_reader_that_stops_acknowledging_never_makes_a_write_wait() {
    let mut w = World::new(2, 5);
    let now = w.now;
    let keep_last = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(4)).unwrap();
    let refuse = w.nodes[0]
        .participant
        .create_writer_with(now, "rt/arm_sdk", TYPE, reliable(4), WriteMode::RefuseWhenFull)
        .unwrap();
    w.nodes[1].participant.create_reader(now, TOPIC, TYPE, reliable(4)).unwrap();
    w.nodes[1].participant.create_reader(now, "rt/arm_sdk", TYPE, reliable(4)).unwrap();
    assert!(w.run(Duration::from_secs(5), |w| matched(w, 0, keep_last) == 1 && matched(w, 0, refuse) == 1));
    w.nodes[1].muted = true; // no more ACKNACKs
    for i in 0..20 {
        write(&mut w, 0, keep_last, &payload(i, 64), &WriteOptions::default()).expect("keep-last never refuses");
    }
    let c = w.nodes[0].participant.writer_counters(keep_last).unwrap();
    assert_eq!(c.written, 20);
    assert!(c.replaced_unacknowledged >= 16, "{c:?}");
    let results: Vec<_> =
        (0..20).map(|i| write(&mut w, 0, refuse, &payload(i, 64), &WriteOptions::default()).map(|_| ())).collect();
    assert!(results[..4].iter().all(Result::is_ok));
    assert!(results[4..].iter().all(|r| *r == Err(WriteError::HistoryFull { depth: 4 })), "{results:?}");
    assert_eq!(w.nodes[0].participant.writer_counters(refuse).unwrap().refused_full, 16);
}

#[test]
fn a_silent_participant_expires_with_its_lease_and_its_matches_end() {
    let mut w = World::new(2, 9);
    let now = w.now;
    let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(1)).unwrap();
    w.nodes[1].participant.create_reader(now, TOPIC, TYPE, reliable(1)).unwrap();
    assert!(w.run(Duration::from_secs(5), |w| matched(w, 0, writer) == 1));
    w.nodes[1].muted = true;
    let lost = |w: &World| {
        w.nodes[0].events.iter().any(|e| matches!(e, Event::ParticipantLost { reason: LostReason::LeaseExpired, .. }))
    };
    assert!(!w.run(Duration::from_secs(19), lost), "not before the 20 s lease");
    assert!(w.run(Duration::from_secs(2), lost), "lost once the lease is over");
    assert!(w.nodes[0].events.iter().any(|e| matches!(e, Event::Unmatched { local, .. } if *local == writer)));
    assert_eq!(w.nodes[0].participant.matched_readers(writer).count(), 0);
    assert_eq!(w.nodes[0].participant.remote_participants().count(), 0);
}

#[test]
fn a_late_joiner_gets_a_transient_local_writers_history() {
    let mut w = World::new(1, 3);
    let now = w.now;
    let writer = w.nodes[0].participant.create_writer(now, "ros_discovery_info", TYPE, transient_local(5)).unwrap();
    let sent: Vec<Vec<u8>> = (0..8).map(|i| payload(i, 40)).collect();
    for s in &sent {
        write(&mut w, 0, writer, s, &WriteOptions::default()).unwrap();
    }
    w.advance(Duration::from_secs(1));
    let late = w.add(net::config(1));
    let now = w.now;
    let reader = w.nodes[late].participant.create_reader(now, "ros_discovery_info", TYPE, transient_local(5)).unwrap();
    assert!(w.run(Duration::from_secs(10), |w| samples(w, late, reader).len() >= 5));
    assert_eq!(samples(&w, late, reader), sent[3..], "the history's last 5, in order");
    // A volatile late joiner gets only what is written after it matched.
    let volatile_node = w.add(net::config(2));
    let now = w.now;
    let volatile =
        w.nodes[volatile_node].participant.create_reader(now, "ros_discovery_info", TYPE, reliable(5)).unwrap();
    assert!(w.run(Duration::from_secs(10), |w| matched(w, volatile_node, volatile) == 1));
    w.advance(Duration::from_secs(1));
    write(&mut w, 0, writer, &payload(99, 40), &WriteOptions::default()).unwrap();
    assert!(w.run(Duration::from_secs(5), |w| !samples(w, volatile_node, volatile).is_empty()));
    w.advance(Duration::from_secs(1));
    assert_eq!(samples(&w, volatile_node, volatile), vec![payload(99, 40)]);
}

#[test]
fn a_qos_mismatch_is_reported_with_its_reason_and_nothing_is_matched() {
    let mut w = World::new(2, 4);
    let now = w.now;
    let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, best_effort(1)).unwrap();
    let reader = w.nodes[1].participant.create_reader(now, TOPIC, TYPE, reliable(1)).unwrap();
    let other_type = w.nodes[1].participant.create_reader(now, TOPIC, "other::Type", best_effort(1)).unwrap();
    let reported = |w: &World| {
        w.nodes[1].events.iter().any(|e| {
            matches!(e, Event::Incompatible { local, reason: MatchError::Qos(_), .. } if *local == reader)
        }) && w.nodes[0].events.iter().any(|e| matches!(e, Event::Incompatible { local, .. } if *local == writer))
            && w.nodes[1].events.iter().any(
                |e| matches!(e, Event::Incompatible { local, reason: MatchError::TypeName, .. } if *local == other_type),
            )
    };
    assert!(w.run(Duration::from_secs(5), reported));
    assert_eq!(matched(&w, 0, writer), 0);
    assert_eq!(matched(&w, 1, reader), 0);
    let reason = w.nodes[1]
        .events
        .iter()
        .find_map(|e| match e {
            Event::Incompatible { local, reason, .. } if *local == reader => Some(reason.to_string()),
            _ => None,
        })
        .unwrap();
    assert!(reason.contains("reliab"), "{reason}");
}

#[test]
fn related_sample_identity_and_source_timestamp_reach_the_reader() {
    let mut w = World::new(2, 6);
    let now = w.now;
    let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(4)).unwrap();
    let reader = w.nodes[1].participant.create_reader(now, TOPIC, TYPE, reliable(4)).unwrap();
    assert!(w.run(Duration::from_secs(5), |w| matched(w, 0, writer) == 1 && matched(w, 1, reader) == 1));
    let related = SampleIdentity {
        writer: Guid::new(w.nodes[1].participant.guid_prefix(), reader),
        sequence: SequenceNumber(77),
    };
    let ts = Timestamp { seconds: 1_700_000_000, fraction: 0x8000_0000 };
    let options = WriteOptions { source_timestamp: Some(ts), related: Some(related), key_hash: None };
    let sn = write(&mut w, 0, writer, &payload(1, 16), &options).unwrap().sequence;
    assert!(w.run(Duration::from_secs(1), |w| !samples(w, 1, reader).is_empty()));
    let info = w.nodes[1]
        .events
        .iter()
        .find_map(|e| match e {
            Event::Sample(s) => Some(s.info),
            _ => None,
        })
        .unwrap();
    assert_eq!(info.sequence, sn);
    assert_eq!(info.related, Some(related));
    assert_eq!(info.source_timestamp, Some(ts));
    assert_eq!(info.writer, Guid::new(w.nodes[0].participant.guid_prefix(), writer));
}

#[test]
fn an_unpadded_payload_is_refused() {
    let mut w = World::new(1, 1);
    let now = w.now;
    let writer = w.nodes[0].participant.create_writer(now, TOPIC, TYPE, reliable(1)).unwrap();
    let refused = write(&mut w, 0, writer, &[0, 1, 0, 0, 7], &WriteOptions::default());
    assert_eq!(refused, Err(WriteError::Unaligned { len: 5 }));
}

#[test]
fn participant_user_data_is_announced_and_seen() {
    let mut w = World::new(1, 8);
    let mut c = net::config(1);
    c.user_data = b"enclave=/;".to_vec();
    w.add(c);
    assert!(w.run(Duration::from_secs(5), World::all_discovered));
    let seen: Vec<_> = w.nodes[0].participant.remote_participants().map(|p| p.user_data.clone()).collect();
    assert_eq!(seen, vec![b"enclave=/;".to_vec()]);
}
