//! Properties of the wire layer: no input panics it, emit then parse gives back every repr, and
//! the number sets behave as sets.

use proptest::prelude::*;
use rtps_proto::types::{
    EntityId, FragmentNumberSet, GuidPrefix, Locator, ProtocolVersion, SequenceNumber, SequenceNumberSet, Timestamp,
    VendorId,
};
use rtps_proto::wire::{
    AckNack, Data, DataFrag, Endianness, Gap, Heartbeat, HeartbeatFrag, InfoDst, InfoReply, InfoReplyIp4, InfoSrc,
    InfoTs, LocatorList, NackFrag, ParameterList, ParameterWriter, Payload, Submessage, SubmessageKind,
};
use std::collections::BTreeSet;

/// Every repr as owned values (reprs borrow; each case builds one from these).
#[derive(Debug, Clone)]
enum Owned {
    Data {
        ids: ([u8; 4], [u8; 4]),
        sn: i64,
        qos: Option<Vec<(u16, Vec<u8>)>>,
        payload: (u8, Vec<u8>),
        n: bool,
    },
    DataFrag {
        ids: ([u8; 4], [u8; 4]),
        sn: i64,
        frag: (u16, u32, u32, u16),
        qos: Option<Vec<(u16, Vec<u8>)>>,
        flags: (bool, bool),
        fill: u8,
    },
    Heartbeat(Heartbeat),
    HeartbeatFrag(HeartbeatFrag),
    AckNack(AckNack),
    NackFrag(NackFrag),
    Gap(Gap),
    InfoTs(InfoTs),
    InfoDst(InfoDst),
    InfoSrc(InfoSrc),
    InfoReply(Vec<Locator>, Option<Vec<Locator>>),
    InfoReplyIp4(InfoReplyIp4),
    Pad,
    Unknown(u8, u8, Vec<u8>),
}

fn entity() -> impl Strategy<Value = EntityId> {
    any::<[u8; 4]>().prop_map(EntityId)
}

fn sn() -> impl Strategy<Value = SequenceNumber> {
    prop_oneof![1..1000i64, 1..=i64::MAX].prop_map(SequenceNumber)
}

fn qos() -> impl Strategy<Value = Option<Vec<(u16, Vec<u8>)>>> {
    prop::option::of(prop::collection::vec((2..=u16::MAX, prop::collection::vec(any::<u8>(), 0..12)), 0..5))
}

fn locator() -> impl Strategy<Value = Locator> {
    (any::<i32>(), any::<u32>(), any::<[u8; 16]>()).prop_map(|(kind, port, address)| Locator { kind, port, address })
}

fn udpv4() -> impl Strategy<Value = Locator> {
    (any::<u32>(), any::<u32>()).prop_map(|(a, port)| {
        let mut address = [0; 16];
        address[12..].copy_from_slice(&a.to_be_bytes());
        Locator { kind: Locator::KIND_UDPV4, port, address }
    })
}

fn sn_set() -> impl Strategy<Value = SequenceNumberSet> {
    (prop_oneof![1..1000i64, 1..=i64::MAX - 256], 0..=256u32, any::<[u32; 8]>())
        .prop_map(|(base, bits, words)| SequenceNumberSet::from_words(SequenceNumber(base), bits, &words).unwrap())
}

fn fragments() -> impl Strategy<Value = (u16, u32, u32, u16)> {
    (1..=64u16, 1..=3000u32).prop_flat_map(|(size, sample)| {
        let total = sample.div_ceil(u32::from(size));
        (Just(size), Just(sample), 1..=total).prop_flat_map(move |(size, sample, start)| {
            let most = (total - start + 1).min(u32::from(u16::MAX)) as u16;
            (Just(size), Just(sample), Just(start), 1..=most)
        })
    })
}

fn owned() -> impl Strategy<Value = Owned> {
    let ids = || (any::<[u8; 4]>(), any::<[u8; 4]>());
    prop_oneof![
        (ids(), sn(), qos(), (0..3u8, prop::collection::vec(any::<u8>(), 0..40)), any::<bool>())
            .prop_map(|(ids, sn, qos, payload, n)| Owned::Data { ids, sn: sn.0, qos, payload, n }),
        (ids(), sn(), fragments(), qos(), any::<(bool, bool)>(), any::<u8>())
            .prop_map(|(ids, sn, frag, qos, flags, fill)| Owned::DataFrag { ids, sn: sn.0, frag, qos, flags, fill }),
        (entity(), entity(), sn(), 0..=1000i64, any::<i32>(), any::<bool>(), any::<bool>()).prop_map(
            |(reader_id, writer_id, first_sn, span, count, final_flag, liveliness_flag)| {
                let last_sn = SequenceNumber(first_sn.0.saturating_add(span) - 1);
                Owned::Heartbeat(Heartbeat {
                    reader_id,
                    writer_id,
                    first_sn,
                    last_sn,
                    count,
                    final_flag,
                    liveliness_flag,
                })
            }
        ),
        (entity(), entity(), sn(), 1..=u32::MAX, any::<i32>()).prop_map(
            |(reader_id, writer_id, writer_sn, last_fragment_num, count)| {
                Owned::HeartbeatFrag(HeartbeatFrag { reader_id, writer_id, writer_sn, last_fragment_num, count })
            }
        ),
        (entity(), entity(), sn_set(), any::<i32>(), any::<bool>()).prop_map(
            |(reader_id, writer_id, reader_sn_state, count, final_flag)| {
                Owned::AckNack(AckNack { reader_id, writer_id, reader_sn_state, count, final_flag })
            }
        ),
        (entity(), entity(), sn(), 1..=u32::MAX - 256, 0..=256u32, any::<[u32; 8]>(), any::<i32>()).prop_map(
            |(reader_id, writer_id, writer_sn, base, bits, words, count)| {
                let fragment_number_state = FragmentNumberSet::from_words(base, bits, &words).unwrap();
                Owned::NackFrag(NackFrag { reader_id, writer_id, writer_sn, fragment_number_state, count })
            }
        ),
        (entity(), entity(), sn_set(), 0..=1000i64).prop_map(|(reader_id, writer_id, gap_list, back)| {
            let gap_start = SequenceNumber((gap_list.base().0 - back).max(1));
            Owned::Gap(Gap { reader_id, writer_id, gap_start, gap_list })
        }),
        prop::option::of(any::<(i32, u32)>()).prop_map(|t| Owned::InfoTs(InfoTs {
            timestamp: t.map(|(seconds, fraction)| Timestamp { seconds, fraction })
        })),
        any::<[u8; 12]>().prop_map(|p| Owned::InfoDst(InfoDst { guid_prefix: GuidPrefix(p) })),
        (any::<[u8; 2]>(), any::<[u8; 2]>(), any::<[u8; 12]>()).prop_map(|(v, vendor, p)| Owned::InfoSrc(InfoSrc {
            version: ProtocolVersion { major: v[0], minor: v[1] },
            vendor: VendorId(vendor),
            guid_prefix: GuidPrefix(p),
        })),
        (prop::collection::vec(locator(), 0..4), prop::option::of(prop::collection::vec(locator(), 0..4)))
            .prop_map(|(u, m)| Owned::InfoReply(u, m)),
        (udpv4(), prop::option::of(udpv4()))
            .prop_map(|(unicast, multicast)| Owned::InfoReplyIp4(InfoReplyIp4 { unicast, multicast })),
        Just(Owned::Pad),
        (
            prop_oneof![0x80..=0xffu8, Just(0x00u8), 0x02..=0x05u8, Just(0x0au8), Just(0x11u8), Just(0x14u8)],
            any::<u8>(),
            prop::collection::vec(any::<u8>(), 1..40)
        )
            .prop_map(|(k, f, b)| Owned::Unknown(k, f, b)),
    ]
}

fn list_bytes(params: &[(u16, Vec<u8>)]) -> Vec<u8> {
    let mut buf = vec![0u8; 4 + params.iter().map(|(_, v)| 4 + v.len().next_multiple_of(4)).sum::<usize>()];
    let mut w = ParameterWriter::new(&mut buf);
    for (pid, value) in params {
        w.push(*pid, value).unwrap();
    }
    let n = w.finish().unwrap();
    assert_eq!(n, buf.len());
    buf
}

fn locator_bytes(locators: &[Locator]) -> Vec<u8> {
    locators.iter().flat_map(|l| [&l.kind.to_le_bytes()[..], &l.port.to_le_bytes(), &l.address].concat()).collect()
}

/// Emits `s`, parses it back from the emitted header and body, and compares.
fn round_trip(s: &Submessage<'_>) -> Result<(), TestCaseError> {
    let mut buf = vec![0u8; s.buffer_len()];
    prop_assert_eq!(s.emit(&mut buf), Ok(buf.len()));
    prop_assert_eq!(SubmessageKind::from_id(buf[0]), s.kind());
    let again = Submessage::parse(buf[0], buf[1], &buf[4..]).unwrap();
    prop_assert_eq!(&again, s);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn emit_then_parse_gives_the_repr(owned in owned()) {
        let (qos_bytes, payload_bytes);
        let (uni, multi);
        let s = match &owned {
            Owned::Data { ids, sn, qos, payload, n } => {
                qos_bytes = qos.as_ref().map(|q| list_bytes(q));
                payload_bytes = payload.1.clone();
                let payload = match payload.0 {
                    0 => Payload::None,
                    1 => Payload::Data(&payload_bytes),
                    _ => Payload::Key(&payload_bytes),
                };
                Submessage::Data(Data {
                    reader_id: EntityId(ids.0),
                    writer_id: EntityId(ids.1),
                    writer_sn: SequenceNumber(*sn),
                    inline_qos: qos_bytes.as_deref().map(|b| ParameterList::little_endian(b).unwrap()),
                    payload,
                    non_standard_payload: *n,
                })
            }
            Owned::DataFrag { ids, sn, frag: (size, sample, start, count), qos, flags, fill } => {
                qos_bytes = qos.as_ref().map(|q| list_bytes(q));
                let mut f = DataFrag {
                    reader_id: EntityId(ids.0),
                    writer_id: EntityId(ids.1),
                    writer_sn: SequenceNumber(*sn),
                    fragment_starting_num: *start,
                    fragments_in_submessage: *count,
                    fragment_size: *size,
                    sample_size: *sample,
                    inline_qos: qos_bytes.as_deref().map(|b| ParameterList::little_endian(b).unwrap()),
                    key: flags.0,
                    non_standard_payload: flags.1,
                    payload: &[],
                };
                payload_bytes = vec![*fill; f.fragment_bytes().unwrap() as usize];
                f.payload = &payload_bytes;
                Submessage::DataFrag(f)
            }
            Owned::Heartbeat(h) => Submessage::Heartbeat(*h),
            Owned::HeartbeatFrag(h) => Submessage::HeartbeatFrag(*h),
            Owned::AckNack(a) => Submessage::AckNack(*a),
            Owned::NackFrag(n) => Submessage::NackFrag(*n),
            Owned::Gap(g) => Submessage::Gap(*g),
            Owned::InfoTs(t) => Submessage::InfoTs(*t),
            Owned::InfoDst(d) => Submessage::InfoDst(*d),
            Owned::InfoSrc(s) => Submessage::InfoSrc(*s),
            Owned::InfoReply(u, m) => {
                uni = locator_bytes(u);
                multi = m.as_ref().map(|m| locator_bytes(m));
                Submessage::InfoReply(InfoReply {
                    unicast: LocatorList::new(&uni, Endianness::Little).unwrap(),
                    multicast: multi.as_deref().map(|m| LocatorList::new(m, Endianness::Little).unwrap()),
                })
            }
            Owned::InfoReplyIp4(r) => Submessage::InfoReplyIp4(*r),
            Owned::Pad => Submessage::Pad,
            Owned::Unknown(kind, flags, body) => Submessage::Unknown { kind: *kind, flags: *flags, body },
        };
        round_trip(&s)?;
    }

    #[test]
    fn no_bytes_panic(mut bytes in prop::collection::vec(any::<u8>(), 0..400), header in any::<bool>()) {
        if header {
            let mut d = b"RTPS\x02\x04\x01\x10".to_vec();
            d.extend([0; 12]);
            d.append(&mut bytes);
            bytes = d;
        }
        rtps_proto::fuzzing::parse_all(&bytes);
        for e in [Endianness::Big, Endianness::Little] {
            if let Ok((list, used)) = ParameterList::parse(&bytes, e) {
                prop_assert!(used <= bytes.len());
                for p in list.iter() {
                    let _ = rtps_proto::wire::pid::name(p.pid);
                }
            }
        }
    }

    /// Framed submessages of every kind with arbitrary bodies: deeper than random bytes reach.
    #[test]
    fn no_submessage_panics(
        submessages in prop::collection::vec(
            (prop_oneof![prop::sample::select(vec![1u8, 6, 7, 8, 9, 12, 13, 14, 15, 0x12, 0x13, 0x15, 0x16]), any::<u8>()],
             any::<u8>(), prop::collection::vec(any::<u8>(), 0..80)),
            0..6
        )
    ) {
        let mut d = b"RTPS\x02\x05\x01\x10".to_vec();
        d.extend([0; 12]);
        for (kind, flags, body) in &submessages {
            d.extend([*kind, *flags]);
            let len = body.len() as u16;
            d.extend(if flags & 1 == 1 { len.to_le_bytes() } else { len.to_be_bytes() });
            d.extend(body);
        }
        rtps_proto::fuzzing::parse_all(&d);
    }

    #[test]
    fn sequence_number_set_is_a_set(
        base in prop_oneof![1..100i64, 1..=i64::MAX - 256, Just(i64::MAX - 256)],
        bits in 0..=256u32,
        inserts in prop::collection::vec(-10..300i64, 0..60),
    ) {
        let mut set = SequenceNumberSet::new(SequenceNumber(base), bits).unwrap();
        let mut model = BTreeSet::new();
        for d in inserts {
            let Some(sn) = base.checked_add(d) else { continue };
            let inside = (0..i64::from(bits)).contains(&d);
            prop_assert_eq!(set.insert(SequenceNumber(sn)), inside);
            if inside {
                model.insert(sn);
            }
        }
        prop_assert_eq!(set.iter().map(|s| s.0).collect::<BTreeSet<_>>(), model.clone());
        for d in -10..300i64 {
            let Some(sn) = base.checked_add(d) else { continue };
            prop_assert_eq!(set.contains(SequenceNumber(sn)), model.contains(&sn));
        }
        let again = SequenceNumberSet::from_words(set.base(), set.num_bits(), set.words()).unwrap();
        prop_assert_eq!(again, set);
        prop_assert_eq!(set.is_empty(), model.is_empty());
    }

    #[test]
    fn fragment_number_set_is_a_set(
        base in prop_oneof![1..100u32, 1..=u32::MAX - 256],
        bits in 0..=256u32,
        inserts in prop::collection::vec(0..300u32, 0..60),
    ) {
        let mut set = FragmentNumberSet::new(base, bits).unwrap();
        let mut model = BTreeSet::new();
        for d in inserts {
            let n = base.saturating_sub(5).saturating_add(d);
            let inside = n >= base && n - base < bits;
            prop_assert_eq!(set.insert(n), inside);
            if inside {
                model.insert(n);
            }
        }
        prop_assert_eq!(set.iter().collect::<BTreeSet<_>>(), model.clone());
        for d in 0..300u32 {
            let n = base.saturating_sub(5).saturating_add(d);
            prop_assert_eq!(set.contains(n), model.contains(&n));
        }
        prop_assert_eq!(FragmentNumberSet::from_words(set.base(), set.num_bits(), set.words()).unwrap(), set);
    }
}
