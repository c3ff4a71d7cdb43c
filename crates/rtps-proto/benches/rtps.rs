//! A 1 KB best-effort sample through the RTPS core, beside a memcpy of its datagram from the same
//! run: the writer's `write` (datagram into the caller's buffer), the reader's receive path
//! (parse, handle, event), and the wire layer's parse alone.

// `criterion_group!` generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;
use std::net::SocketAddr;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use rtps_proto::discovery::{History, Qos, Reliability};
use rtps_proto::participant::{Destination, Event, Participant, ParticipantConfig};
use rtps_proto::wire::{Data, Message, Payload, Submessage};
use rtps_proto::{EntityId, GuidPrefix, Locator, Time};

/// The serialized sample handed to `write`: the 4-byte encapsulation header and 1020 bytes.
const SAMPLE_LEN: usize = 1024;
const TOPIC: &str = "rt/bench";
const TYPE: &str = "robowire::bench::Blob_";

fn config(n: u8) -> ParticipantConfig {
    let mut c = ParticipantConfig::new(GuidPrefix([n; 12]), 0);
    let addr: SocketAddr = format!("127.0.0.1:{}", 7400 + 10 * u16::from(n)).parse().unwrap();
    c.metatraffic_unicast = vec![Locator::udp(addr)];
    c.default_unicast = c.metatraffic_unicast.clone();
    c
}

/// The writer participant and its best-effort writer.
struct Tx {
    now: Time,
    participant: Participant,
    writer: EntityId,
}

/// The reader participant and its best-effort reader.
struct Rx {
    now: Time,
    participant: Participant,
    reader: EntityId,
    source: SocketAddr,
}

/// A writer participant and a reader participant, discovered and matched in memory
/// (best-effort, KEEP_LAST 1), with no event left to poll.
fn matched_pair() -> (Tx, Rx) {
    let now = Time::from_nanos(1_000_000_000);
    let mut a = Participant::new(config(1), now);
    let mut b = Participant::new(config(2), now);
    let qos = Qos { history: History::KeepLast { depth: 1 }, reliability: Reliability::BestEffort, ..Qos::default() };
    let writer = a.create_writer(now, TOPIC, TYPE, qos.clone()).unwrap();
    let reader = b.create_reader(now, TOPIC, TYPE, qos).unwrap();
    let source: SocketAddr = "127.0.0.1:7410".parse().unwrap();
    let mut buf = vec![0u8; 65_536];
    for _ in 0..20 {
        while let Some(t) = a.poll_transmit(now, &mut buf) {
            b.handle_datagram(now, source, Destination::Unicast, &buf[..t.len]);
        }
        while let Some(t) = b.poll_transmit(now, &mut buf) {
            a.handle_datagram(now, source, Destination::Unicast, &buf[..t.len]);
        }
    }
    assert_eq!(a.matched_readers(writer).count(), 1, "the writer matched the reader");
    assert_eq!(b.matched_writers(reader).count(), 1, "the reader matched the writer");
    while a.poll_event().is_some() {}
    while b.poll_event().is_some() {}
    (Tx { now, participant: a, writer }, Rx { now, participant: b, reader, source })
}

impl Tx {
    /// Writes `sample` and returns the length of its datagram in `buf`.
    fn write(&mut self, sample: &[u8], buf: &mut [u8]) -> usize {
        let written = self.participant.write(self.now, self.writer, sample, &Default::default(), buf).unwrap();
        written.transmit.expect("a matched reader").len
    }
}

impl Rx {
    /// The reader's side of one datagram: parse and handle it, poll its events, give the sample's
    /// buffer back. Returns the number of samples delivered.
    fn receive(&mut self, datagram: &[u8]) -> usize {
        self.participant.handle_datagram(self.now, self.source, Destination::Unicast, datagram);
        let mut samples = 0;
        while let Some(e) = self.participant.poll_event() {
            if let Event::Sample(s) = e {
                samples += 1;
                self.participant.recycle(s.payload);
            }
        }
        samples
    }
}

/// The payload bytes of every DATA in `datagram` (the wire layer alone).
fn parse_wire(datagram: &[u8]) -> usize {
    let Ok(message) = Message::parse(datagram) else { return 0 };
    let mut bytes = 0;
    for submessage in message.submessages() {
        if let Ok(Submessage::Data(Data { payload: Payload::Data(payload), .. })) = submessage {
            bytes += payload.len();
        }
    }
    bytes
}

fn benches(c: &mut Criterion) {
    let (mut tx, mut rx) = matched_pair();
    let mut sample = vec![0u8; SAMPLE_LEN];
    sample[1] = 1; // CDR_LE
    for (i, b) in sample.iter_mut().enumerate().skip(4) {
        *b = i as u8;
    }
    // One datagram, checked end to end: it carries the sample, and the reader delivers it.
    let mut buf = vec![0u8; 65_536];
    let len = tx.write(&sample, &mut buf);
    let datagram = buf[..len].to_vec();
    assert_eq!(parse_wire(&datagram), SAMPLE_LEN, "one DATA carrying the whole sample");
    assert_eq!(rx.receive(&datagram), 1, "the reader delivers the sample");

    let mut group = c.benchmark_group("rtps");
    // Every bench moves the same datagram; xtask reads its length from here.
    group.throughput(Throughput::Bytes(datagram.len() as u64));

    // The writer participant makes each iteration's datagram (a fresh, increasing sequence
    // number) in `iter_batched_ref`'s setup, which criterion does not time; the datagram is
    // dropped after timing too. The timed routine is the reader participant's receive path
    // alone: parse, handle (best-effort reader, in order), the Sample event, recycle.
    let (mut written, mut delivered) = (0usize, 0usize);
    group.bench_function("parse_handle_data_1KB", |b| {
        b.iter_batched_ref(
            || {
                let mut out = vec![0u8; 2 * len];
                let n = tx.write(&sample, &mut out);
                out.truncate(n);
                written += 1;
                out
            },
            |datagram| delivered += rx.receive(black_box(datagram)),
            BatchSize::SmallInput,
        )
    });
    assert_eq!(delivered, written, "every datagram delivered one sample");
    let lost = rx.participant.reader_counters(rx.reader).map(|c| c.lost);
    assert_eq!(lost, Some(0), "no sample counted lost");

    group.bench_function("write_1KB", |b| b.iter(|| tx.write(black_box(&sample), &mut buf)));

    let mut out = vec![0u8; datagram.len()];
    group.bench_function("memcpy_1KB", |b| {
        b.iter(|| {
            out.copy_from_slice(black_box(&datagram));
            black_box(&out);
        })
    });

    group.bench_function("wire_parse_1KB", |b| b.iter(|| parse_wire(black_box(&datagram))));
    group.finish();
}

criterion_group!(rtps, benches);
criterion_main!(rtps);
