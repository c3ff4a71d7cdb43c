//! The fuzz oracles (internal; the fuzz targets and the xtask's corpus replay call them):
//! [`parse_all`] for the wire layer, [`participant`] / [`participant_steps`] for a whole
//! [`Participant`] driven by a sequence of [`Step`]s.

use alloc::vec;
use alloc::vec::Vec;
use core::net::{IpAddr, Ipv4Addr, SocketAddr};
use core::time::Duration;

use crate::discovery::Qos;
use crate::participant::{Destination, Event, Participant, ParticipantConfig};
use crate::wire::{
    Endianness, Header, LocatorList, Message, MessageWriter, ParameterList, Payload, Submessage, Submessages, pid,
};
use crate::{EntityId, GuidPrefix, Locator, Time};

/// Parses `datagram` and walks everything in it: every submessage, each inline QoS list, a DATA
/// payload that is a parameter list (SPDP/SEDP), every locator. Each parsed submessage is emitted
/// and parsed again and must give the same repr (and the same bytes when emitted again); the
/// valid submessages written as one message with [`MessageWriter`] must parse back in order.
/// Panics when one of these does not hold.
pub fn parse_all(datagram: &[u8]) {
    let Ok(message) = Message::parse(datagram) else { return };
    let header = message.header();
    let mut valid = Vec::new();
    for item in message.submessages() {
        let Ok(submessage) = item else { continue };
        walk(&submessage);
        round_trip(&submessage);
        valid.push(submessage);
    }
    message_round_trip(&header, &valid);
}

fn walk(submessage: &Submessage<'_>) {
    match submessage {
        Submessage::Data(d) => {
            d.inline_qos.iter().for_each(walk_list);
            if let Payload::Data(b) | Payload::Key(b) = d.payload {
                walk_payload(b);
            }
        }
        Submessage::DataFrag(d) => {
            d.inline_qos.iter().for_each(walk_list);
            assert!(d.fragment_bytes().is_some_and(|n| n == d.payload.len() as u64));
        }
        Submessage::InfoReply(r) => {
            assert_eq!(r.unicast.iter().count(), r.unicast.len());
            if let Some(m) = &r.multicast {
                assert_eq!(m.iter().count(), m.len());
            }
        }
        _ => {}
    }
}

/// A DATA payload with a PL_CDR encapsulation (discovery data) is a parameter list.
fn walk_payload(payload: &[u8]) {
    let endianness = match payload.get(..2) {
        Some([0x00, 0x02]) => Endianness::Big,
        Some([0x00, 0x03]) => Endianness::Little,
        _ => return,
    };
    if let Ok((list, used)) = ParameterList::parse(payload.get(4..).unwrap_or_default(), endianness) {
        assert!(used <= payload.len() - 4);
        walk_list(&list);
    }
}

fn walk_list(list: &ParameterList<'_>) {
    for p in list.iter() {
        let _ = pid::name(p.pid);
        assert!(p.pid != pid::PAD && p.pid != pid::SENTINEL);
        if matches!(
            p.pid & !pid::MUST_UNDERSTAND,
            pid::UNICAST_LOCATOR
                | pid::MULTICAST_LOCATOR
                | pid::DEFAULT_UNICAST_LOCATOR
                | pid::DEFAULT_MULTICAST_LOCATOR
                | pid::METATRAFFIC_UNICAST_LOCATOR
                | pid::METATRAFFIC_MULTICAST_LOCATOR
        ) {
            let whole = p.value.len() / 24 * 24;
            if let Ok(locators) = LocatorList::new(p.value.get(..whole).unwrap_or_default(), list.endianness()) {
                locators.iter().for_each(|l| {
                    let _ = (l.socket_addr(), l.is_multicast());
                });
            }
        }
    }
    assert_eq!(list.find(pid::SENTINEL), None);
}

/// Emits `submessage` alone, parses it again, compares.
fn round_trip(submessage: &Submessage<'_>) {
    let len = submessage.buffer_len();
    let mut buf = vec![0u8; len];
    assert_eq!(submessage.emit(&mut buf), Ok(len));
    if len > 0 {
        assert!(submessage.emit(&mut buf[..len - 1]).is_err(), "emit into a short buffer");
    }
    let again = reparse(&buf);
    assert!(same(submessage, &again), "emit then parse changed {submessage:?} into {again:?}");
    let mut buf2 = vec![0u8; again.buffer_len()];
    assert_eq!(again.emit(&mut buf2), Ok(buf2.len()));
    assert_eq!(buf, buf2, "a re-parsed submessage emits other bytes");
}

fn reparse(emitted: &[u8]) -> Submessage<'_> {
    let (kind, flags) = (emitted[0], emitted[1]);
    let length = [emitted[2], emitted[3]];
    let length = usize::from(if flags & 1 == 1 { u16::from_le_bytes(length) } else { u16::from_be_bytes(length) });
    let body = if length == 0 { &emitted[4..] } else { &emitted[4..4 + length] };
    Submessage::parse(kind, flags, body).expect("an emitted submessage parses")
}

/// Equal, but inline QoS and locator lists that came big-endian compare by their contents.
fn same(a: &Submessage<'_>, b: &Submessage<'_>) -> bool {
    fn lists(a: &Option<ParameterList<'_>>, b: &Option<ParameterList<'_>>) -> bool {
        match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) if a.endianness() == Endianness::Little => a == b,
            (Some(a), Some(b)) => a.iter().eq(b.iter()),
            _ => false,
        }
    }
    fn locators(a: &LocatorList<'_>, b: &LocatorList<'_>) -> bool {
        a.iter().eq(b.iter())
    }
    match (a, b) {
        (Submessage::Data(x), Submessage::Data(y)) => {
            lists(&x.inline_qos, &y.inline_qos)
                && Submessage::Data(crate::wire::Data { inline_qos: None, ..*x })
                    == Submessage::Data(crate::wire::Data { inline_qos: None, ..*y })
        }
        (Submessage::DataFrag(x), Submessage::DataFrag(y)) => {
            lists(&x.inline_qos, &y.inline_qos)
                && crate::wire::DataFrag { inline_qos: None, ..*x } == crate::wire::DataFrag { inline_qos: None, ..*y }
        }
        (Submessage::InfoReply(x), Submessage::InfoReply(y)) => {
            locators(&x.unicast, &y.unicast)
                && match (&x.multicast, &y.multicast) {
                    (None, None) => true,
                    (Some(m), Some(n)) => locators(m, n),
                    _ => false,
                }
        }
        _ => a == b,
    }
}

/// The valid submessages as one little-endian message parse back in order, when each can be
/// framed (a body over 65535 bytes, or an unknown one with no body, is written with length 0
/// and must end the message).
fn message_round_trip(header: &Header, submessages: &[Submessage<'_>]) {
    let framed = |s: &Submessage<'_>| {
        let body = s.buffer_len() - 4;
        body <= usize::from(u16::MAX) && (body > 0 || matches!(s, Submessage::Pad | Submessage::InfoTs(_)))
    };
    if !submessages.iter().all(framed) {
        return;
    }
    let len = Header::LEN + submessages.iter().map(Submessage::buffer_len).sum::<usize>();
    let mut buf = vec![0u8; len];
    let mut writer = MessageWriter::new(&mut buf, header).expect("room for the header");
    for s in submessages {
        writer.push(s).expect("room for every submessage");
    }
    assert_eq!(writer.finish(), len);
    let message = Message::parse(&buf).expect("an emitted message parses");
    assert_eq!(message.header(), *header);
    let parsed: Submessages<'_> = message.submessages();
    let mut n = 0;
    for (s, again) in submessages.iter().zip(parsed) {
        let again = again.expect("an emitted submessage parses");
        assert!(same(s, &again), "{s:?} came back as {again:?}");
        n += 1;
    }
    assert_eq!(n, submessages.len());
    assert_eq!(message.submessages().count(), submessages.len());
}

// ---------------------------------------------------------------------------------------------
// The participant target: a whole `Participant` driven by a fuzzed sequence of steps.
// ---------------------------------------------------------------------------------------------

/// The fuzzed participant's GUID prefix.
pub const LOCAL_PREFIX: GuidPrefix = GuidPrefix([0x01; 12]);
/// The prefix of the fuzzer's peer (every templated datagram comes from it).
pub const PEER_PREFIX: GuidPrefix = GuidPrefix([0x0f; 12]);
/// The topic both participants write and read.
pub const TOPIC: &str = "rt/fuzz";
/// Its type name.
pub const TYPE_NAME: &str = "robowire::msg::dds_::Fuzz_";
/// When both participants start.
const T0: Time = Time::from_nanos(1_000_000_000);
/// Bytes of a generated payload at most (a DATA's, a DATA_FRAG's, a local write's).
const MAX_PAYLOAD: usize = 16 * 1024;

fn address(prefix: GuidPrefix) -> SocketAddr {
    SocketAddr::new(IpAddr::V4(Ipv4Addr::new(127, 0, 0, 1)), 7400 + u16::from(prefix.0[0]))
}

fn fuzz_config(prefix: GuidPrefix) -> ParticipantConfig {
    let mut c = ParticipantConfig::new(prefix, 0);
    c.metatraffic_unicast = alloc::vec![Locator::udp(address(prefix))];
    c.default_unicast = c.metatraffic_unicast.clone();
    c
}

/// What every run of [`participant_steps`] starts from, built once: the discovery datagrams of a
/// real peer participant (SPDP, SEDP for one reliable writer and one reader on [`TOPIC`]), as it
/// sent them to the fuzzed participant during a complete exchange, and the peer's endpoint ids.
#[derive(Debug, Clone)]
pub struct ParticipantSetup {
    /// The peer's datagrams, in the order it sent them.
    pub discovery: Vec<Vec<u8>>,
    /// The peer's writer.
    pub peer_writer: EntityId,
    /// The peer's reader.
    pub peer_reader: EntityId,
    /// The fuzzed participant as each setup byte's two bits leave it before the first step
    /// (discovery fed or not; endpoints created before or after it): cloned per run, so a run
    /// costs no discovery exchange.
    prepared: [Option<(Participant, EntityId, EntityId)>; 4],
}

impl Default for ParticipantSetup {
    fn default() -> Self {
        Self::new()
    }
}

impl ParticipantSetup {
    /// Runs the fuzzed participant and a peer to quiet and keeps what the peer sent.
    pub fn new() -> Self {
        let mut ours = Participant::new(fuzz_config(LOCAL_PREFIX), T0);
        let mut peer = Participant::new(fuzz_config(PEER_PREFIX), T0);
        let (mut discovery, mut buf) = (Vec::new(), vec![0u8; 65_536]);
        let endpoints = |p: &mut Participant| {
            let w = p.create_writer(T0, TOPIC, TYPE_NAME, Qos::default()).expect("a writer");
            let r = p.create_reader(T0, TOPIC, TYPE_NAME, Qos::default()).expect("a reader");
            (w, r)
        };
        endpoints(&mut ours);
        let (peer_writer, peer_reader) = endpoints(&mut peer);
        for _ in 0..20 {
            while let Some(t) = ours.poll_transmit(T0, &mut buf) {
                peer.handle_datagram(T0, address(LOCAL_PREFIX), Destination::Unicast, &buf[..t.len]);
            }
            while let Some(t) = peer.poll_transmit(T0, &mut buf) {
                discovery.push(buf[..t.len].to_vec());
                ours.handle_datagram(T0, address(PEER_PREFIX), Destination::Unicast, &buf[..t.len]);
            }
        }
        let mut setup = Self { discovery, peer_writer, peer_reader, prepared: [None, None, None, None] };
        let prepared = core::array::from_fn(|flags| Some(setup.prepare(flags as u8)));
        setup.prepared = prepared;
        setup
    }

    /// The fuzzed participant before the first step, for the setup byte `flags`: endpoints
    /// created before discovery unless bit 1, the peer's discovery fed unless bit 0.
    fn prepare(&self, flags: u8) -> (Participant, EntityId, EntityId) {
        let now = T0;
        let mut p = Participant::new(fuzz_config(LOCAL_PREFIX), now);
        let endpoints = |p: &mut Participant| {
            let w = p.create_writer(now, TOPIC, TYPE_NAME, Qos::default()).expect("a writer");
            let r = p.create_reader(now, TOPIC, TYPE_NAME, Qos::default()).expect("a reader");
            (w, r)
        };
        let early = (flags & 2 == 0).then(|| endpoints(&mut p));
        if flags & 1 == 0 {
            for d in &self.discovery {
                p.handle_datagram(now, address(PEER_PREFIX), Destination::Unicast, d);
            }
        }
        let (w, r) = early.unwrap_or_else(|| endpoints(&mut p));
        (p, w, r)
    }
}

/// One step of a participant run. [`Step::encode`] and [`Step::decode`] are each other's
/// inverse on the byte format the fuzzer mutates: a tag byte (modulo the number of kinds), then
/// the fields in order, little-endian; missing bytes read as zeros (as `arbitrary`'s
/// `Unstructured` does), so every input is a valid sequence of steps.
///
/// Datagram steps that name endpoints choose them with a selector byte from the matched pair
/// (the peer's writer or reader and ours), the builtin SPDP/SEDP endpoints, `UNKNOWN`, and the
/// wrong kind. Their `wrap` byte: bit 0 an INFO_DST to us first, bit 1 an INFO_DST to someone
/// else, bit 2 an INFO_TS, bit 3 big-endian submessages, bit 4 received on multicast.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step<'a> {
    /// Any bytes as a datagram.
    Raw(&'a [u8]),
    /// The peer's RTPS header, then any bytes.
    FromPeer(&'a [u8]),
    /// One of the setup's discovery datagrams (index modulo their number), with up to two bytes
    /// replaced (position `at - 1` modulo the length; `at` 0 leaves it).
    Discovery {
        /// Which datagram.
        index: u8,
        /// Two patches: (position + 1, value).
        patches: [(u16, u8); 2],
    },
    /// DATA from the peer (payload: a CDR header and `len` bytes; flags bit 0 inline QoS with a
    /// status info of `flags >> 4`, bit 1 a key instead of data, bit 2 no payload).
    Data {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// writerSN.
        sn: i64,
        /// Payload bytes after the CDR header (modulo 16 KiB + 1).
        len: u16,
        /// Flags.
        flags: u8,
    },
    /// DATA_FRAG from the peer (`len` 0: the payload the numbers imply; else `len - 1` bytes).
    DataFrag {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// writerSN.
        sn: i64,
        /// fragmentStartingNum.
        start: u32,
        /// fragmentsInSubmessage.
        count: u16,
        /// fragmentSize.
        size: u16,
        /// sampleSize.
        sample: u32,
        /// Payload length.
        len: u16,
    },
    /// HEARTBEAT from the peer (flags bit 0 F, bit 1 L).
    Heartbeat {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// firstSN.
        first: i64,
        /// lastSN.
        last: i64,
        /// count.
        count: i32,
        /// Flags.
        flags: u8,
    },
    /// HEARTBEAT_FRAG from the peer.
    HeartbeatFrag {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// writerSN.
        sn: i64,
        /// lastFragmentNum.
        last: u32,
        /// count.
        count: i32,
    },
    /// ACKNACK from the peer's side (the set's words: as many as `bits` implies, at most 8).
    AckNack {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector (remote).
        from: u8,
        /// Writer selector (ours).
        to: u8,
        /// The set's base.
        base: i64,
        /// numBits.
        bits: u32,
        /// The bitmap words.
        words: [u32; 8],
        /// count.
        count: i32,
        /// F.
        final_flag: bool,
    },
    /// GAP from the peer.
    Gap {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector.
        to: u8,
        /// Writer selector.
        from: u8,
        /// gapStart.
        start: i64,
        /// The list's base.
        base: i64,
        /// numBits.
        bits: u32,
        /// The bitmap words.
        words: [u32; 8],
    },
    /// NACK_FRAG from the peer's side.
    NackFrag {
        /// The datagram's wrap byte.
        wrap: u8,
        /// Reader selector (remote).
        from: u8,
        /// Writer selector (ours).
        to: u8,
        /// writerSN.
        sn: i64,
        /// The set's base.
        base: u32,
        /// numBits.
        bits: u32,
        /// The bitmap words.
        words: [u32; 8],
        /// count.
        count: i32,
    },
    /// The clock moves `ms` (modulo 10 001) milliseconds, then `handle_timeout`.
    Clock {
        /// Milliseconds.
        ms: u16,
    },
    /// Drains `poll_transmit` and `poll_event` (sample buffers recycled).
    Poll,
    /// Our writer writes a sample of a CDR header and `len` bytes (modulo 16 KiB + 1; longer
    /// than the fragment size: DATA_FRAG).
    Write {
        /// Bytes after the CDR header.
        len: u16,
    },
}

/// Fields read from the front of the input; missing bytes are zeros.
struct Input<'a>(&'a [u8]);

impl<'a> Input<'a> {
    fn bytes(&mut self, n: usize) -> &'a [u8] {
        let (head, tail) = self.0.split_at(n.min(self.0.len()));
        self.0 = tail;
        head
    }
    fn array<const N: usize>(&mut self) -> [u8; N] {
        let mut a = [0; N];
        let b = self.bytes(N);
        a[..b.len()].copy_from_slice(b);
        a
    }
    fn u8(&mut self) -> u8 {
        self.array::<1>()[0]
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.array())
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.array())
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.array())
    }
    fn i64(&mut self) -> i64 {
        i64::from_le_bytes(self.array())
    }
    fn words(&mut self) -> [u32; 8] {
        core::array::from_fn(|_| self.u32())
    }
}

const STEP_KINDS: u8 = 13;

impl<'a> Step<'a> {
    /// Reads one step; `None` at the end of the input.
    pub fn decode(input: &mut &'a [u8]) -> Option<Self> {
        if input.is_empty() {
            return None;
        }
        let mut i = Input(input);
        let step = match i.u8() % STEP_KINDS {
            0 => {
                let n = usize::from(i.u16());
                Step::Raw(i.bytes(n))
            }
            1 => {
                let n = usize::from(i.u16());
                Step::FromPeer(i.bytes(n))
            }
            2 => Step::Discovery { index: i.u8(), patches: [(i.u16(), i.u8()), (i.u16(), i.u8())] },
            3 => Step::Data { wrap: i.u8(), to: i.u8(), from: i.u8(), sn: i.i64(), len: i.u16(), flags: i.u8() },
            4 => Step::DataFrag {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                sn: i.i64(),
                start: i.u32(),
                count: i.u16(),
                size: i.u16(),
                sample: i.u32(),
                len: i.u16(),
            },
            5 => Step::Heartbeat {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                first: i.i64(),
                last: i.i64(),
                count: i.i32(),
                flags: i.u8(),
            },
            6 => Step::HeartbeatFrag {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                sn: i.i64(),
                last: i.u32(),
                count: i.i32(),
            },
            7 => Step::AckNack {
                wrap: i.u8(),
                from: i.u8(),
                to: i.u8(),
                base: i.i64(),
                bits: i.u32(),
                words: i.words(),
                count: i.i32(),
                final_flag: i.u8() & 1 == 1,
            },
            8 => Step::Gap {
                wrap: i.u8(),
                to: i.u8(),
                from: i.u8(),
                start: i.i64(),
                base: i.i64(),
                bits: i.u32(),
                words: i.words(),
            },
            9 => Step::NackFrag {
                wrap: i.u8(),
                from: i.u8(),
                to: i.u8(),
                sn: i.i64(),
                base: i.u32(),
                bits: i.u32(),
                words: i.words(),
                count: i.i32(),
            },
            10 => Step::Clock { ms: i.u16() },
            11 => Step::Poll,
            _ => Step::Write { len: i.u16() },
        };
        *input = i.0;
        Some(step)
    }

    /// Appends the step's bytes (what [`decode`](Self::decode) reads back as this step).
    pub fn encode(&self, out: &mut Vec<u8>) {
        let mut put = |b: &[u8]| out.extend_from_slice(b);
        match *self {
            Step::Raw(b) | Step::FromPeer(b) => {
                let n = b.len().min(usize::from(u16::MAX));
                put(&[if matches!(self, Step::Raw(_)) { 0 } else { 1 }]);
                put(&(n as u16).to_le_bytes());
                put(&b[..n]);
            }
            Step::Discovery { index, patches } => {
                put(&[2, index]);
                for (at, value) in patches {
                    put(&at.to_le_bytes());
                    put(&[value]);
                }
            }
            Step::Data { wrap, to, from, sn, len, flags } => {
                put(&[3, wrap, to, from]);
                put(&sn.to_le_bytes());
                put(&len.to_le_bytes());
                put(&[flags]);
            }
            Step::DataFrag { wrap, to, from, sn, start, count, size, sample, len } => {
                put(&[4, wrap, to, from]);
                put(&sn.to_le_bytes());
                put(&start.to_le_bytes());
                put(&count.to_le_bytes());
                put(&size.to_le_bytes());
                put(&sample.to_le_bytes());
                put(&len.to_le_bytes());
            }
            Step::Heartbeat { wrap, to, from, first, last, count, flags } => {
                put(&[5, wrap, to, from]);
                put(&first.to_le_bytes());
                put(&last.to_le_bytes());
                put(&count.to_le_bytes());
                put(&[flags]);
            }
            Step::HeartbeatFrag { wrap, to, from, sn, last, count } => {
                put(&[6, wrap, to, from]);
                put(&sn.to_le_bytes());
                put(&last.to_le_bytes());
                put(&count.to_le_bytes());
            }
            Step::AckNack { wrap, from, to, base, bits, words, count, final_flag } => {
                put(&[7, wrap, from, to]);
                put(&base.to_le_bytes());
                put(&bits.to_le_bytes());
                words.iter().for_each(|w| put(&w.to_le_bytes()));
                put(&count.to_le_bytes());
                put(&[u8::from(final_flag)]);
            }
            Step::Gap { wrap, to, from, start, base, bits, words } => {
                put(&[8, wrap, to, from]);
                put(&start.to_le_bytes());
                put(&base.to_le_bytes());
                put(&bits.to_le_bytes());
                words.iter().for_each(|w| put(&w.to_le_bytes()));
            }
            Step::NackFrag { wrap, from, to, sn, base, bits, words, count } => {
                put(&[9, wrap, from, to]);
                put(&sn.to_le_bytes());
                put(&base.to_le_bytes());
                put(&bits.to_le_bytes());
                words.iter().for_each(|w| put(&w.to_le_bytes()));
                put(&count.to_le_bytes());
            }
            Step::Clock { ms } => {
                put(&[10]);
                put(&ms.to_le_bytes());
            }
            Step::Poll => put(&[11]),
            Step::Write { len } => {
                put(&[12]);
                put(&len.to_le_bytes());
            }
        }
    }
}

/// A whole input: the setup byte (bit 0: do not feed the peer's discovery first; bit 1: create
/// our endpoints after it), then the steps.
pub fn encode_steps(setup: u8, steps: &[Step<'_>]) -> Vec<u8> {
    let mut out = vec![setup];
    steps.iter().for_each(|s| s.encode(&mut out));
    out
}

/// [`participant_steps`] with a setup built for this input alone (the corpus replay's check).
pub fn participant(input: &[u8]) {
    participant_steps(&ParticipantSetup::new(), input);
}

/// Our participant with one reliable writer and one reader on [`TOPIC`], the peer's discovery
/// fed to it (unless the setup byte says not), then `input`'s steps. Nothing is asserted but
/// that nothing panics; the fuzz target adds a bound on the heap.
pub fn participant_steps(setup: &ParticipantSetup, input: &[u8]) {
    let Some((&flags, mut rest)) = input.split_first() else { return };
    let mut now = T0;
    let (mut p, writer, reader) = match &setup.prepared[usize::from(flags & 3)] {
        Some(prepared) => prepared.clone(),
        None => setup.prepare(flags & 3),
    };
    let ids = Ids { writer, reader, peer_writer: setup.peer_writer, peer_reader: setup.peer_reader };
    let mut buf = vec![0u8; 65_536];
    let mut datagram = Vec::with_capacity(65_536);
    let mut payload = Vec::with_capacity(MAX_PAYLOAD + 4);
    while let Some(step) = Step::decode(&mut rest) {
        let destination = |wrap: u8| if wrap & 16 != 0 { Destination::Multicast } else { Destination::Unicast };
        let mut wrap_byte = 0;
        datagram.clear();
        match step {
            Step::Raw(b) => datagram.extend_from_slice(b),
            Step::FromPeer(b) => {
                header(&mut datagram);
                datagram.extend_from_slice(b);
            }
            Step::Discovery { index, patches } => {
                let Some(d) = setup.discovery.get(usize::from(index) % setup.discovery.len().max(1)) else {
                    continue;
                };
                datagram.extend_from_slice(d);
                for (at, value) in patches {
                    if at != 0 && !datagram.is_empty() {
                        let i = usize::from(at - 1) % datagram.len();
                        datagram[i] = value;
                    }
                }
            }
            Step::Clock { ms } => {
                now = now + Duration::from_millis(u64::from(ms % 10_001));
                p.handle_timeout(now);
                continue;
            }
            Step::Poll => {
                while p.poll_transmit(now, &mut buf).is_some() {}
                while let Some(e) = p.poll_event() {
                    if let Event::Sample(s) = e {
                        p.recycle(s.payload);
                    }
                }
                continue;
            }
            Step::Write { len } => {
                fill(&mut payload, usize::from(len) % (MAX_PAYLOAD + 1), 0x5a);
                let _ = p.write(now, writer, &payload, &Default::default(), &mut buf);
                continue;
            }
            templated => {
                wrap_byte = templated_datagram(&mut datagram, &templated, &ids, &mut payload);
            }
        }
        p.handle_datagram(now, address(PEER_PREFIX), destination(wrap_byte), &datagram);
    }
}

/// The endpoints a selector chooses among.
struct Ids {
    writer: EntityId,
    reader: EntityId,
    peer_writer: EntityId,
    peer_reader: EntityId,
}

impl Ids {
    /// A reader for a writer's submessage (ours first).
    fn local_reader(&self, sel: u8) -> EntityId {
        [
            self.reader,
            EntityId::UNKNOWN,
            EntityId::SEDP_PUBLICATIONS_READER,
            EntityId::SEDP_SUBSCRIPTIONS_READER,
            EntityId::SPDP_READER,
            EntityId::P2P_MESSAGE_READER,
            self.writer,
            EntityId([0, 0, sel, 0x04]),
        ][usize::from(sel % 8)]
    }
    /// A writer sending a writer's submessage (the peer's first).
    fn remote_writer(&self, sel: u8) -> EntityId {
        [
            self.peer_writer,
            EntityId::SEDP_PUBLICATIONS_WRITER,
            EntityId::SEDP_SUBSCRIPTIONS_WRITER,
            EntityId::SPDP_WRITER,
            EntityId::P2P_MESSAGE_WRITER,
            EntityId::UNKNOWN,
            self.peer_reader,
            EntityId([0, 0, sel, 0x03]),
        ][usize::from(sel % 8)]
    }
    /// A writer of ours an ACKNACK or NACK_FRAG names.
    fn local_writer(&self, sel: u8) -> EntityId {
        [
            self.writer,
            EntityId::SEDP_PUBLICATIONS_WRITER,
            EntityId::SEDP_SUBSCRIPTIONS_WRITER,
            EntityId::SPDP_WRITER,
            EntityId::P2P_MESSAGE_WRITER,
            EntityId::UNKNOWN,
            self.reader,
            EntityId([0, 0, sel, 0x03]),
        ][usize::from(sel % 8)]
    }
    /// The remote reader sending an ACKNACK or NACK_FRAG.
    fn remote_reader(&self, sel: u8) -> EntityId {
        [
            self.peer_reader,
            EntityId::SEDP_PUBLICATIONS_READER,
            EntityId::SEDP_SUBSCRIPTIONS_READER,
            EntityId::SPDP_READER,
            EntityId::P2P_MESSAGE_READER,
            EntityId::UNKNOWN,
            self.peer_writer,
            EntityId([0, 0, sel, 0x04]),
        ][usize::from(sel % 8)]
    }
}

fn fill(buf: &mut Vec<u8>, len: usize, byte: u8) {
    buf.clear();
    buf.extend_from_slice(&[0, 1, 0, 0]);
    buf.resize(4 + len, byte);
}

fn header(d: &mut Vec<u8>) {
    d.extend_from_slice(b"RTPS\x02\x04\x01\x12");
    d.extend_from_slice(&PEER_PREFIX.0);
}

/// Little- or big-endian field writing for one submessage body.
struct Body<'v> {
    v: &'v mut Vec<u8>,
    little: bool,
}

impl Body<'_> {
    fn u16(&mut self, x: u16) {
        self.v.extend_from_slice(&if self.little { x.to_le_bytes() } else { x.to_be_bytes() });
    }
    fn u32(&mut self, x: u32) {
        self.v.extend_from_slice(&if self.little { x.to_le_bytes() } else { x.to_be_bytes() });
    }
    fn sn(&mut self, sn: i64) {
        self.u32((sn >> 32) as u32);
        self.u32(sn as u32);
    }
    fn ids(&mut self, reader: EntityId, writer: EntityId) {
        self.v.extend_from_slice(&reader.0);
        self.v.extend_from_slice(&writer.0);
    }
    fn set(&mut self, bits: u32, words: &[u32; 8]) {
        self.u32(bits);
        let n = (u64::from(bits).div_ceil(32)).min(8) as usize;
        words[..n].iter().for_each(|w| self.u32(*w));
    }
}

/// Appends a submessage: kind, flags (E added when little-endian), length, body.
fn submessage(d: &mut Vec<u8>, kind: u8, flags: u8, little: bool, body: impl FnOnce(&mut Body<'_>)) {
    d.extend_from_slice(&[kind, flags | u8::from(little), 0, 0]);
    let start = d.len();
    body(&mut Body { v: d, little });
    let len = u16::try_from(d.len() - start).unwrap_or(0);
    let len = if little { len.to_le_bytes() } else { len.to_be_bytes() };
    d[start - 2..start].copy_from_slice(&len);
}

/// Builds a templated step's datagram into `d`; returns its wrap byte.
fn templated_datagram(d: &mut Vec<u8>, step: &Step<'_>, ids: &Ids, payload: &mut Vec<u8>) -> u8 {
    let wrap = match *step {
        Step::Data { wrap, .. }
        | Step::DataFrag { wrap, .. }
        | Step::Heartbeat { wrap, .. }
        | Step::HeartbeatFrag { wrap, .. }
        | Step::AckNack { wrap, .. }
        | Step::Gap { wrap, .. }
        | Step::NackFrag { wrap, .. } => wrap,
        _ => 0,
    };
    let little = wrap & 8 == 0;
    header(d);
    if wrap & 1 != 0 {
        submessage(d, 0x0e, 0, little, |b| b.v.extend_from_slice(&LOCAL_PREFIX.0));
    }
    if wrap & 2 != 0 {
        submessage(d, 0x0e, 0, little, |b| b.v.extend_from_slice(&[0x42; 12]));
    }
    if wrap & 4 != 0 {
        submessage(d, 0x09, 0, little, |b| {
            b.u32(1_700_000_000);
            b.u32(0x8000_0000);
        });
    }
    match *step {
        Step::Data { to, from, sn, len, flags, .. } => {
            let (qos, key, none) = (flags & 1 != 0, flags & 2 != 0, flags & 4 != 0);
            let payload_flag = match (none, key) {
                (true, _) => 0,
                (false, true) => 8,
                (false, false) => 4,
            };
            let f = u8::from(qos) << 1 | payload_flag;
            fill(payload, usize::from(len) % (MAX_PAYLOAD + 1), 0xa5);
            submessage(d, 0x15, f, little, |b| {
                b.u16(0);
                b.u16(16);
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(sn);
                if qos {
                    b.u16(pid::STATUS_INFO);
                    b.u16(4);
                    b.v.extend_from_slice(&[0, 0, 0, flags >> 4]);
                    b.u16(pid::SENTINEL);
                    b.u16(0);
                }
                if !none {
                    b.v.extend_from_slice(payload);
                }
            });
        }
        Step::DataFrag { to, from, sn, start, count, size, sample, len, .. } => {
            let n = if len == 0 {
                let offset = u64::from(start.saturating_sub(1)) * u64::from(size);
                let want = u64::from(count) * u64::from(size);
                want.min(u64::from(sample).saturating_sub(offset))
            } else {
                u64::from(len - 1)
            };
            payload.clear();
            payload.resize(n.min(MAX_PAYLOAD as u64) as usize, 0x3c);
            submessage(d, 0x16, 0, little, |b| {
                b.u16(0);
                b.u16(28);
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(sn);
                b.u32(start);
                b.u16(count);
                b.u16(size);
                b.u32(sample);
                b.v.extend_from_slice(payload);
            });
        }
        Step::Heartbeat { to, from, first, last, count, flags, .. } => {
            submessage(d, 0x07, (flags & 3) << 1, little, |b| {
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(first);
                b.sn(last);
                b.u32(count as u32);
            });
        }
        Step::HeartbeatFrag { to, from, sn, last, count, .. } => {
            submessage(d, 0x13, 0, little, |b| {
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(sn);
                b.u32(last);
                b.u32(count as u32);
            });
        }
        Step::AckNack { from, to, base, bits, ref words, count, final_flag, .. } => {
            submessage(d, 0x06, u8::from(final_flag) << 1, little, |b| {
                b.ids(ids.remote_reader(from), ids.local_writer(to));
                b.sn(base);
                b.set(bits, words);
                b.u32(count as u32);
            });
        }
        Step::Gap { to, from, start, base, bits, ref words, .. } => {
            submessage(d, 0x08, 0, little, |b| {
                b.ids(ids.local_reader(to), ids.remote_writer(from));
                b.sn(start);
                b.sn(base);
                b.set(bits, words);
            });
        }
        Step::NackFrag { from, to, sn, base, bits, ref words, count, .. } => {
            submessage(d, 0x12, 0, little, |b| {
                b.ids(ids.remote_reader(from), ids.local_writer(to));
                b.sn(sn);
                b.u32(base);
                b.set(bits, words);
                b.u32(count as u32);
            });
        }
        _ => {}
    }
    wrap
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_setup_discovers_and_matches_the_peer() {
        let setup = ParticipantSetup::new();
        assert!(!setup.discovery.is_empty());
        let mut p = Participant::new(fuzz_config(LOCAL_PREFIX), T0);
        let w = p.create_writer(T0, TOPIC, TYPE_NAME, Qos::default()).unwrap();
        let r = p.create_reader(T0, TOPIC, TYPE_NAME, Qos::default()).unwrap();
        for d in &setup.discovery {
            p.handle_datagram(T0, address(PEER_PREFIX), Destination::Unicast, d);
        }
        assert_eq!(p.matched_readers(w).count(), 1);
        assert_eq!(p.matched_writers(r).count(), 1);
    }

    #[test]
    fn steps_decode_as_encoded() {
        let steps = [
            Step::Raw(&[1, 2, 3]),
            Step::FromPeer(&[]),
            Step::Discovery { index: 3, patches: [(1, 2), (0, 0)] },
            Step::Data { wrap: 5, to: 0, from: 0, sn: 1, len: 8, flags: 1 },
            Step::DataFrag { wrap: 0, to: 0, from: 0, sn: 2, start: 1, count: 1, size: 1024, sample: 3000, len: 0 },
            Step::Heartbeat { wrap: 8, to: 0, from: 0, first: 1, last: 3, count: 1, flags: 0 },
            Step::HeartbeatFrag { wrap: 0, to: 0, from: 0, sn: 2, last: 2, count: 1 },
            Step::AckNack { wrap: 0, from: 0, to: 0, base: 1, bits: 8, words: [1; 8], count: 1, final_flag: true },
            Step::Gap { wrap: 0, to: 0, from: 0, start: 1, base: 2, bits: 0, words: [0; 8] },
            Step::NackFrag { wrap: 0, from: 0, to: 0, sn: 1, base: 1, bits: 3, words: [7; 8], count: 2 },
            Step::Clock { ms: 100 },
            Step::Poll,
            Step::Write { len: 3000 },
        ];
        let ids = Ids {
            writer: EntityId([0, 0, 1, 3]),
            reader: EntityId([0, 0, 2, 4]),
            peer_writer: EntityId([0, 0, 1, 3]),
            peer_reader: EntityId([0, 0, 2, 4]),
        };
        for step in &steps[3..10] {
            let (mut d, mut payload) = (Vec::new(), Vec::new());
            templated_datagram(&mut d, step, &ids, &mut payload);
            let m = Message::parse(&d).unwrap();
            assert!(m.submessages().all(|s| s.is_ok()), "{step:?}");
        }
        let bytes = encode_steps(0, &steps);
        let mut rest = &bytes[1..];
        let back: Vec<Step<'_>> = core::iter::from_fn(|| Step::decode(&mut rest)).collect();
        assert_eq!(back, steps);
        participant(&bytes);
    }
}
