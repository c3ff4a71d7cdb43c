//! Hostile RTPS datagrams, the same for every test and seed corpus that sends them.

/// SPDP's builtin reader and writer, SEDP's publications reader and writer (entity ids).
const SPDP_READER: [u8; 4] = [0, 1, 0, 0xC7];
const SPDP_WRITER: [u8; 4] = [0, 1, 0, 0xC2];
const SEDP_PUBLICATIONS_READER: [u8; 4] = [0, 0, 3, 0xC7];
const SEDP_PUBLICATIONS_WRITER: [u8; 4] = [0, 0, 3, 0xC2];

/// For each of the six fields of a datagram that rustdds 0.15.1 trusted (robowire's DDS before
/// `rtps-proto`; `robowire/tests/dds_flood`), one datagram that sets it, as the participant of
/// GUID prefix `from` would send it to another (little-endian, counts past any seen), named by
/// the field: a DATA_FRAG announcing a 4 GiB sample; a HEARTBEAT of 2^40 samples; a GAP up to
/// 2^40; a NACK_FRAG whose fragment numbers pass 2^32; a NACK_FRAG of fragment 0; an ACKNACK
/// whose set passes `i64::MAX`.
pub fn hostile_datagrams(from: [u8; 12]) -> [(&'static str, Vec<u8>); 6] {
    let datagram = |kind: u8, body: Vec<u8>| {
        let mut d = b"RTPS\x02\x04\x01\x12".to_vec();
        d.extend(from);
        d.extend([kind, 0x01]);
        d.extend(u16::try_from(body.len()).unwrap_or(u16::MAX).to_le_bytes());
        d.extend(body);
        d
    };
    let sn = |sn: i64| [((sn >> 32) as i32).to_le_bytes(), (sn as u32).to_le_bytes()].concat();
    let count = i32::MAX.to_le_bytes();
    let (reader, writer) = (SEDP_PUBLICATIONS_READER, SEDP_PUBLICATIONS_WRITER);
    // Fragment 1 of 1024 bytes of a 4 GiB sample.
    let data_frag = [&[0, 0, 28, 0][..], &SPDP_READER, &SPDP_WRITER, &sn(1), &1u32.to_le_bytes()]
        .concat()
        .into_iter()
        .chain(1u16.to_le_bytes())
        .chain(1024u16.to_le_bytes())
        .chain(0xFFFF_FFF0u32.to_le_bytes())
        .chain([0; 1024])
        .collect();
    // Sequence numbers 1..=2^40 available; 1000..2^40 irrelevant; fragments up to 2^32 - 1 of
    // sample 1 missing; its fragment 0 missing; sample i64::MAX - 8 + 31 missing.
    let heartbeat = [&reader[..], &writer, &sn(1), &sn(1 << 40), &count].concat();
    let gap = [&reader[..], &writer, &sn(1000), &sn(1 << 40), &0u32.to_le_bytes()].concat();
    let words = [0xFFu8; 32];
    let nack_frag =
        [&reader[..], &writer, &sn(1), &0xFFFF_FF00u32.to_le_bytes(), &256u32.to_le_bytes(), &words, &count].concat();
    let fragment_0 =
        [&reader[..], &writer, &sn(1), &0u32.to_le_bytes(), &1u32.to_le_bytes(), &[0, 0, 0, 0x80], &count].concat();
    let acknack = [&reader[..], &writer, &sn(i64::MAX - 8), &32u32.to_le_bytes(), &1u32.to_le_bytes(), &count].concat();
    [
        ("DATA_FRAG sampleSize", datagram(0x16, data_frag)),
        ("HEARTBEAT range", datagram(0x07, heartbeat)),
        ("GAP range", datagram(0x08, gap)),
        ("NACK_FRAG fragment numbers", datagram(0x12, nack_frag)),
        ("NACK_FRAG fragment number 0", datagram(0x12, fragment_0)),
        ("sequence number overflow", datagram(0x06, acknack)),
    ]
}
