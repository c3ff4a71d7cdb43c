//! The flood's datagrams: garbage, near-valid RTPS and captured ones with bits flipped, and which
//! of them rustdds 0.15.1 would trust.

use std::net::Ipv4Addr;

/// Domain 0's multicast group.
pub(crate) const GROUP: Ipv4Addr = Ipv4Addr::new(239, 255, 0, 1);
/// The SPDP writer's entity id: its DATA is a participant's announcement.
pub(crate) const SPDP_WRITER: [u8; 4] = [0, 1, 0, 0xC2];

/// SplitMix64.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let z = (self.0 ^ (self.0 >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        let z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (n > 0).
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.u64() % n as u64) as usize
    }

    pub(crate) fn one_in(&mut self, n: usize) -> bool {
        self.below(n) == 0
    }

    pub(crate) fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    pub(crate) fn fill(&mut self, out: &mut Vec<u8>, n: usize) {
        out.extend((0..n).map(|_| self.u64() as u8));
    }

    /// A count or number at an edge half the time.
    fn wild_u32(&mut self) -> u32 {
        const EDGES: [u32; 8] = [0, 1, 2, 0x7FFF_FFFF, 0x8000_0000, 0xFFFF_FFFE, 0xFFFF_FFFF, 0x0001_0000];
        match self.below(4) {
            0 | 1 => *self.pick(&EDGES),
            2 => self.below(300) as u32,
            _ => self.u64() as u32,
        }
    }
}

/// Bytes of one submessage, in the byte order its E flag says.
struct Wire<'a> {
    out: &'a mut Vec<u8>,
    little: bool,
}

impl Wire<'_> {
    fn u16(&mut self, v: u16) {
        self.out.extend(if self.little { v.to_le_bytes() } else { v.to_be_bytes() });
    }

    fn u32(&mut self, v: u32) {
        self.out.extend(if self.little { v.to_le_bytes() } else { v.to_be_bytes() });
    }

    /// A sequence number (high, low).
    fn sn(&mut self, rng: &mut Rng) {
        let high = if rng.one_in(2) { 0 } else { rng.wild_u32() };
        self.u32(high);
        self.u32(rng.wild_u32());
    }

    /// A sequence or fragment number set: its base, a bit count that may lie, up to 8 words.
    fn set(&mut self, rng: &mut Rng, sequence_numbers: bool) {
        if sequence_numbers {
            self.sn(rng);
        } else {
            self.u32(rng.wild_u32());
        }
        let bits = if rng.one_in(4) { rng.wild_u32() } else { rng.below(257) as u32 };
        self.u32(bits);
        let words = if rng.one_in(4) { rng.below(9) } else { (bits.min(256) as usize).div_ceil(32) };
        for _ in 0..words {
            self.u32(rng.u64() as u32);
        }
    }

    fn entity(&mut self, rng: &mut Rng) {
        /// Builtin endpoints (SPDP, SEDP, participant messages), unknown, and user ones.
        const ENTITIES: [[u8; 4]; 12] = [
            [0, 0, 0, 0],
            [0, 0, 1, 0xC1],
            [0, 1, 0, 0xC2],
            [0, 1, 0, 0xC7],
            [0, 0, 3, 0xC2],
            [0, 0, 3, 0xC7],
            [0, 0, 4, 0xC2],
            [0, 0, 4, 0xC7],
            [0, 2, 0, 0xC2],
            [0, 2, 0, 0xC7],
            [0, 0, 1, 0x02],
            [0, 0, 1, 0x07],
        ];
        if rng.one_in(5) {
            rng.fill(self.out, 4);
        } else {
            self.out.extend(rng.pick(&ENTITIES));
        }
    }

    /// A UDPv4 locator, on loopback or the group most of the time.
    fn locator(&mut self, rng: &mut Rng) {
        self.u32(if rng.one_in(4) { rng.wild_u32() } else { 1 });
        self.u32(if rng.one_in(4) { rng.wild_u32() } else { 7400 + rng.below(40) as u32 });
        self.out.extend([0; 12]);
        match rng.below(4) {
            0 => rng.fill(self.out, 4),
            1 => self.out.extend(GROUP.octets()),
            _ => self.out.extend([127, 0, 0, 1]),
        }
    }

    /// A parameter list (inline QoS, discovery data) of parameters whose lengths may lie.
    fn parameters(&mut self, rng: &mut Rng, prefixes: &[[u8; 12]]) {
        /// Lease, topic/type names, reliability, versions, locators, GUIDs, builtin endpoints,
        /// key hash, status info.
        const PIDS: [u16; 16] = [
            0x0002, 0x0005, 0x0007, 0x001A, 0x0015, 0x0016, 0x002F, 0x0031, 0x0032, 0x0033, 0x0048, 0x0050, 0x0058,
            0x005A, 0x0070, 0x0071,
        ];
        for _ in 0..rng.below(12) {
            let pid = if rng.one_in(6) { rng.u64() as u16 } else { *rng.pick(&PIDS) };
            self.u16(pid);
            let length_at = self.out.len();
            self.u16(0);
            let start = self.out.len();
            match pid {
                0x002F | 0x0031..=0x0033 | 0x0048 => self.locator(rng),
                0x0050 | 0x005A => {
                    self.out.extend(guid_prefix(rng, prefixes));
                    self.entity(rng);
                }
                0x0005 | 0x0007 => {
                    let len = rng.below(40);
                    self.u32(if rng.one_in(4) { rng.wild_u32() } else { len as u32 });
                    rng.fill(self.out, len);
                }
                _ => {
                    let len = rng.below(33);
                    rng.fill(self.out, len);
                }
            }
            self.out.resize(start + (self.out.len() - start).next_multiple_of(4), 0);
            let len = self.out.len() - start;
            let stated = if rng.one_in(4) { rng.u64() as u16 } else { len as u16 };
            let bytes = if self.little { stated.to_le_bytes() } else { stated.to_be_bytes() };
            self.out[length_at..length_at + 2].copy_from_slice(&bytes);
        }
        if !rng.one_in(5) {
            self.u16(1); // PID_SENTINEL
            self.u16(0);
        }
    }

    /// A serialized payload: an encapsulation header, then a parameter list or random bytes.
    fn payload(&mut self, rng: &mut Rng, prefixes: &[[u8; 12]]) {
        let kind = if rng.one_in(5) { rng.u64() as u8 } else { *rng.pick(&[0, 1, 2, 3, 6, 7, 8, 9, 10, 11]) };
        self.out.extend([0, kind, 0, 0]);
        if kind == 2 || kind == 3 {
            Wire { out: self.out, little: kind == 3 }.parameters(rng, prefixes);
        } else {
            let len = rng.below(200);
            rng.fill(self.out, len);
        }
    }
}

/// A known participant's GUID prefix half the time (spoofing it), else a random one.
fn guid_prefix(rng: &mut Rng, prefixes: &[[u8; 12]]) -> [u8; 12] {
    if !prefixes.is_empty() && rng.one_in(2) {
        return *rng.pick(prefixes);
    }
    std::array::from_fn(|_| rng.u64() as u8)
}

/// The body of submessage `id` with random fields (RTPS 2.5 §9.4.5).
fn submessage_body(rng: &mut Rng, id: u8, flags: u8, wire: &mut Wire<'_>, prefixes: &[[u8; 12]]) {
    let inline_qos = flags & 0x02 != 0;
    match id {
        // DATA
        0x15 => {
            wire.u16(0);
            wire.u16(if rng.one_in(4) { rng.u64() as u16 } else { 16 });
            wire.entity(rng);
            wire.entity(rng);
            wire.sn(rng);
            if inline_qos {
                wire.parameters(rng, prefixes);
            }
            if flags & 0x0C != 0 {
                wire.payload(rng, prefixes);
            }
        }
        // DATA_FRAG: a sample size up to 4 GiB
        0x16 => {
            wire.u16(0);
            wire.u16(if rng.one_in(4) { rng.u64() as u16 } else { 28 });
            wire.entity(rng);
            wire.entity(rng);
            wire.sn(rng);
            wire.u32(rng.wild_u32());
            wire.u16(rng.wild_u32() as u16);
            wire.u16(rng.wild_u32() as u16);
            wire.u32(rng.wild_u32());
            if inline_qos {
                wire.parameters(rng, prefixes);
            }
            let len = rng.below(256);
            rng.fill(wire.out, len);
        }
        // HEARTBEAT
        0x07 => {
            wire.entity(rng);
            wire.entity(rng);
            wire.sn(rng);
            wire.sn(rng);
            wire.u32(rng.wild_u32());
        }
        // ACKNACK
        0x06 => {
            wire.entity(rng);
            wire.entity(rng);
            wire.set(rng, true);
            wire.u32(rng.wild_u32());
        }
        // GAP
        0x08 => {
            wire.entity(rng);
            wire.entity(rng);
            wire.sn(rng);
            wire.set(rng, true);
        }
        // NACK_FRAG
        0x12 => {
            wire.entity(rng);
            wire.entity(rng);
            wire.sn(rng);
            wire.set(rng, false);
            wire.u32(rng.wild_u32());
        }
        // HEARTBEAT_FRAG
        0x13 => {
            wire.entity(rng);
            wire.entity(rng);
            wire.sn(rng);
            wire.u32(rng.wild_u32());
            wire.u32(rng.wild_u32());
        }
        // INFO_TS (none with the I flag)
        0x09 if !inline_qos => {
            wire.u32(rng.wild_u32());
            wire.u32(rng.wild_u32());
        }
        // INFO_SRC
        0x0C => {
            wire.u32(rng.wild_u32());
            wire.out.extend([2, rng.below(6) as u8, 1, 0x12]);
            wire.out.extend(guid_prefix(rng, prefixes));
        }
        // INFO_DST
        0x0E => wire.out.extend(guid_prefix(rng, prefixes)),
        // INFO_REPLY: locator lists whose counts may lie
        0x0F => {
            for _ in 0..1 + usize::from(inline_qos) {
                let n = rng.below(4);
                wire.u32(if rng.one_in(4) { rng.wild_u32() } else { n as u32 });
                for _ in 0..n {
                    wire.locator(rng);
                }
            }
        }
        // INFO_REPLY_IP4
        0x0D => {
            for _ in 0..1 + usize::from(inline_qos) {
                wire.out.extend([127, 0, 0, 1]);
                wire.u32(rng.wild_u32());
            }
        }
        // PAD, the security submessages, anything else
        _ => {
            let len = rng.below(64);
            rng.fill(wire.out, len);
        }
    }
}

/// An RTPS header (protocol 2.x, a vendor, a GUID prefix), then up to 8 submessages whose bodies
/// are cut short at times and whose `octetsToNextHeader` lies more often than not.
pub(crate) fn near_valid_rtps(rng: &mut Rng, prefixes: &[[u8; 12]], out: &mut Vec<u8>) {
    /// PAD, ACKNACK, HEARTBEAT, GAP, INFO_TS, INFO_SRC, INFO_REPLY_IP4, INFO_DST, INFO_REPLY,
    /// NACK_FRAG, HEARTBEAT_FRAG, DATA, DATA_FRAG, SEC_BODY, SEC_PREFIX, SRTPS_PREFIX.
    const IDS: [u8; 16] =
        [0x01, 0x06, 0x07, 0x08, 0x09, 0x0C, 0x0D, 0x0E, 0x0F, 0x12, 0x13, 0x15, 0x16, 0x30, 0x31, 0x33];
    /// RTI, OpenSplice, eProsima, CycloneDDS, RustDDS, unknown.
    const VENDORS: [[u8; 2]; 6] = [[1, 1], [1, 2], [1, 0x0F], [1, 0x10], [1, 0x12], [0, 0]];
    out.extend(b"RTPS");
    out.extend([2, rng.below(6) as u8]);
    out.extend(rng.pick(&VENDORS));
    out.extend(guid_prefix(rng, prefixes));
    for _ in 0..=rng.below(8) {
        let id = if rng.one_in(10) { rng.u64() as u8 } else { *rng.pick(&IDS) };
        let flags = rng.u64() as u8;
        let little = flags & 1 == 1;
        let start = out.len();
        out.extend([id, flags, 0, 0]);
        submessage_body(rng, id, flags, &mut Wire { out, little }, prefixes);
        let body = out.len() - start - 4;
        if rng.one_in(4) {
            out.truncate(start + 4 + rng.below(body + 1));
        }
        let body = out.len() - start - 4;
        let stated = match rng.below(6) {
            0 | 1 => body,
            2 => 0,
            3 => (body + rng.below(9)).saturating_sub(4),
            4 => 0xFFFF,
            _ => rng.below(0x1_0000),
        } as u16;
        out[start + 2..start + 4].copy_from_slice(&if little { stated.to_le_bytes() } else { stated.to_be_bytes() });
    }
}

/// A captured datagram with 1 to 8 bits flipped (one in ten also cut short).
pub(crate) fn bit_flipped(rng: &mut Rng, captured: &[Vec<u8>], out: &mut Vec<u8>) {
    out.extend(rng.pick(captured));
    for _ in 0..=rng.below(8) {
        let bit = rng.below(out.len() * 8);
        out[bit / 8] ^= 1 << (bit % 8);
    }
    if rng.one_in(10) {
        out.truncate(rng.below(out.len()));
    }
}

/// The submessages of an RTPS datagram as rustdds 0.15.1 splits them (`Submessage::read_from_buffer`):
/// `(kind, flags, body)`, a zero length meaning "to the end" except for PAD and INFO_TS; a length
/// past the end ends the walk (rustdds drops the whole datagram then).
pub(crate) fn submessages(datagram: &[u8]) -> impl Iterator<Item = (u8, u8, &[u8])> {
    let mut rest = if datagram.len() >= 20 && datagram.starts_with(b"RTPS") { &datagram[20..] } else { &[][..] };
    std::iter::from_fn(move || {
        let (&[kind, flags, a, b], after) = rest.split_first_chunk::<4>()?;
        let stated = usize::from(if flags & 1 == 1 { u16::from_le_bytes([a, b]) } else { u16::from_be_bytes([a, b]) });
        let len = match (stated, kind) {
            (0, 0x01 | 0x09) => 0,
            (0, _) => after.len(),
            (n, _) => n,
        };
        let body = after.get(..len)?;
        rest = &after[len..];
        Some((kind, flags, body))
    })
}

/// How far a sequence (or fragment) number range may reach in the default flood.
const SPAN: i128 = 1 << 16;

/// Which of the fields rustdds 0.15.1 trusts `datagram` sets out of bounds, if any. Each is one
/// datagram from anyone that breaks a participant (for the HEARTBEAT, GAP and NACK_FRAG: spoofing a
/// participant seen on the network, whose GUID prefix is in its announcements):
///
/// - DATA_FRAG `sampleSize` (to any reader, from any writer GUID): `AssemblyBuffer::new`
///   (`src/rtps/fragment_assembler.rs`) allocates and zeroes that many bytes, up to 4 GiB, per
///   writer GUID and sequence number (128 per writer, writers unbounded);
/// - HEARTBEAT `firstSN..lastSN` (from a matched writer): `RtpsWriterProxy::missing_seqnums`
///   (`src/rtps/rtps_writer_proxy.rs`) collects every sequence number of the range into a `Vec`,
///   of which `Reader::handle_heartbeat_msg` uses 256: 2^32 numbers are 32 GiB;
/// - GAP `gapStart..gapList.base` (from a matched writer): `irrelevant_changes_range` (same file)
///   inserts every number of the range into a `BTreeMap` ("TODO: This potentially generates a
///   very large BTreeMap");
/// - NACK_FRAG `fragmentNumberState` (from a matched reader, for any sequence number):
///   `RtpsReaderProxy::mark_frags_requested` grows a `BitVec` to the highest fragment number (up
///   to 2^32 bits), which the writer's repair timer clones and scans bit by bit on every tick;
///   and it takes fragment number 0 (`bitmapBase` 0, bit 0 set) as index `0 - 1`: a panic with
///   overflow checks, `capacity overflow` without;
/// - a sequence number set's `bitmapBase` near `i64::MAX` (an ACKNACK's `readerSNState`, to any
///   reliable writer, from anyone): `bitmapBase + bit index` overflows in `NumberSetIter::next`
///   (called first by `Writer::handle_ack_nack`): with overflow checks (every debug build) a panic
///   on the participant's event-loop thread, which ends it. A GAP's `gapList` goes through the
///   same sum; HEARTBEATs and GAPs that near the end are kept out as well.
pub(crate) fn rustdds_0_15_1_trusts(datagram: &[u8]) -> Option<&'static str> {
    for (kind, flags, body) in submessages(datagram) {
        let little = flags & 1 == 1;
        let u32_at = |at: usize| {
            let b: [u8; 4] = body.get(at..at + 4)?.try_into().ok()?;
            Some(if little { u32::from_le_bytes(b) } else { u32::from_be_bytes(b) })
        };
        let sn_at = |at: usize| Some(i128::from(((i64::from(u32_at(at)? as i32)) << 32) + i64::from(u32_at(at + 4)?)));
        let near_max = |sn: Option<i128>| sn.is_some_and(|sn| sn > i128::from(i64::MAX) - SPAN);
        let wide = |first: Option<i128>, last: Option<i128>| match (first, last) {
            (Some(first), Some(last)) => last - first.max(0) > SPAN,
            _ => false,
        };
        let trusted = match kind {
            0x16 if u32_at(28).is_some_and(|size| size > 0xFFFF) => "DATA_FRAG sampleSize",
            0x07 if wide(sn_at(8), sn_at(16)) => "HEARTBEAT range",
            0x08 if wide(sn_at(8), sn_at(16)) => "GAP range",
            0x12 if u32_at(16) == Some(0) => "NACK_FRAG fragment number 0",
            0x12 if u32_at(16)
                .zip(u32_at(20))
                .is_some_and(|(base, bits)| i128::from(base) + i128::from(bits) > SPAN) =>
            {
                "NACK_FRAG fragment numbers"
            }
            0x06..=0x08 if near_max(sn_at(8)) || near_max(sn_at(16)) => "sequence number overflow",
            _ => continue,
        };
        return Some(trusted);
    }
    None
}

/// For each field of [`rustdds_0_15_1_trusts`], one datagram that sets it, as the participant of
/// GUID prefix `from` would send it to another participant.
pub(crate) use robowire_fixtures::rtps::hostile_datagrams as one_datagram_each;
