//! SPDP/SEDP discovery data: hand-built parameter lists in both byte orders, emit → parse round
//! trips, limits, must-understand, and the QoS Request/Offered match.

use proptest::prelude::*;
use rtps_proto::discovery::{
    BuiltinEndpointSet, DATA_REPRESENTATION_XCDR1, DATA_REPRESENTATION_XCDR2, DATA_REPRESENTATION_XML,
    DestinationOrder, DiscoveryError, Durability, EndpointData, History, Liveliness, LivelinessKind, Ownership,
    OwnershipKind, ParticipantData, Qos, QosMismatch, Reliability, ReliabilityKind, check_match,
};
use rtps_proto::types::DdsDuration;
use rtps_proto::wire::{Endianness, ParameterList};
use rtps_proto::{EntityId, Guid, GuidPrefix, Limits, Locator, ProtocolVersion, VendorId};

/// Builds a parameter list by hand in either byte order.
struct List {
    big: bool,
    bytes: Vec<u8>,
}

impl List {
    fn new(e: Endianness) -> Self {
        Self { big: e == Endianness::Big, bytes: Vec::new() }
    }

    fn u16(&self, v: u16) -> [u8; 2] {
        if self.big { v.to_be_bytes() } else { v.to_le_bytes() }
    }

    fn u32(&self, v: u32) -> [u8; 4] {
        if self.big { v.to_be_bytes() } else { v.to_le_bytes() }
    }

    fn param(&mut self, pid: u16, value: &[u8]) -> &mut Self {
        let padded = value.len().next_multiple_of(4);
        let (p, l) = (self.u16(pid), self.u16(padded as u16));
        self.bytes.extend_from_slice(&p);
        self.bytes.extend_from_slice(&l);
        self.bytes.extend_from_slice(value);
        self.bytes.resize(self.bytes.len() + padded - value.len(), 0);
        self
    }

    fn words(&self, words: &[u32]) -> Vec<u8> {
        words.iter().flat_map(|&w| self.u32(w)).collect()
    }

    fn string(&self, s: &str) -> Vec<u8> {
        let mut v = self.u32(s.len() as u32 + 1).to_vec();
        v.extend_from_slice(s.as_bytes());
        v.push(0);
        v
    }

    fn locator(&self, l: Locator) -> Vec<u8> {
        let mut v = self.words(&[l.kind as u32, l.port]);
        v.extend_from_slice(&l.address);
        v
    }

    fn finish(&mut self) -> Vec<u8> {
        let mut out = self.bytes.clone();
        out.extend_from_slice(&self.u16(0x0001));
        out.extend_from_slice(&[0, 0]);
        out
    }

    fn payload(&mut self) -> Vec<u8> {
        let mut out = if self.big { vec![0, 2, 0, 0] } else { vec![0, 3, 0, 0] };
        out.extend(self.finish());
        out
    }
}

const BOTH: [Endianness; 2] = [Endianness::Big, Endianness::Little];
const PREFIX: GuidPrefix = GuidPrefix([1, 0xf, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]);

fn udp(a: [u8; 4], port: u16) -> Locator {
    Locator::udpv4(std::net::SocketAddrV4::new(a.into(), port))
}

fn participant_guid_bytes() -> Vec<u8> {
    Guid::new(PREFIX, EntityId::PARTICIPANT).to_bytes().to_vec()
}

fn parse_spdp(bytes: &[u8], e: Endianness, limits: &Limits) -> Result<ParticipantData, DiscoveryError> {
    let (list, used) = ParameterList::parse(bytes, e).expect("a valid list");
    assert_eq!(used, bytes.len());
    ParticipantData::parse(&list, limits)
}

fn parse_sedp(bytes: &[u8], e: Endianness, key: Option<[u8; 16]>) -> Result<EndpointData, DiscoveryError> {
    let (list, _) = ParameterList::parse(bytes, e).expect("a valid list");
    EndpointData::parse(&list, key, &Limits::default())
}

#[test]
fn spdp_hand_built_in_both_byte_orders() {
    for e in BOTH {
        let mut l = List::new(e);
        let meta = udp([192, 168, 1, 10], 7410);
        let mcast = udp([239, 255, 0, 1], 7400);
        let user = udp([192, 168, 1, 10], 7411);
        let (g, loc_meta, loc_mcast, loc_user) =
            (participant_guid_bytes(), l.locator(meta), l.locator(mcast), l.locator(user));
        let (domain, set, lease, name) = (l.u32(7), l.u32(0x0c3f), l.words(&[20, 0x8000_0000]), l.string("robot/arm"));
        let mut user_data = l.u32(3).to_vec();
        user_data.extend_from_slice(b"abc");
        let count = l.u32(5);
        l.param(0x0015, &[2, 3])
            .param(0x0016, &[1, 0x10])
            .param(0x8007, &[1, 2, 3, 4]) // CycloneDDS's vendor-specific version info: skipped
            .param(0x0050, &g)
            .param(0x000f, &domain)
            .param(0x0058, &set)
            .param(0x0032, &loc_meta)
            .param(0x0033, &loc_mcast)
            .param(0x0031, &loc_user)
            .param(0x0002, &lease)
            .param(0x0062, &name)
            .param(0x002c, &user_data)
            .param(0x0034, &count)
            .param(0x0000, &[]) // PID_PAD
            .param(0x0077, &[0; 8]); // BUILTIN_ENDPOINT_QOS: known to RTPS, not kept here
        let d = parse_spdp(&l.finish(), e, &Limits::default()).unwrap();
        assert_eq!(d.guid_prefix, PREFIX);
        assert_eq!(d.protocol_version, ProtocolVersion { major: 2, minor: 3 });
        assert_eq!(d.vendor_id, VendorId::CYCLONEDDS);
        assert_eq!(d.domain_id, Some(7));
        assert_eq!(d.domain_tag, "");
        assert!(d.builtin_endpoints.contains(BuiltinEndpointSet::PARTICIPANT_ANNOUNCER));
        assert!(d.builtin_endpoints.contains(BuiltinEndpointSet::PARTICIPANT_MESSAGE_DATA_READER));
        assert!(!d.builtin_endpoints.contains(BuiltinEndpointSet::TOPICS_ANNOUNCER));
        assert_eq!(d.metatraffic_unicast_locators, [meta]);
        assert_eq!(d.metatraffic_multicast_locators, [mcast]);
        assert_eq!(d.default_unicast_locators, [user]);
        assert!(d.default_multicast_locators.is_empty());
        assert_eq!(d.lease_duration.to_duration(), Some(std::time::Duration::from_millis(20_500)));
        assert_eq!(d.entity_name.as_deref(), Some("robot/arm"));
        assert_eq!(d.user_data, b"abc");
        assert_eq!(d.manual_liveliness_count, 5);
        assert!(!d.expects_inline_qos);
        assert_eq!(d.unknown_parameters, 2, "the vendor PID and BUILTIN_ENDPOINT_QOS");
        assert_eq!(d.dropped_locators, 0);
    }
}

#[test]
fn spdp_defaults_and_missing_guid() {
    for e in BOTH {
        let mut l = List::new(e);
        l.param(0x0050, &participant_guid_bytes());
        let d = parse_spdp(&l.finish(), e, &Limits::default()).unwrap();
        assert_eq!(d.lease_duration, DdsDuration { seconds: 100, fraction: 0 });
        assert_eq!(d.domain_id, None);
        assert_eq!(d.vendor_id, VendorId::UNKNOWN);

        let mut l = List::new(e);
        let domain = l.u32(0);
        l.param(0x000f, &domain);
        assert_eq!(parse_spdp(&l.finish(), e, &Limits::default()), Err(DiscoveryError::MissingGuid));
    }
}

/// A SEDP reader: QoS in the list's byte order, OWNERSHIP_STRENGTH before OWNERSHIP.
#[test]
fn sedp_hand_built_in_both_byte_orders() {
    let reader = Guid::new(PREFIX, EntityId::user(0x12, EntityId::KIND_READER_NO_KEY));
    for e in BOTH {
        let mut l = List::new(e);
        let (topic, ty) = (l.string("rt/chatter"), l.string("std_msgs::msg::dds_::String_"));
        let reliability = l.words(&[2, 0, 0x4000_0000]);
        let durability = l.u32(1);
        let history = l.words(&[0, 10]);
        let deadline = l.words(&[1, 0]);
        let liveliness = l.words(&[1, 3, 0]);
        let (strength, ownership, order) = (l.u32(5), l.u32(1), l.u32(1));
        let mut partition = l.u32(2).to_vec();
        partition.extend(l.string("a")); // 6 bytes, then 2 of padding before the next string
        partition.extend([0, 0]);
        partition.extend(l.string("b*"));
        let mut repr = l.u32(2).to_vec();
        repr.extend(if e == Endianness::Big { [0, 2, 0, 0] } else { [2, 0, 0, 0] });
        let loc = l.locator(udp([10, 0, 0, 2], 7411));
        let max_size = l.u32(1024);
        l.param(0x005a, &reader.to_bytes())
            .param(0x0050, &Guid::new(PREFIX, EntityId::PARTICIPANT).to_bytes())
            .param(0x0005, &topic)
            .param(0x0007, &ty)
            .param(0x001a, &reliability)
            .param(0x001d, &durability)
            .param(0x0040, &history)
            .param(0x0023, &deadline)
            .param(0x001b, &liveliness)
            .param(0x0006, &strength)
            .param(0x001f, &ownership)
            .param(0x0025, &order)
            .param(0x0029, &partition)
            .param(0x0073, &repr)
            .param(0x002f, &loc)
            .param(0x0043, &[1])
            .param(0x0075, &[9, 9, 9, 9, 8, 8, 8, 8])
            .param(0x0060, &max_size)
            .param(0x0021, &[0; 8]); // PRESENTATION: skipped, counted
        let d = parse_sedp(&l.finish(), e, None).unwrap();
        assert_eq!(d.guid, reader);
        assert_eq!(d.participant_guid, Some(Guid::new(PREFIX, EntityId::PARTICIPANT)));
        assert_eq!(d.topic_name, "rt/chatter");
        assert_eq!(d.type_name, "std_msgs::msg::dds_::String_");
        let q = &d.qos;
        assert_eq!(
            q.reliability,
            Reliability::Reliable { max_blocking_time: DdsDuration { seconds: 0, fraction: 1 << 30 } }
        );
        assert_eq!(q.durability, Durability::TransientLocal);
        assert_eq!(q.history, History::KeepLast { depth: 10 });
        assert_eq!(q.deadline_period, DdsDuration { seconds: 1, fraction: 0 });
        assert_eq!(
            q.liveliness,
            Liveliness {
                kind: LivelinessKind::ManualByParticipant,
                lease_duration: DdsDuration { seconds: 3, fraction: 0 }
            }
        );
        assert_eq!(q.ownership, Ownership::Exclusive { strength: 5 });
        assert_eq!(q.destination_order, DestinationOrder::BySourceTimestamp);
        assert_eq!(q.partitions, ["a", "b*"]);
        assert_eq!(q.data_representation, [DATA_REPRESENTATION_XCDR2, DATA_REPRESENTATION_XCDR1]);
        assert_eq!(q.latency_budget, DdsDuration::ZERO, "absent: the default");
        assert_eq!(d.unicast_locators, [udp([10, 0, 0, 2], 7411)]);
        assert!(d.expects_inline_qos);
        assert_eq!(d.type_information.as_deref(), Some(&[9, 9, 9, 9, 8, 8, 8, 8][..]));
        assert_eq!(d.type_max_serialized_size, Some(1024));
        assert_eq!(d.unknown_parameters, 1);
    }
}

#[test]
fn sedp_defaults_by_kind_and_key_hash() {
    let writer = Guid::new(PREFIX, EntityId::user(3, EntityId::KIND_WRITER_WITH_KEY));
    let reader = Guid::new(PREFIX, EntityId::user(3, EntityId::KIND_READER_WITH_KEY));
    for e in BOTH {
        let mut l = List::new(e);
        let (topic, ty) = (l.string("t"), l.string("T"));
        l.param(0x0005, &topic).param(0x0007, &ty);
        let bytes = l.finish();
        // No ENDPOINT_GUID: the key hash names the endpoint; absent QoS takes its kind's default.
        let w = parse_sedp(&bytes, e, Some(writer.to_bytes())).unwrap();
        assert_eq!(w.guid, writer);
        assert_eq!(w.qos, Qos::default());
        assert!(matches!(w.qos.reliability, Reliability::Reliable { .. }));
        let r = parse_sedp(&bytes, e, Some(reader.to_bytes())).unwrap();
        assert_eq!(r.qos, Qos::reader_default());
        assert_eq!(r.qos.reliability, Reliability::BestEffort);
        assert_eq!(parse_sedp(&bytes, e, None), Err(DiscoveryError::MissingGuid));

        let mut l = List::new(e);
        let ty = l.string("T");
        l.param(0x005a, &writer.to_bytes()).param(0x0007, &ty);
        assert_eq!(parse_sedp(&l.finish(), e, None), Err(DiscoveryError::Missing { pid: 0x0005 }));
    }
}

#[test]
fn must_understand_refuses_and_vendor_specific_is_skipped() {
    for e in BOTH {
        let mut l = List::new(e);
        l.param(0x0050, &participant_guid_bytes()).param(0x4077, &[0; 4]);
        assert_eq!(parse_spdp(&l.finish(), e, &Limits::default()), Err(DiscoveryError::MustUnderstand { pid: 0x4077 }));

        let mut l = List::new(e);
        l.param(0x0050, &participant_guid_bytes()).param(0xc001, &[0; 4]).param(0x8001, &[0; 4]);
        assert_eq!(parse_spdp(&l.finish(), e, &Limits::default()).unwrap().unknown_parameters, 2);

        // PID_DOMAIN_TAG carries the bit and is understood.
        let mut l = List::new(e);
        let tag = l.string("lab");
        l.param(0x0050, &participant_guid_bytes()).param(0x4014, &tag);
        assert_eq!(parse_spdp(&l.finish(), e, &Limits::default()).unwrap().domain_tag, "lab");

        let w = Guid::new(PREFIX, EntityId::user(1, EntityId::KIND_WRITER_NO_KEY));
        let mut l = List::new(e);
        let (topic, ty) = (l.string("t"), l.string("T"));
        l.param(0x005a, &w.to_bytes()).param(0x0005, &topic).param(0x0007, &ty).param(0x4100, &[]);
        assert_eq!(parse_sedp(&l.finish(), e, None), Err(DiscoveryError::MustUnderstand { pid: 0x4100 }));
    }
}

#[test]
fn locator_flood_is_bounded_and_counted() {
    let mut limits = Limits::default();
    limits.locators_per_endpoint = 16;
    for e in BOTH {
        let mut l = List::new(e);
        l.param(0x0050, &participant_guid_bytes());
        for i in 0..1000u16 {
            let loc = l.locator(udp([10, 0, (i >> 8) as u8, i as u8], 7400 + i));
            l.param(if i % 2 == 0 { 0x0032 } else { 0x0031 }, &loc);
        }
        let d = parse_spdp(&l.finish(), e, &limits).unwrap();
        let kept = d.metatraffic_unicast_locators.len() + d.default_unicast_locators.len();
        assert_eq!(kept, 16);
        assert_eq!(d.dropped_locators, 1000 - 16);
        assert_eq!(d.metatraffic_unicast_locators[0], udp([10, 0, 0, 0], 7400), "the first ones are kept");

        let w = Guid::new(PREFIX, EntityId::user(1, EntityId::KIND_WRITER_NO_KEY));
        let mut l = List::new(e);
        let (topic, ty) = (l.string("t"), l.string("T"));
        l.param(0x005a, &w.to_bytes()).param(0x0005, &topic).param(0x0007, &ty);
        for i in 0..1000u16 {
            let loc = l.locator(udp([239, 0, 0, 1], i));
            l.param(0x0030, &loc);
        }
        let d = parse_sedp(&l.finish(), e, None).unwrap();
        assert_eq!(d.multicast_locators.len(), Limits::default().locators_per_endpoint);
        assert_eq!(d.dropped_locators as usize, 1000 - Limits::default().locators_per_endpoint);
    }
}

/// Lengths read from the wire are checked before anything is allocated: a 4 GiB string or
/// sequence is refused (an attempt to allocate it would abort the test binary).
#[test]
fn huge_lengths_are_refused_before_allocating() {
    for e in BOTH {
        let mut small = Limits::default();
        small.parameter_bytes = 8;
        let mut l = List::new(e);
        let mut huge = l.u32(u32::MAX).to_vec();
        huge.extend_from_slice(b"abc\0");
        l.param(0x0050, &participant_guid_bytes()).param(0x0062, &huge);
        assert_eq!(
            parse_spdp(&l.finish(), e, &Limits::default()),
            Err(DiscoveryError::StringLength { pid: 0x0062, length: u32::MAX })
        );

        // Fits the value, exceeds the limit.
        let mut l = List::new(e);
        let long = l.string("0123456789");
        l.param(0x0050, &participant_guid_bytes()).param(0x0062, &long);
        assert_eq!(
            parse_spdp(&l.finish(), e, &small),
            Err(DiscoveryError::TooLong { pid: 0x0062, length: 11, limit: 8 })
        );

        // A string without its NUL, a non-UTF-8 one.
        let mut l = List::new(e);
        let mut no_nul = l.u32(4).to_vec();
        no_nul.extend_from_slice(b"abcd");
        l.param(0x0050, &participant_guid_bytes()).param(0x0062, &no_nul);
        assert_eq!(
            parse_spdp(&l.finish(), e, &Limits::default()),
            Err(DiscoveryError::StringLength { pid: 0x0062, length: 4 })
        );
        let mut l = List::new(e);
        let mut bad = l.u32(3).to_vec();
        bad.extend_from_slice(&[0xff, 0xfe, 0]);
        l.param(0x0050, &participant_guid_bytes()).param(0x0062, &bad);
        assert_eq!(parse_spdp(&l.finish(), e, &Limits::default()), Err(DiscoveryError::NotUtf8 { pid: 0x0062 }));

        // USER_DATA of 4 GiB, PARTITION of 4 G strings.
        let mut l = List::new(e);
        let mut octets = l.u32(u32::MAX).to_vec();
        octets.extend_from_slice(&[1, 2, 3, 4]);
        l.param(0x0050, &participant_guid_bytes()).param(0x002c, &octets);
        assert!(matches!(
            parse_spdp(&l.finish(), e, &Limits::default()),
            Err(DiscoveryError::ValueLength { pid: 0x002c, .. })
        ));
        let w = Guid::new(PREFIX, EntityId::user(1, EntityId::KIND_WRITER_NO_KEY));
        let mut l = List::new(e);
        let (topic, ty, count) = (l.string("t"), l.string("T"), l.u32(u32::MAX));
        l.param(0x005a, &w.to_bytes()).param(0x0005, &topic).param(0x0007, &ty).param(0x0029, &count);
        assert!(matches!(parse_sedp(&l.finish(), e, None), Err(DiscoveryError::ValueLength { pid: 0x0029, .. })));

        // A value too short for its type.
        let mut l = List::new(e);
        l.param(0x0050, &participant_guid_bytes()).param(0x0032, &[0; 8]);
        assert_eq!(
            parse_spdp(&l.finish(), e, &Limits::default()),
            Err(DiscoveryError::ValueLength { pid: 0x0032, expected: 24, found: 8 })
        );
        // An out-of-range kind.
        let mut l = List::new(e);
        let (topic, ty, kind) = (l.string("t"), l.string("T"), l.words(&[3, 0, 0]));
        l.param(0x005a, &w.to_bytes()).param(0x0005, &topic).param(0x0007, &ty).param(0x001a, &kind);
        assert_eq!(parse_sedp(&l.finish(), e, None), Err(DiscoveryError::InvalidValue { pid: 0x001a }));
    }
}

#[test]
fn payload_encapsulation() {
    let mut l = List::new(Endianness::Big);
    l.param(0x0050, &participant_guid_bytes());
    let be = l.payload();
    assert_eq!(ParticipantData::parse_payload(&be, &Limits::default()).unwrap().guid_prefix, PREFIX);
    let mut l = List::new(Endianness::Little);
    l.param(0x0050, &participant_guid_bytes());
    let le = l.payload();
    assert_eq!(ParticipantData::parse_payload(&le, &Limits::default()).unwrap().guid_prefix, PREFIX);

    let mut cdr = le.clone();
    cdr[1] = 0x01; // CDR_LE: not a parameter list
    assert_eq!(ParticipantData::parse_payload(&cdr, &Limits::default()), Err(DiscoveryError::Encapsulation([0, 1])));
    assert_eq!(
        ParticipantData::parse_payload(&le[..3], &Limits::default()),
        Err(DiscoveryError::ShortPayload { length: 3 })
    );
    assert!(matches!(
        ParticipantData::parse_payload(&le[..le.len() - 4], &Limits::default()),
        Err(DiscoveryError::Wire(_))
    ));
    let mut tiny = Limits::default();
    tiny.parameter_list_bytes = 16;
    assert_eq!(
        ParticipantData::parse_payload(&le, &tiny),
        Err(DiscoveryError::ListTooLong { length: le.len() - 4, limit: 16 })
    );
}

fn robowire_participant() -> ParticipantData {
    let mut d = ParticipantData::new(PREFIX);
    d.domain_id = Some(0);
    d.metatraffic_unicast_locators.push(udp([192, 168, 123, 99], 7410));
    d.metatraffic_multicast_locators.push(udp([239, 255, 0, 1], 7400));
    d.default_unicast_locators.push(udp([192, 168, 123, 99], 7411));
    d.entity_name = Some("robowire".into());
    d
}

#[test]
fn emitted_payload_is_pl_cdr_le_with_standard_pids_and_a_sentinel() {
    let d = robowire_participant();
    let mut buf = [0u8; 1024];
    let n = d.emit_payload(&mut buf).unwrap();
    assert_eq!(&buf[..4], &[0, 3, 0, 0]);
    assert_eq!(&buf[n - 4..n], &[1, 0, 0, 0]);
    let (list, used) = ParameterList::parse(&buf[4..n], Endianness::Little).unwrap();
    assert_eq!(used, n - 4);
    assert!(list.iter().all(|p| p.pid & 0x8000 == 0 && p.value.len() % 4 == 0));
    assert_eq!(ParticipantData::parse_payload(&buf[..n], &Limits::default()).unwrap(), d);

    // Every shorter buffer is refused, never a panic.
    for short in 0..n {
        assert!(d.emit_payload(&mut buf[..short]).is_err(), "{short} bytes");
    }

    let mut e = EndpointData::new(
        Guid::new(PREFIX, EntityId::user(1, EntityId::KIND_WRITER_NO_KEY)),
        "rt/lowcmd".into(),
        "unitree_go::msg::dds_::LowCmd_".into(),
    );
    e.qos.partitions = vec!["x".into()];
    let n = e.emit_payload(&mut buf).unwrap();
    let (list, _) = ParameterList::parse(&buf[4..n], Endianness::Little).unwrap();
    assert!(list.iter().all(|p| p.pid & 0x8000 == 0 && p.pid & 0x4000 == 0));
    for short in 0..n {
        assert!(e.emit_payload(&mut buf[..short]).is_err(), "{short} bytes");
    }
}

fn qos_with(f: impl FnOnce(&mut Qos)) -> Qos {
    let mut q = Qos::default();
    f(&mut q);
    q
}

fn secs(s: i32) -> DdsDuration {
    DdsDuration { seconds: s, fraction: 0 }
}

#[test]
fn qos_match_table() {
    use QosMismatch as M;
    let be = |q: &mut Qos| q.reliability = Reliability::BestEffort;
    let rel = |q: &mut Qos| q.reliability = Reliability::Reliable { max_blocking_time: secs(5) };
    let parts = |p: &[&str]| {
        let p: Vec<String> = p.iter().map(|s| s.to_string()).collect();
        qos_with(move |q| q.partitions = p)
    };
    let repr = |r: &[i16]| {
        let r = r.to_vec();
        qos_with(move |q| q.data_representation = r)
    };
    let table: Vec<(&str, Qos, Qos, Result<(), QosMismatch>)> = vec![
        ("defaults", Qos::default(), Qos::reader_default(), Ok(())),
        ("reliable to reliable", Qos::default(), qos_with(rel), Ok(())),
        ("best effort to best effort", qos_with(be), qos_with(be), Ok(())),
        (
            "best effort to reliable",
            qos_with(be),
            qos_with(rel),
            Err(M::Reliability { offered: ReliabilityKind::BestEffort, requested: ReliabilityKind::Reliable }),
        ),
        (
            "transient local to volatile",
            qos_with(|q| q.durability = Durability::TransientLocal),
            Qos::default(),
            Ok(()),
        ),
        (
            "persistent to transient",
            qos_with(|q| q.durability = Durability::Persistent),
            qos_with(|q| q.durability = Durability::Transient),
            Ok(()),
        ),
        (
            "volatile to transient local",
            Qos::default(),
            qos_with(|q| q.durability = Durability::TransientLocal),
            Err(M::Durability { offered: Durability::Volatile, requested: Durability::TransientLocal }),
        ),
        (
            "transient local to transient",
            qos_with(|q| q.durability = Durability::TransientLocal),
            qos_with(|q| q.durability = Durability::Transient),
            Err(M::Durability { offered: Durability::TransientLocal, requested: Durability::Transient }),
        ),
        (
            "deadline 1 s to 2 s",
            qos_with(|q| q.deadline_period = secs(1)),
            qos_with(|q| q.deadline_period = secs(2)),
            Ok(()),
        ),
        (
            "deadline equal",
            qos_with(|q| q.deadline_period = secs(2)),
            qos_with(|q| q.deadline_period = secs(2)),
            Ok(()),
        ),
        (
            "deadline 2 s to 1 s",
            qos_with(|q| q.deadline_period = secs(2)),
            qos_with(|q| q.deadline_period = secs(1)),
            Err(M::Deadline { offered: secs(2), requested: secs(1) }),
        ),
        (
            "deadline infinite to 1 s",
            Qos::default(),
            qos_with(|q| q.deadline_period = secs(1)),
            Err(M::Deadline { offered: DdsDuration::INFINITE, requested: secs(1) }),
        ),
        ("latency budget 0 to 1 s", Qos::default(), qos_with(|q| q.latency_budget = secs(1)), Ok(())),
        (
            "latency budget 1 s to 0",
            qos_with(|q| q.latency_budget = secs(1)),
            Qos::default(),
            Err(M::LatencyBudget { offered: secs(1), requested: DdsDuration::ZERO }),
        ),
        (
            "liveliness manual by topic to automatic",
            qos_with(|q| q.liveliness.kind = LivelinessKind::ManualByTopic),
            Qos::default(),
            Ok(()),
        ),
        (
            "liveliness automatic to manual by participant",
            Qos::default(),
            qos_with(|q| q.liveliness.kind = LivelinessKind::ManualByParticipant),
            Err(M::LivelinessKind {
                offered: LivelinessKind::Automatic,
                requested: LivelinessKind::ManualByParticipant,
            }),
        ),
        (
            "liveliness lease 1 s to 2 s",
            qos_with(|q| q.liveliness.lease_duration = secs(1)),
            qos_with(|q| q.liveliness.lease_duration = secs(2)),
            Ok(()),
        ),
        (
            "liveliness lease infinite to 2 s",
            Qos::default(),
            qos_with(|q| q.liveliness.lease_duration = secs(2)),
            Err(M::LivelinessLease { offered: DdsDuration::INFINITE, requested: secs(2) }),
        ),
        (
            "ownership exclusive to exclusive",
            qos_with(|q| q.ownership = Ownership::Exclusive { strength: 3 }),
            qos_with(|q| q.ownership = Ownership::Exclusive { strength: 0 }),
            Ok(()),
        ),
        (
            "ownership exclusive to shared",
            qos_with(|q| q.ownership = Ownership::Exclusive { strength: 3 }),
            Qos::default(),
            Err(M::Ownership { offered: OwnershipKind::Exclusive, requested: OwnershipKind::Shared }),
        ),
        (
            "ownership shared to exclusive",
            Qos::default(),
            qos_with(|q| q.ownership = Ownership::Exclusive { strength: 3 }),
            Err(M::Ownership { offered: OwnershipKind::Shared, requested: OwnershipKind::Exclusive }),
        ),
        (
            "destination order by source to by reception",
            qos_with(|q| q.destination_order = DestinationOrder::BySourceTimestamp),
            Qos::default(),
            Ok(()),
        ),
        (
            "destination order by reception to by source",
            Qos::default(),
            qos_with(|q| q.destination_order = DestinationOrder::BySourceTimestamp),
            Err(M::DestinationOrder {
                offered: DestinationOrder::ByReceptionTimestamp,
                requested: DestinationOrder::BySourceTimestamp,
            }),
        ),
        ("partition default to \"\"", Qos::default(), parts(&[""]), Ok(())),
        ("partition default to a", Qos::default(), parts(&["a"]), Err(M::Partition)),
        ("partition a,b to b", parts(&["a", "b"]), parts(&["b"]), Ok(())),
        ("partition a to b", parts(&["a"]), parts(&["b"]), Err(M::Partition)),
        ("partition rt* to rt/x", parts(&["rt*"]), parts(&["rt/x"]), Ok(())),
        ("partition rt/x to r?/*", parts(&["rt/x"]), parts(&["r?/*"]), Ok(())),
        ("partition * to default", parts(&["*"]), Qos::default(), Ok(())),
        ("partition a?c to abcd", parts(&["a?c"]), parts(&["abcd"]), Err(M::Partition)),
        ("partition a* to b*", parts(&["a*"]), parts(&["b*"]), Err(M::Partition)),
        ("partition a* to a*", parts(&["a*"]), parts(&["a*"]), Ok(())),
        ("partition *x*y to axxbxy", parts(&["*x*y"]), parts(&["axxbxy"]), Ok(())),
        ("representation none to none", Qos::default(), Qos::reader_default(), Ok(())),
        ("representation XCDR2 to XCDR1,XCDR2", repr(&[2]), repr(&[0, 2]), Ok(())),
        ("representation XCDR1 first to none", repr(&[0, 2]), Qos::default(), Ok(())),
        (
            "representation XCDR2 to none",
            repr(&[DATA_REPRESENTATION_XCDR2]),
            Qos::default(),
            Err(M::DataRepresentation { offered: DATA_REPRESENTATION_XCDR2 }),
        ),
        (
            "representation none to XCDR2",
            Qos::default(),
            repr(&[DATA_REPRESENTATION_XCDR2]),
            Err(M::DataRepresentation { offered: DATA_REPRESENTATION_XCDR1 }),
        ),
        (
            "representation XML to XCDR1,XCDR2",
            repr(&[DATA_REPRESENTATION_XML]),
            repr(&[0, 2]),
            Err(M::DataRepresentation { offered: DATA_REPRESENTATION_XML }),
        ),
    ];
    for (name, writer, reader, expected) in table {
        assert_eq!(check_match(&writer, &reader), expected, "{name}");
    }
}

#[test]
fn qos_mismatch_says_what_differs() {
    let reliable = Qos::default();
    let best_effort = Qos::reader_default();
    let m = check_match(&best_effort, &reliable).unwrap_err();
    assert_eq!(m.to_string(), "reliability: the writer offers best effort, the reader requests reliable");
    let m = QosMismatch::Deadline {
        offered: DdsDuration::INFINITE,
        requested: DdsDuration::from_duration(std::time::Duration::from_millis(1500)),
    };
    assert_eq!(m.to_string(), "deadline: the writer offers a period of infinite, the reader requests 1.5s");
    assert_eq!(
        QosMismatch::Durability { offered: Durability::Volatile, requested: Durability::TransientLocal }.to_string(),
        "durability: the writer offers volatile, the reader requests transient local"
    );
}

#[test]
fn qos_defaults_are_the_dds_defaults() {
    let w = Qos::default();
    assert_eq!(
        w.reliability,
        Reliability::Reliable { max_blocking_time: DdsDuration::from_duration(std::time::Duration::from_millis(100)) }
    );
    assert_eq!(w.durability, Durability::Volatile);
    assert_eq!(w.history, History::KeepLast { depth: 1 });
    assert_eq!(w.deadline_period, DdsDuration::INFINITE);
    assert_eq!(w.liveliness, Liveliness { kind: LivelinessKind::Automatic, lease_duration: DdsDuration::INFINITE });
    assert_eq!(Qos::reader_default(), Qos { reliability: Reliability::BestEffort, ..w });
}

// ---- round trips ---------------------------------------------------------------------------

fn duration() -> impl Strategy<Value = DdsDuration> {
    (any::<i32>(), any::<u32>()).prop_map(|(seconds, fraction)| DdsDuration { seconds, fraction })
}

fn text() -> impl Strategy<Value = String> {
    "[^\\x00]{0,12}"
}

fn locators(max: usize) -> impl Strategy<Value = Vec<Locator>> {
    prop::collection::vec(
        (any::<i32>(), any::<u32>(), any::<[u8; 16]>()).prop_map(|(kind, port, address)| Locator {
            kind,
            port,
            address,
        }),
        0..=max,
    )
}

fn octets() -> impl Strategy<Value = Vec<u8>> {
    prop::collection::vec(any::<u8>(), 0..12)
}

fn qos() -> impl Strategy<Value = Qos> {
    let reliability = prop_oneof![
        Just(Reliability::BestEffort),
        duration().prop_map(|d| Reliability::Reliable { max_blocking_time: d })
    ];
    let durability = prop::sample::select(vec![
        Durability::Volatile,
        Durability::TransientLocal,
        Durability::Transient,
        Durability::Persistent,
    ]);
    let history =
        prop_oneof![Just(History::KeepAll), (1..=i32::MAX as u32).prop_map(|depth| History::KeepLast { depth })];
    let liveliness = (
        prop::sample::select(vec![
            LivelinessKind::Automatic,
            LivelinessKind::ManualByParticipant,
            LivelinessKind::ManualByTopic,
        ]),
        duration(),
    )
        .prop_map(|(kind, lease_duration)| Liveliness { kind, lease_duration });
    let ownership =
        prop_oneof![Just(Ownership::Shared), any::<i32>().prop_map(|strength| Ownership::Exclusive { strength })];
    let order = prop::sample::select(vec![DestinationOrder::ByReceptionTimestamp, DestinationOrder::BySourceTimestamp]);
    (
        (reliability, durability, history, duration(), duration(), liveliness, ownership, order, duration()),
        (prop::collection::vec(text(), 0..4), prop::collection::vec(any::<i16>(), 0..4), octets(), octets(), octets()),
    )
        .prop_map(
            |(
                (
                    reliability,
                    durability,
                    history,
                    deadline_period,
                    latency_budget,
                    liveliness,
                    ownership,
                    order,
                    lifespan,
                ),
                (partitions, data_representation, user_data, topic_data, group_data),
            )| Qos {
                reliability,
                durability,
                history,
                deadline_period,
                latency_budget,
                liveliness,
                ownership,
                destination_order: order,
                lifespan,
                partitions,
                data_representation,
                user_data,
                topic_data,
                group_data,
            },
        )
}

fn participant() -> impl Strategy<Value = ParticipantData> {
    (
        (
            any::<[u8; 12]>(),
            any::<(u8, u8)>(),
            any::<[u8; 2]>(),
            any::<Option<u32>>(),
            text(),
            any::<u32>(),
            any::<bool>(),
        ),
        (locators(4), locators(4), locators(4), locators(4)),
        (duration(), octets(), prop::option::of(text()), any::<i32>()),
    )
        .prop_map(
            |(
                (prefix, (major, minor), vendor, domain_id, domain_tag, set, inline),
                (mu, mm, du, dm),
                (lease, user, name, count),
            )| {
                let mut d = ParticipantData::new(GuidPrefix(prefix));
                d.protocol_version = ProtocolVersion { major, minor };
                d.vendor_id = VendorId(vendor);
                d.domain_id = domain_id;
                d.domain_tag = domain_tag;
                d.builtin_endpoints = BuiltinEndpointSet(set);
                d.expects_inline_qos = inline;
                d.metatraffic_unicast_locators = mu;
                d.metatraffic_multicast_locators = mm;
                d.default_unicast_locators = du;
                d.default_multicast_locators = dm;
                d.lease_duration = lease;
                d.user_data = user;
                d.entity_name = name;
                d.manual_liveliness_count = count;
                d
            },
        )
}

fn endpoint() -> impl Strategy<Value = EndpointData> {
    (
        (any::<[u8; 12]>(), any::<[u8; 4]>(), prop::option::of(any::<[u8; 16]>()), text(), text(), qos()),
        (
            locators(8),
            locators(8),
            any::<bool>(),
            prop::option::of(prop::collection::vec(any::<[u8; 4]>(), 0..6).prop_map(|v| v.concat())),
            any::<Option<u32>>(),
            prop::option::of(text()),
        ),
    )
        .prop_map(|((prefix, entity, participant, topic, ty, qos), (uni, multi, inline, info, max, name))| {
            let mut d = EndpointData::new(Guid::new(GuidPrefix(prefix), EntityId(entity)), topic, ty);
            d.participant_guid = participant.map(Guid::from_bytes);
            d.qos = qos;
            d.unicast_locators = uni;
            d.multicast_locators = multi;
            d.expects_inline_qos = inline;
            d.type_information = info;
            d.type_max_serialized_size = max;
            d.entity_name = name;
            d
        })
}

proptest! {
    #[test]
    fn participant_round_trip(d in participant()) {
        let mut buf = vec![0u8; 8192];
        let n = d.emit_payload(&mut buf).unwrap();
        let back = ParticipantData::parse_payload(&buf[..n], &Limits::default()).unwrap();
        prop_assert_eq!(back, d);
    }

    #[test]
    fn endpoint_round_trip(d in endpoint()) {
        let mut buf = vec![0u8; 8192];
        let n = d.emit_payload(&mut buf).unwrap();
        let (list, _) = ParameterList::parse(&buf[4..n], Endianness::Little).unwrap();
        prop_assert!(list.iter().all(|p| p.pid & 0x8000 == 0));
        let back = EndpointData::parse_payload(&buf[..n], None, &Limits::default()).unwrap();
        prop_assert_eq!(back, d);
    }

    /// Any bytes: a refusal or data, never a panic.
    #[test]
    fn arbitrary_payloads_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512), key in any::<Option<[u8; 16]>>()) {
        let _ = ParticipantData::parse_payload(&bytes, &Limits::default());
        let _ = EndpointData::parse_payload(&bytes, key, &Limits::default());
    }

    /// Emitted data with bytes flipped: a refusal or data, never a panic.
    #[test]
    fn mutated_payloads_never_panic(d in endpoint(), flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let mut buf = vec![0u8; 8192];
        let n = d.emit_payload(&mut buf).unwrap();
        for (i, b) in flips {
            buf[i.index(n)] = b;
        }
        let _ = EndpointData::parse_payload(&buf[..n], None, &Limits::default());
        let _ = ParticipantData::parse_payload(&buf[..n], &Limits::default());
    }
}

// ---- golden datagrams --------------------------------------------------------------------------

/// Discovery DATA payloads from the golden captures (`fixtures/rtps/*.hex`, or the directory in
/// `ROBOWIRE_RTPS_FIXTURES`): every SPDP and SEDP DATA with a payload parses. The RTPS header and
/// submessages are walked by hand here, independent of the wire module's iterator.
#[test]
fn golden_discovery_payloads_parse() {
    let dir = std::env::var_os("ROBOWIRE_RTPS_FIXTURES")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/rtps"));
    let entries =
        std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("the golden RTPS captures at {}: {e}", dir.display()));
    let mut files: Vec<_> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
    files.retain(|p| p.extension().is_some_and(|x| x == "hex"));
    files.sort();
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let (mut spdp, mut sedp) = (0, 0);
        for (n, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let bytes: Vec<u8> =
                (0..line.len()).step_by(2).map(|i| u8::from_str_radix(&line[i..i + 2], 16).unwrap()).collect();
            let at = format!("{}:{}", path.display(), n + 1);
            for (writer, payload, key) in discovery_data(&bytes) {
                match writer {
                    [0, 1, 0, 0xc2] => {
                        let d = ParticipantData::parse_payload(payload, &Limits::default())
                            .unwrap_or_else(|e| panic!("{at}: SPDP: {e}"));
                        assert_eq!(&d.guid_prefix.0[..], &bytes[8..20], "{at}");
                        spdp += 1;
                    }
                    [0, 0, 3, 0xc2] | [0, 0, 4, 0xc2] => {
                        let d = EndpointData::parse_payload(payload, key, &Limits::default())
                            .unwrap_or_else(|e| panic!("{at}: SEDP: {e}"));
                        assert_eq!(d.guid.entity.is_reader(), writer[2] == 4, "{at}: {:?}", d.guid);
                        assert!(!d.topic_name.is_empty(), "{at}");
                        sedp += 1;
                    }
                    _ => {}
                }
            }
        }
        eprintln!("{}: {spdp} SPDP and {sedp} SEDP payloads parsed", path.display());
        assert!(spdp > 0, "{}: no SPDP DATA", path.display());
    }
}

/// A DATA with a payload: writer entity id, serialized payload, inline key hash.
type DataPayload<'a> = ([u8; 4], &'a [u8], Option<[u8; 16]>);

/// Each DATA with a payload in the datagram.
fn discovery_data(msg: &[u8]) -> Vec<DataPayload<'_>> {
    let mut out = Vec::new();
    if msg.len() < 20 || &msg[..4] != b"RTPS" {
        return out;
    }
    let mut pos = 20;
    while pos + 4 <= msg.len() {
        let (id, flags) = (msg[pos], msg[pos + 1]);
        let little = flags & 1 != 0;
        let u16_at =
            |b: &[u8]| if little { u16::from_le_bytes([b[0], b[1]]) } else { u16::from_be_bytes([b[0], b[1]]) };
        let len = usize::from(u16_at(&msg[pos + 2..]));
        let body_start = pos + 4;
        let body_end = if len == 0 { msg.len() } else { (body_start + len).min(msg.len()) };
        let body = &msg[body_start..body_end];
        // DATA with the D flag: extraFlags, octetsToInlineQos, readerId, writerId, writerSN.
        if id == 0x15 && flags & 0x04 != 0 && body.len() >= 20 {
            let writer = [body[8], body[9], body[10], body[11]];
            let mut at = 4 + usize::from(u16_at(&body[2..]));
            let mut key = None;
            if flags & 0x02 != 0 {
                let e = if little { Endianness::Little } else { Endianness::Big };
                let (qos, used) = ParameterList::parse(&body[at..], e).expect("inline QoS");
                key = qos.find(0x0070).map(|p| p.value.try_into().expect("a 16-byte key hash"));
                at += used;
            }
            out.push((writer, &body[at..], key));
        }
        pos = body_end;
    }
    out
}
