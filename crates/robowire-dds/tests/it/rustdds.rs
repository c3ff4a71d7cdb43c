//! rustdds 0.15.1 (an independent DDS on its own RTPS) against robowire-dds, both in this test
//! process, each scenario in a private network namespace (`netns`): discovery both ways, Go2
//! LowCmd/LowState best effort and reliable both ways, a fragmented HG LowState both ways,
//! transient-local late joiners, a reliability mismatch, and the rustdds participant leaving and
//! coming back. rustdds's side writes and reads raw payload bytes, compared byte for byte with
//! what robowire's codec encodes.

use std::convert::Infallible;
use std::net::{IpAddr, Ipv4Addr};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use futures::FutureExt;
use robowire_core::cdr::CdrType;
use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions, Reader};
use robowire_fixtures::wait::{runtime, some_async};
use rustdds::bytes::Bytes;
use rustdds::no_key::{DataWriter, Decode, DefaultDecoder, DeserializerAdapter, SerializerAdapter, SimpleDataReader};
use rustdds::policy::{Durability, History, Reliability};
use rustdds::{
    DataReaderStatus, DataWriterStatus, DomainParticipant, DomainParticipantBuilder, QosPolicies, QosPolicyBuilder,
    RTPSEntity, RepresentationIdentifier, StatusEvented, TopicKind,
};
use unitree_proto::{CdrEncoding, HgLowState, LowCmd, LowState, Message};

// Each test uses a domain of its own, 21 to 27, apart from the other modules' (0 and fastdds.rs's
// 1 to 11): where `lo` already carries multicast, the tests of this binary share this namespace
// and would otherwise meet.

/// How long anything may take before the test fails (a watchdog, not a measurement).
const WAIT: Duration = Duration::from_secs(30);
/// How long a dropped rustdds participant may take to be forgotten: at once when its dispose goes
/// out, its announced lease (5 × its 10 s announcement period) when its drop dies before that
/// (rustdds 0.15.1's discovery thread can end up joining itself: "failed to join thread:
/// Resource deadlock avoided"), and a margin.
const RUSTDDS_GONE: Duration = Duration::from_secs(50 + 20);

/// A payload as rustdds carries it: the representation identifier of its encapsulation header and
/// the bytes after the header (rustdds writes the header's two option bytes as zero and does not
/// hand them to a reader).
#[derive(Debug, Clone, PartialEq, Eq)]
struct Payload {
    representation: [u8; 2],
    body: Vec<u8>,
}

impl Payload {
    /// The payload robowire's codec encodes for `message` (XCDR1, as robowire's writers send it).
    fn of<M: Message>(message: &M) -> Self {
        let mut cdr = vec![0u8; M::cdr_len(CdrEncoding::Xcdr1)];
        let n = message.encode_cdr(CdrEncoding::Xcdr1, &mut cdr).unwrap();
        assert_eq!(n, cdr.len());
        assert_eq!(cdr[2..4], [0, 0], "no padding: a body of a multiple of 4 bytes");
        Self { representation: [cdr[0], cdr[1]], body: cdr[4..].to_vec() }
    }
}

/// rustdds's serializer and deserializer adapters for [`Payload`]: bytes in, bytes out.
struct RawAdapter;

impl SerializerAdapter<Payload> for RawAdapter {
    type Error = Infallible;
    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }
    fn to_bytes(value: &Payload) -> Result<Bytes, Infallible> {
        assert_eq!(value.representation, Self::output_encoding().to_bytes());
        Ok(Bytes::copy_from_slice(&value.body))
    }
}

impl DeserializerAdapter<Payload> for RawAdapter {
    type Error = Infallible;
    type Decoded = Payload;
    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &[RepresentationIdentifier::CDR_LE, RepresentationIdentifier::CDR_BE]
    }
    fn transform_decoded(decoded: Payload) -> Payload {
        decoded
    }
}

#[derive(Clone)]
struct RawDecoder;

impl<'de> Decode<'de, Payload> for RawDecoder {
    type Error = Infallible;
    fn decode_bytes(self, body: &'de [u8], id: RepresentationIdentifier) -> Result<Payload, Infallible> {
        Ok(Payload { representation: id.to_bytes(), body: body.to_vec() })
    }
}

impl DefaultDecoder<Payload> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}

type RawWriter = DataWriter<Payload, RawAdapter>;
type RawReader = SimpleDataReader<Payload, RawAdapter>;

/// A rustdds participant on `lo` in `domain`.
fn rustdds_participant(domain: u16) -> DomainParticipant {
    DomainParticipantBuilder::new(domain).with_only_networks([IpAddr::V4(Ipv4Addr::LOCALHOST)]).build().unwrap()
}

/// rustdds QoS of the same meaning as robowire's `qos`.
fn rustdds_qos(qos: Qos) -> QosPolicies {
    let reliability = if qos.reliable {
        Reliability::Reliable { max_blocking_time: rustdds::Duration::from_millis(100) }
    } else {
        Reliability::BestEffort
    };
    let durability = if qos.transient_local { Durability::TransientLocal } else { Durability::Volatile };
    QosPolicyBuilder::new()
        .reliability(reliability)
        .durability(durability)
        .history(History::KeepLast { depth: qos.depth })
        .build()
}

fn rustdds_writer<M: CdrType>(dp: &DomainParticipant, topic: &str, qos: Qos) -> RawWriter {
    let q = rustdds_qos(qos);
    let topic = dp.create_topic(topic.into(), M::TYPE_NAME.into(), &q, TopicKind::NoKey).unwrap();
    dp.create_publisher(&q).unwrap().create_datawriter_no_key::<Payload, RawAdapter>(&topic, Some(q)).unwrap()
}

fn rustdds_reader<M: CdrType>(dp: &DomainParticipant, topic: &str, qos: Qos) -> RawReader {
    let q = rustdds_qos(qos);
    let topic = dp.create_topic(topic.into(), M::TYPE_NAME.into(), &q, TopicKind::NoKey).unwrap();
    dp.create_subscriber(&q).unwrap().create_simple_datareader_no_key::<Payload, RawAdapter>(&topic, Some(q)).unwrap()
}

/// Waits for rustdds's writer to report matching the reader `guid`.
async fn rustdds_writer_matched(writer: &RawWriter, guid: [u8; 16]) {
    some_async(WAIT, "rustdds's writer matched", || {
        std::iter::from_fn(|| writer.try_recv_status())
            .any(|s| matches!(s, DataWriterStatus::PublicationMatched { reader, .. } if reader.to_bytes() == guid))
            .then_some(())
    })
    .await;
}

/// The next sample a rustdds reader has, with its writer's GUID.
fn take(reader: &RawReader) -> Option<(Payload, [u8; 16])> {
    let change = reader.try_take_one().unwrap()?;
    Some((change.sample.clone(), change.writer_guid().to_bytes()))
}

/// The next sample of a robowire reader within [`WAIT`].
async fn recv<T: CdrType + 'static>(reader: &mut Reader<T>, what: &str) -> robowire_dds::Sample<T> {
    tokio::time::timeout(WAIT, reader.recv()).await.unwrap_or_else(|_| panic!("{what}: nothing")).unwrap()
}

/// A robowire participant on `lo` in `domain`.
fn robowire_participant(domain: u16) -> Participant {
    Participant::new(ParticipantOptions::new(domain, Some("lo"))).unwrap()
}

fn lowcmd(tag: u32) -> LowCmd {
    let mut cmd = LowCmd::default();
    cmd.reserve = tag.into();
    cmd.motor_cmd[2].q = (-1.3).into();
    cmd.sealed()
}

fn lowstate(tick: u32) -> LowState {
    let mut state = LowState::default();
    state.tick = tick.into();
    state.motor_state[5].q = 0.25.into();
    state.sealed()
}

fn hg_lowstate(tick: u32) -> HgLowState {
    let mut state = HgLowState::default();
    state.tick = tick.into();
    state.motor_state[28].q = (-0.5).into();
    state.wireless_remote[39] = 0xa5;
    state.sealed()
}

/// A GUID's participant prefix.
fn prefix(guid: [u8; 16]) -> [u8; 12] {
    guid[..12].try_into().unwrap()
}

/// Whether `by` knows the endpoint `guid` as a writer or reader of `topic` with type `M`'s name.
fn robowire_sees<M: CdrType>(by: &Participant, guid: [u8; 16], writer: bool, topic: &str) -> bool {
    by.discovered_endpoints()
        .iter()
        .any(|e| e.guid == guid && e.writer == writer && e.topic == topic && e.type_name == M::TYPE_NAME)
}

#[test]
fn discovery_both_ways() {
    let domain: u16 = 21;
    with_loopback_multicast(|| {
        runtime().block_on(async {
            let robowire = robowire_participant(domain);
            let state_writer = robowire.writer::<LowState>(LowState::TOPIC, Qos::WRITER).unwrap();
            let cmd_reader = robowire.reader::<LowCmd>(LowCmd::TOPIC, Qos::READER).unwrap();
            let dp = rustdds_participant(domain);
            let cmd_writer = rustdds_writer::<LowCmd>(&dp, LowCmd::TOPIC, Qos::WRITER);
            let state_reader = rustdds_reader::<LowState>(&dp, LowState::TOPIC, Qos::READER);
            let (w, r) = (cmd_writer.guid().to_bytes(), state_reader.guid().to_bytes());

            // robowire sees rustdds's participant, its writer and its reader.
            let rustdds = some_async(WAIT, "robowire discovers the rustdds participant", || {
                robowire.discovered_participants().into_iter().find(|p| p.guid_prefix == prefix(w))
            })
            .await;
            assert_eq!(rustdds.vendor, ([0x01, 0x12], Some("Atostek RustDDS")));
            assert!(!rustdds.unicast.is_empty(), "{rustdds:?}");
            some_async(WAIT, "robowire discovers rustdds's writer and reader", || {
                (robowire_sees::<LowCmd>(&robowire, w, true, LowCmd::TOPIC)
                    && robowire_sees::<LowState>(&robowire, r, false, LowState::TOPIC))
                .then_some(())
            })
            .await;

            // rustdds sees robowire's writer and reader, with their topics and type names.
            some_async(WAIT, "rustdds discovers robowire's writer", || {
                dp.discovered_writers()
                    .iter()
                    .any(|d| {
                        d.writer_proxy.remote_writer_guid.to_bytes() == state_writer.guid()
                            && d.publication_topic_data.topic_name == LowState::TOPIC
                            && d.publication_topic_data.type_name == LowState::TYPE_NAME
                            && matches!(d.publication_topic_data.reliability, Some(Reliability::Reliable { .. }))
                            && d.publication_topic_data.durability == Some(Durability::Volatile)
                    })
                    .then_some(())
            })
            .await;
            some_async(WAIT, "rustdds discovers robowire's reader", || {
                dp.discovered_readers()
                    .iter()
                    .any(|d| {
                        d.reader_proxy.remote_reader_guid.to_bytes() == cmd_reader.guid()
                            && d.subscription_topic_data.topic_name() == LowCmd::TOPIC
                            && d.subscription_topic_data.type_name() == LowCmd::TYPE_NAME
                    })
                    .then_some(())
            })
            .await;

            // Both sides match (Unitree's QoS: a reliable writer, a best-effort reader).
            some_async(WAIT, "robowire's endpoints match rustdds's", || {
                (state_writer.matched_readers() == 1 && cmd_reader.matched_writers() == 1).then_some(())
            })
            .await;
            let mut matched = (false, false);
            some_async(WAIT, "rustdds's endpoints report the match", || {
                while let Some(status) = cmd_writer.try_recv_status() {
                    if let DataWriterStatus::PublicationMatched { reader, .. } = status {
                        matched.0 |= reader.to_bytes() == cmd_reader.guid();
                    }
                }
                while let Some(status) = state_reader.try_recv_status() {
                    if let DataReaderStatus::SubscriptionMatched { writer, .. } = status {
                        matched.1 |= writer.to_bytes() == state_writer.guid();
                    }
                }
                (matched == (true, true)).then_some(())
            })
            .await;
            assert_eq!(robowire.counters().discovery_errors, 0);
        })
    });
}

/// LowState from robowire's typed writer to rustdds's raw reader, and LowCmd from rustdds's raw
/// writer to robowire's typed reader, best effort or reliable. Reliable: every one of a burst,
/// in order.
fn lowcmd_and_lowstate_both_ways(reliable: bool) {
    let domain: u16 = if reliable { 23 } else { 22 };
    const BURST: u32 = 20;
    let qos = Qos { reliable, depth: if reliable { 32 } else { 1 }, ..Qos::WRITER };
    runtime().block_on(async {
        let robowire = robowire_participant(domain);
        let dp = rustdds_participant(domain);
        let state_writer = robowire.writer::<LowState>(LowState::TOPIC, qos).unwrap();
        let mut cmd_reader = robowire.reader::<LowCmd>(LowCmd::TOPIC, qos).unwrap();
        let cmd_writer = rustdds_writer::<LowCmd>(&dp, LowCmd::TOPIC, qos);
        let state_reader = rustdds_reader::<LowState>(&dp, LowState::TOPIC, qos);

        some_async(WAIT, "matched", || {
            (state_writer.matched_readers() == 1 && cmd_reader.matched_writers() == 1).then_some(())
        })
        .await;

        // robowire → rustdds: written until one arrives (rustdds may match a moment later).
        let (first, from) = some_async(WAIT, "a LowState at rustdds", || {
            state_writer.write(lowstate(0)).unwrap();
            take(&state_reader)
        })
        .await;
        assert_eq!(from, state_writer.guid());
        assert_eq!(first, Payload::of(&lowstate(0)), "the bytes robowire's codec encodes");
        assert_eq!(first.representation, [0x00, 0x01], "XCDR1 little endian");

        // rustdds → robowire.
        let sample = some_async(WAIT, "a LowCmd at robowire", || {
            cmd_writer.write(Payload::of(&lowcmd(0)), None).unwrap();
            cmd_reader.recv().now_or_never()
        })
        .await
        .unwrap();
        assert_eq!(sample.value, lowcmd(0), "decoded, CRC verified");
        assert_eq!(sample.writer, cmd_writer.guid().to_bytes());
        assert!(sample.sequence >= 1);

        if reliable {
            // Drain what the first writes left, then a burst each way.
            while take(&state_reader).is_some() {}
            while cmd_reader.recv().now_or_never().is_some() {}
            for tick in 1..=BURST {
                state_writer.write(lowstate(tick)).unwrap();
                cmd_writer.write(Payload::of(&lowcmd(tick)), None).unwrap();
            }
            let mut ticks = Vec::new();
            while ticks.last() != Some(&BURST) {
                let (payload, _) = some_async(WAIT, "the LowState burst at rustdds", || take(&state_reader)).await;
                let tick = LowState::decode_cdr(&[&payload.representation[..], &[0, 0], &payload.body].concat())
                    .unwrap()
                    .0
                    .tick
                    .get();
                assert_eq!(payload, Payload::of(&lowstate(tick)));
                if tick != 0 {
                    ticks.push(tick);
                }
            }
            assert_eq!(ticks, (1..=BURST).collect::<Vec<_>>(), "rustdds got every LowState, in order");
            let mut tags = Vec::new();
            while tags.last() != Some(&BURST) {
                let sample = recv(&mut cmd_reader, "the LowCmd burst at robowire").await;
                let tag = sample.value.reserve.get();
                assert_eq!(sample.value, lowcmd(tag));
                if tag != 0 {
                    tags.push(tag);
                }
            }
            assert_eq!(tags, (1..=BURST).collect::<Vec<_>>(), "robowire got every LowCmd, in order");
            // Each side acknowledged everything the other wrote.
            assert_eq!(cmd_writer.wait_for_acknowledgments(WAIT).ok(), Some(true), "robowire acknowledged");
            let acknowledged = tokio::time::timeout(WAIT, state_writer.acknowledged()).await;
            assert!(matches!(acknowledged, Ok(Ok(true))), "rustdds acknowledged");
        }
        let stats = cmd_reader.stats();
        assert_eq!((stats.decode_errors, stats.checksum_errors), (0, 0));
        assert_eq!(state_writer.stats().write_errors, 0);
    });
}

#[test]
fn best_effort_lowcmd_and_lowstate_both_ways() {
    with_loopback_multicast(|| lowcmd_and_lowstate_both_ways(false));
}

#[test]
fn reliable_lowcmd_and_lowstate_both_ways() {
    with_loopback_multicast(|| lowcmd_and_lowstate_both_ways(true));
}

/// A capture of every frame on the calling thread's namespace's interfaces (`lo`): a packet
/// socket (`AF_PACKET`, all protocols; `CAP_NET_RAW` in the namespace, which its root has) read
/// by a thread until stopped.
struct Capture {
    stop: Arc<AtomicBool>,
    thread: std::thread::JoinHandle<Vec<Vec<u8>>>,
}

impl Capture {
    fn start() -> Self {
        use socket2::{Domain, Protocol, Socket, Type};
        const AF_PACKET: i32 = 17;
        const SOCK_RAW: i32 = 3;
        const ETH_P_ALL: u16 = 3;
        let socket = Socket::new(
            Domain::from(AF_PACKET),
            Type::from(SOCK_RAW),
            Some(Protocol::from(i32::from(ETH_P_ALL.to_be()))),
        )
        .expect("a packet socket in the test's namespace");
        socket.set_read_timeout(Some(Duration::from_millis(20))).unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let thread = std::thread::spawn({
            let stop = stop.clone();
            move || {
                use std::io::Read;
                let mut frames = Vec::new();
                let mut buf = vec![0u8; 70_000];
                while !stop.load(Ordering::Relaxed) {
                    if let Ok(n) = (&socket).read(&mut buf) {
                        frames.push(buf[..n].to_vec());
                    }
                }
                frames
            }
        });
        Self { stop, thread }
    }

    /// Stops the capture; the RTPS messages captured, each as its GUID prefix and submessages
    /// (on `lo` a packet socket may see a datagram twice, as sent and as received).
    fn stop(self) -> Vec<([u8; 12], Vec<Submessage>)> {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().unwrap().iter().filter_map(|frame| rtps_message(frame)).collect()
    }
}

/// A submessage on the wire: its id and, for a DATA_FRAG, its fragments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Submessage {
    id: u8,
    /// DATA_FRAG: (fragmentStartingNum, fragmentsInSubmessage, fragmentSize, sampleSize).
    fragments: Option<(u32, u16, u16, u32)>,
}

/// DATA_FRAG.
const DATA_FRAG: u8 = 0x16;

/// The RTPS message in an Ethernet frame of UDP over IPv4 (`lo`'s frames): its GUID prefix and
/// submessages.
fn rtps_message(frame: &[u8]) -> Option<([u8; 12], Vec<Submessage>)> {
    let ip = frame.get(14..)?;
    if frame[12..14] != [0x08, 0x00] || ip.is_empty() || ip[0] >> 4 != 4 || ip.get(9) != Some(&17) {
        return None;
    }
    let rtps = ip.get(usize::from(ip[0] & 0xf) * 4 + 8..)?;
    if rtps.len() < 20 || &rtps[..4] != b"RTPS" {
        return None;
    }
    let mut submessages = Vec::new();
    let mut sub = 20;
    while sub + 4 <= rtps.len() {
        let (id, little) = (rtps[sub], rtps[sub + 1] & 1 == 1);
        let u16_of = |b: &[u8]| {
            let b = [b[0], b[1]];
            if little { u16::from_le_bytes(b) } else { u16::from_be_bytes(b) }
        };
        let u32_of = |b: &[u8]| {
            let b = [b[0], b[1], b[2], b[3]];
            if little { u32::from_le_bytes(b) } else { u32::from_be_bytes(b) }
        };
        let len = usize::from(u16_of(&rtps[sub + 2..]));
        let body = &rtps[sub + 4..];
        let fragments = (id == DATA_FRAG && body.len() >= 32)
            .then(|| (u32_of(&body[20..]), u16_of(&body[24..]), u16_of(&body[26..]), u32_of(&body[28..])));
        submessages.push(Submessage { id, fragments });
        if len == 0 {
            break;
        }
        sub += 4 + len;
    }
    Some((rtps[8..20].try_into().unwrap(), submessages))
}

/// An HG LowState (2092-byte image, larger than one fragment of either implementation) both
/// ways over reliable endpoints, `lo` at an Ethernet MTU so that rustdds fragments too; the
/// DATA_FRAGs of each side seen on the wire.
#[test]
fn a_fragmented_hg_lowstate_both_ways() {
    let domain: u16 = 24;
    with_loopback_multicast(|| {
        // rustdds sizes its datagrams by the interface MTU (`lo`: 65536, one DATA); at 1500 it
        // sends 256-byte fragments. Only in a namespace of the test's own: this thread's, or this
        // process run again in one (not the host's `lo`, where it already carries multicast).
        let ns = |of: &str| std::fs::read_link(format!("/proc/{of}/ns/net")).unwrap();
        if ns("thread-self") == ns("self") && std::env::var_os(robowire_dds::netns::CHILD_ENV).is_none() {
            return robowire_fixtures::interop::skip(
                "lo carries multicast here, so the test would run in this namespace, whose lo MTU it must not change",
            );
        }
        let out = Command::new("ip").args(["link", "set", "lo", "mtu", "1500"]).output().unwrap();
        assert!(out.status.success(), "ip link set lo mtu 1500: {}", String::from_utf8_lossy(&out.stderr));
        let wire = Capture::start();
        let qos = Qos { reliable: true, depth: 4, ..Qos::WRITER };
        let (robowire_prefix, rustdds_prefix) = runtime().block_on(async {
            let robowire = robowire_participant(domain);
            let dp = rustdds_participant(domain);
            let state_writer = robowire.writer::<HgLowState>(HgLowState::TOPIC, qos).unwrap();
            let mut state_reader = robowire.reader::<HgLowState>("rt/lowstate_echo", qos).unwrap();
            let raw_writer = rustdds_writer::<HgLowState>(&dp, "rt/lowstate_echo", qos);
            let raw_reader = rustdds_reader::<HgLowState>(&dp, HgLowState::TOPIC, qos);
            let expected = Payload::of(&hg_lowstate(7));
            assert_eq!(expected.body.len() + 4, 2092, "{}", expected.body.len());
            some_async(WAIT, "matched", || {
                (state_writer.matched_readers() == 1 && state_reader.matched_writers() == 1).then_some(())
            })
            .await;
            rustdds_writer_matched(&raw_writer, state_reader.guid()).await;

            state_writer.write(hg_lowstate(7)).unwrap();
            let (got, from) = some_async(WAIT, "the HG LowState at rustdds", || take(&raw_reader)).await;
            assert_eq!(from, state_writer.guid());
            assert_eq!(got, expected, "reassembled by rustdds, byte for byte");

            raw_writer.write(expected.clone(), None).unwrap();
            let sample = recv(&mut state_reader, "the HG LowState at robowire").await;
            assert_eq!(sample.value, hg_lowstate(7), "reassembled by robowire, CRC verified");
            assert_eq!(sample.writer, raw_writer.guid().to_bytes());
            assert_eq!(state_reader.stats().checksum_errors + state_reader.stats().decode_errors, 0);
            (prefix(state_writer.guid()), prefix(raw_writer.guid().to_bytes()))
        });
        let messages = wire.stop();
        // Each side's DATA_FRAGs: (fragment size, sample size) and the fragments they carry.
        let frags = |from: [u8; 12]| {
            let mut sizes = std::collections::BTreeSet::new();
            let mut numbers = std::collections::BTreeSet::new();
            for sub in messages.iter().filter(|(p, _)| *p == from).flat_map(|(_, subs)| subs) {
                if let Some((start, count, size, sample)) = sub.fragments {
                    sizes.insert((size, sample));
                    numbers.extend(start..start + u32::from(count));
                }
            }
            (sizes.into_iter().collect::<Vec<_>>(), numbers.len())
        };
        let (ours, theirs) = (frags(robowire_prefix), frags(rustdds_prefix));
        eprintln!(
            "on the wire, (fragment size, sample size) and fragments: robowire {ours:?}, rustdds {theirs:?} \
             ({} RTPS messages)",
            messages.len()
        );
        assert_eq!(ours, (vec![(1344, 2092)], 2), "robowire's fragments");
        assert_eq!(theirs, (vec![(256, 2092)], 9), "rustdds's fragments at MTU 1500");
    });
}

/// A transient-local writer's kept sample reaches a reader that joins after it was written, with
/// nothing written since: robowire's writer to a late rustdds reader, and rustdds's writer to a
/// late robowire reader.
#[test]
fn transient_local_late_joiners_both_ways() {
    let domain: u16 = 25;
    with_loopback_multicast(|| {
        runtime().block_on(async {
            let qos = Qos { transient_local: true, depth: 1, ..Qos::WRITER };
            let robowire = robowire_participant(domain);
            let state_writer = robowire.writer::<LowState>(LowState::TOPIC, qos).unwrap();
            state_writer.write(lowstate(41)).unwrap();
            state_writer.write(lowstate(42)).unwrap();
            let dp = rustdds_participant(domain);
            let cmd_writer = rustdds_writer::<LowCmd>(&dp, LowCmd::TOPIC, qos);
            cmd_writer.write(Payload::of(&lowcmd(42)), None).unwrap();

            // Late: rustdds's reader joins robowire's writer, robowire's reader rustdds's writer.
            let state_reader = rustdds_reader::<LowState>(&dp, LowState::TOPIC, qos);
            let (got, from) =
                some_async(WAIT, "robowire's kept LowState at the late rustdds reader", || take(&state_reader)).await;
            assert_eq!((got, from), (Payload::of(&lowstate(42)), state_writer.guid()), "the newest kept (depth 1)");
            let mut cmd_reader = robowire.reader::<LowCmd>(LowCmd::TOPIC, qos).unwrap();
            let sample = recv(&mut cmd_reader, "rustdds's kept LowCmd at the late robowire reader").await;
            assert_eq!((sample.value, sample.writer), (lowcmd(42), cmd_writer.guid().to_bytes()));

            // Nothing else: each was delivered once.
            tokio::time::sleep(Duration::from_millis(500)).await;
            assert_eq!(take(&state_reader), None);
            assert!(cmd_reader.recv().now_or_never().is_none());
        })
    });
}

/// A reliable reader and a best-effort writer do not match (DDS's RxO): rustdds reports the
/// incompatibility on its side; robowire's side has discovered the endpoint and does not match it.
#[test]
fn a_reliable_reader_and_a_best_effort_writer_do_not_match() {
    let domain: u16 = 26;
    with_loopback_multicast(|| {
        runtime().block_on(async {
            let best_effort = Qos { reliable: false, ..Qos::WRITER };
            let reliable = Qos { reliable: true, ..Qos::WRITER };
            let robowire = robowire_participant(domain);
            let dp = rustdds_participant(domain);
            // rustdds reliable reader, robowire best-effort writer.
            let state_writer = robowire.writer::<LowState>(LowState::TOPIC, best_effort).unwrap();
            let state_reader = rustdds_reader::<LowState>(&dp, LowState::TOPIC, reliable);
            // rustdds best-effort writer, robowire reliable reader.
            let mut cmd_reader = robowire.reader::<LowCmd>(LowCmd::TOPIC, reliable).unwrap();
            let cmd_writer = rustdds_writer::<LowCmd>(&dp, LowCmd::TOPIC, best_effort);

            let (mut requested, mut offered) = (None, None);
            some_async(WAIT, "rustdds reports both incompatibilities", || {
                while let Some(status) = state_reader.try_recv_status() {
                    match status {
                        DataReaderStatus::RequestedIncompatibleQos { writer, last_policy_id, .. } => {
                            requested = Some((writer.to_bytes(), last_policy_id));
                        }
                        DataReaderStatus::SubscriptionMatched { writer, .. } => {
                            panic!("rustdds's reliable reader matched {writer:?}")
                        }
                        _ => {}
                    }
                }
                while let Some(status) = cmd_writer.try_recv_status() {
                    match status {
                        DataWriterStatus::OfferedIncompatibleQos { reader, last_policy_id, .. } => {
                            offered = Some((reader.to_bytes(), last_policy_id));
                        }
                        DataWriterStatus::PublicationMatched { reader, .. } => {
                            panic!("rustdds's best-effort writer matched {reader:?}")
                        }
                        _ => {}
                    }
                }
                requested.zip(offered)
            })
            .await;
            let (requested, offered) = (requested.unwrap(), offered.unwrap());
            assert_eq!(requested.0, state_writer.guid(), "{requested:?}");
            assert_eq!(offered.0, cmd_reader.guid(), "{offered:?}");
            assert_eq!(format!("{:?}", requested.1), "Reliability");
            assert_eq!(format!("{:?}", offered.1), "Reliability");

            // robowire knows both rustdds endpoints and matches neither.
            let (w, r) = (cmd_writer.guid().to_bytes(), state_reader.guid().to_bytes());
            some_async(WAIT, "robowire discovers rustdds's endpoints", || {
                (robowire_sees::<LowCmd>(&robowire, w, true, LowCmd::TOPIC)
                    && robowire_sees::<LowState>(&robowire, r, false, LowState::TOPIC))
                .then_some(())
            })
            .await;
            for n in 0..10 {
                state_writer.write(lowstate(n)).unwrap();
                cmd_writer.write(Payload::of(&lowcmd(n)), None).unwrap();
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            assert_eq!(state_writer.matched_readers(), 0);
            assert_eq!(cmd_reader.matched_writers(), 0);
            // robowire says why, for each side.
            for why in [state_writer.incompatible_readers(), cmd_reader.incompatible_writers()] {
                assert!(why.len() == 1 && why[0].reason.contains("reliab"), "{why:?}");
            }
            assert_eq!(take(&state_reader), None, "nothing delivered");
            assert!(cmd_reader.recv().now_or_never().is_none(), "nothing delivered");
        })
    });
}

/// The rustdds participant is dropped: robowire forgets it and its endpoints; a new one comes
/// back, is discovered and matched, and samples cross both ways again.
#[test]
fn the_rustdds_participant_leaves_and_comes_back() {
    let domain: u16 = 27;
    with_loopback_multicast(|| {
        runtime().block_on(async {
            let qos = Qos { reliable: true, depth: 8, ..Qos::WRITER };
            let robowire = robowire_participant(domain);
            let state_writer = robowire.writer::<LowState>(LowState::TOPIC, qos).unwrap();
            let mut cmd_reader = robowire.reader::<LowCmd>(LowCmd::TOPIC, qos).unwrap();
            let mut prefixes = Vec::new();
            for round in 0..2u32 {
                let dp = rustdds_participant(domain);
                let cmd_writer = rustdds_writer::<LowCmd>(&dp, LowCmd::TOPIC, qos);
                let state_reader = rustdds_reader::<LowState>(&dp, LowState::TOPIC, qos);
                let rustdds = prefix(cmd_writer.guid().to_bytes());
                some_async(WAIT, "matched", || {
                    (state_writer.matched_readers() == 1 && cmd_reader.matched_writers() == 1).then_some(())
                })
                .await;
                let (got, _) = some_async(WAIT, "a LowState at rustdds", || {
                    state_writer.write(lowstate(round)).unwrap();
                    take(&state_reader)
                })
                .await;
                assert_eq!(got, Payload::of(&lowstate(round)), "round {round}");
                let sample = some_async(WAIT, "a LowCmd at robowire", || {
                    cmd_writer.write(Payload::of(&lowcmd(round)), None).unwrap();
                    cmd_reader.recv().now_or_never()
                })
                .await
                .unwrap();
                assert_eq!((sample.value, sample.writer), (lowcmd(round), cmd_writer.guid().to_bytes()));
                prefixes.push(rustdds);

                let began = Instant::now();
                drop((cmd_writer, state_reader));
                drop(dp);
                some_async(RUSTDDS_GONE, "robowire forgets the rustdds participant", || {
                    let gone = !robowire.discovered_participants().iter().any(|p| p.guid_prefix == rustdds)
                        && !robowire.discovered_endpoints().iter().any(|e| prefix(e.guid) == rustdds);
                    (gone && state_writer.matched_readers() == 0 && cmd_reader.matched_writers() == 0).then_some(())
                })
                .await;
                eprintln!("round {round}: rustdds participant forgotten {:?} after its drop began", began.elapsed());
                // Samples that arrived before it left are still there to take; nothing after.
                while let Some(sample) = cmd_reader.recv().now_or_never() {
                    assert_eq!(prefix(sample.unwrap().writer), rustdds);
                }
            }
            assert_ne!(prefixes[0], prefixes[1], "a new participant");
            // Writes with no reader matched are kept or dropped, never an error.
            state_writer.write(lowstate(9)).unwrap();
            assert_eq!(state_writer.stats().write_errors, 0);
        })
    });
}
