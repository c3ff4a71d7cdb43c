//! An RTPS datagram as JSON: its header and every submessage's fields, from `rtps_proto::wire`'s
//! checked views. The first refusal ends the datagram (no partial JSON); parameter lists are
//! decoded in `rtps_params`.

use std::fmt;

use rtps_proto::types::{SequenceNumberSet, Timestamp};
use rtps_proto::wire::{Endianness, Message, Payload, Submessage, SubmessageKind, WireError};
use serde_json::{Map, Value, json};

use super::rtps_names::{entity, locator, prefix, vendor};
use super::rtps_params::parameters;
use crate::hex;

/// Why a datagram has no JSON: the wire layer's refusal and, when it came after the header, the
/// index (from 0) of the submessage it refused.
#[derive(Debug, Clone, Copy)]
pub(super) struct Refusal {
    pub(super) error: WireError,
    pub(super) submessage: Option<usize>,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.submessage {
            Some(i) => write!(f, "{} (submessage index {i})", self.error),
            None => write!(f, "{}", self.error),
        }
    }
}

/// The datagram as one JSON object: `length`, `header`, `submessages`.
pub(super) fn datagram(bytes: &[u8]) -> Result<Map<String, Value>, Refusal> {
    let message = Message::parse(bytes).map_err(|error| Refusal { error, submessage: None })?;
    let header = message.header();
    let mut flags = SubmessageFlags { rest: message.body() };
    let mut submessages = Vec::new();
    for (i, parsed) in message.submessages().enumerate() {
        let refused = |error| Refusal { error, submessage: Some(i) };
        // The iterator yields no flags; they are read again from the same header it parsed.
        let flags = flags.next().unwrap_or(0);
        let parsed = parsed.map_err(refused)?;
        submessages.push(submessage(&parsed, flags).map_err(refused)?);
    }
    let mut out = Map::new();
    out.insert("length".into(), json!(bytes.len()));
    out.insert(
        "header".into(),
        json!({
            "version": format!("{}.{}", header.version.major, header.version.minor),
            "vendor_id": vendor(header.vendor),
            "guid_prefix": prefix(header.guid_prefix),
        }),
    );
    out.insert("submessages".into(), Value::Array(submessages));
    Ok(out)
}

/// The flags byte of each submessage header, walked as `Submessages` walks them (a length of 0
/// runs to the end, except for PAD and INFO_TS).
struct SubmessageFlags<'a> {
    rest: &'a [u8],
}

impl Iterator for SubmessageFlags<'_> {
    type Item = u8;
    fn next(&mut self) -> Option<u8> {
        let (&[kind, flags, l0, l1], after) = self.rest.split_first_chunk::<4>()?;
        let length =
            usize::from(if flags & 1 == 1 { u16::from_le_bytes([l0, l1]) } else { u16::from_be_bytes([l0, l1]) });
        let to_end =
            length == 0 && !matches!(SubmessageKind::from_id(kind), SubmessageKind::Pad | SubmessageKind::InfoTs);
        self.rest = if to_end { &[] } else { after.get(length..).unwrap_or_default() };
        Some(flags)
    }
}

/// The submessage's name as the spec writes it.
fn kind_name(kind: SubmessageKind) -> &'static str {
    match kind {
        SubmessageKind::Pad => "PAD",
        SubmessageKind::AckNack => "ACKNACK",
        SubmessageKind::Heartbeat => "HEARTBEAT",
        SubmessageKind::Gap => "GAP",
        SubmessageKind::InfoTs => "INFO_TS",
        SubmessageKind::InfoSrc => "INFO_SRC",
        SubmessageKind::InfoReplyIp4 => "INFO_REPLY_IP4",
        SubmessageKind::InfoDst => "INFO_DST",
        SubmessageKind::InfoReply => "INFO_REPLY",
        SubmessageKind::NackFrag => "NACK_FRAG",
        SubmessageKind::HeartbeatFrag => "HEARTBEAT_FRAG",
        SubmessageKind::Data => "DATA",
        SubmessageKind::DataFrag => "DATA_FRAG",
        SubmessageKind::Unknown(_) => "UNKNOWN",
    }
}

/// The letters of the flags set, by the kind's table (E first); bits without a meaning for the
/// kind are left out (the raw byte is beside them).
fn flag_names(kind: SubmessageKind, flags: u8) -> Vec<&'static str> {
    let table: &[(u8, &str)] = match kind {
        SubmessageKind::Data => &[(0x02, "Q"), (0x04, "D"), (0x08, "K"), (0x10, "N")],
        SubmessageKind::DataFrag => &[(0x02, "Q"), (0x04, "K"), (0x08, "N")],
        SubmessageKind::Heartbeat => &[(0x02, "F"), (0x04, "L"), (0x08, "G")],
        SubmessageKind::AckNack => &[(0x02, "F")],
        SubmessageKind::Gap => &[(0x02, "G")],
        SubmessageKind::InfoTs => &[(0x02, "I")],
        SubmessageKind::InfoReply | SubmessageKind::InfoReplyIp4 => &[(0x02, "M")],
        _ => &[],
    };
    std::iter::once((0x01, "E"))
        .chain(table.iter().copied())
        .filter(|&(bit, _)| flags & bit != 0)
        .map(|(_, n)| n)
        .collect()
}

fn submessage(sub: &Submessage<'_>, flags: u8) -> Result<Value, WireError> {
    let kind = sub.kind();
    let mut out = Map::new();
    out.insert("kind".into(), json!(kind_name(kind)));
    out.insert("id".into(), json!(format!("0x{:02x}", kind.id())));
    out.insert("flags".into(), json!(format!("0x{flags:02x}")));
    out.insert("flag_names".into(), json!(flag_names(kind, flags)));
    let endianness = if flags & 1 == 1 { Endianness::Little } else { Endianness::Big };
    out.insert("endianness".into(), json!(endianness_name(endianness)));
    let fields = match sub {
        Submessage::Data(d) => {
            let mut f = json!({
                "reader_id": entity(d.reader_id),
                "writer_id": entity(d.writer_id),
                "writer_sn": d.writer_sn.0,
                "non_standard_payload": d.non_standard_payload,
                "inline_qos": d.inline_qos.as_ref().map(parameters),
            });
            match d.payload {
                Payload::None => {}
                Payload::Data(b) => f["serialized_payload"] = payload(b, d.non_standard_payload)?,
                Payload::Key(b) => f["serialized_key"] = payload(b, d.non_standard_payload)?,
            }
            f
        }
        Submessage::DataFrag(d) => json!({
            "reader_id": entity(d.reader_id),
            "writer_id": entity(d.writer_id),
            "writer_sn": d.writer_sn.0,
            "fragment_starting_num": d.fragment_starting_num,
            "fragments_in_submessage": d.fragments_in_submessage,
            "fragment_size": d.fragment_size,
            "sample_size": d.sample_size,
            "total_fragments": d.total_fragments(),
            "key": d.key,
            "non_standard_payload": d.non_standard_payload,
            "inline_qos": d.inline_qos.as_ref().map(parameters),
            // The sample's encapsulation header is in its first fragment only.
            "encapsulation": (d.fragment_starting_num == 1 && !d.non_standard_payload)
                .then(|| d.payload.first_chunk::<2>().map(|&id| encapsulation_name(id)))
                .flatten(),
            "payload": {"length": d.payload.len(), "hex": hex::format(d.payload)},
        }),
        Submessage::Heartbeat(h) => json!({
            "reader_id": entity(h.reader_id),
            "writer_id": entity(h.writer_id),
            "first_sn": h.first_sn.0,
            "last_sn": h.last_sn.0,
            "count": h.count,
            "final": h.final_flag,
            "liveliness": h.liveliness_flag,
        }),
        Submessage::HeartbeatFrag(h) => json!({
            "reader_id": entity(h.reader_id),
            "writer_id": entity(h.writer_id),
            "writer_sn": h.writer_sn.0,
            "last_fragment_num": h.last_fragment_num,
            "count": h.count,
        }),
        Submessage::AckNack(a) => json!({
            "reader_id": entity(a.reader_id),
            "writer_id": entity(a.writer_id),
            "reader_sn_state": sn_set(&a.reader_sn_state),
            "count": a.count,
            "final": a.final_flag,
        }),
        Submessage::NackFrag(n) => json!({
            "reader_id": entity(n.reader_id),
            "writer_id": entity(n.writer_id),
            "writer_sn": n.writer_sn.0,
            "fragment_number_state": {
                "base": n.fragment_number_state.base(),
                "num_bits": n.fragment_number_state.num_bits(),
                "members": n.fragment_number_state.iter().collect::<Vec<_>>(),
            },
            "count": n.count,
        }),
        Submessage::Gap(g) => json!({
            "reader_id": entity(g.reader_id),
            "writer_id": entity(g.writer_id),
            "gap_start": g.gap_start.0,
            "gap_list": sn_set(&g.gap_list),
        }),
        Submessage::InfoTs(t) => json!({ "timestamp": t.timestamp.map(timestamp) }),
        Submessage::InfoDst(d) => json!({ "guid_prefix": prefix(d.guid_prefix) }),
        Submessage::InfoSrc(s) => json!({
            "version": format!("{}.{}", s.version.major, s.version.minor),
            "vendor_id": vendor(s.vendor),
            "guid_prefix": prefix(s.guid_prefix),
        }),
        Submessage::InfoReply(r) => json!({
            "unicast_locators": r.unicast.iter().map(|l| locator(&l)).collect::<Vec<_>>(),
            "multicast_locators": r.multicast.map(|m| m.iter().map(|l| locator(&l)).collect::<Vec<_>>()),
        }),
        Submessage::InfoReplyIp4(r) => json!({
            "unicast_locator": locator(&r.unicast),
            "multicast_locator": r.multicast.as_ref().map(locator),
        }),
        Submessage::Pad => json!({}),
        Submessage::Unknown { kind, body, .. } => json!({
            // 0x80..=0xff are the vendors' own (Fast DDS's statistics, …).
            "vendor_specific": *kind >= 0x80,
            "body": {"length": body.len(), "hex": hex::format(body)},
        }),
    };
    if let Value::Object(fields) = fields {
        out.extend(fields);
    }
    Ok(Value::Object(out))
}

/// A DATA's serialized payload or key: a parameter list (SPDP, SEDP) decoded, others in hex.
/// A parameter list that does not check is the submessage's refusal.
fn payload(bytes: &[u8], non_standard: bool) -> Result<Value, WireError> {
    let (Some(&[i0, i1, o0, o1]), Some(data), false) = (bytes.first_chunk::<4>(), bytes.get(4..), non_standard) else {
        return Ok(json!({ "encapsulation": null, "length": bytes.len(), "hex": hex::format(bytes) }));
    };
    let options = hex::format(&[o0, o1]);
    let list_endianness = match [i0, i1] {
        [0, 2] => Some(Endianness::Big),
        [0, 3] => Some(Endianness::Little),
        _ => None,
    };
    Ok(match list_endianness {
        Some(e) => {
            let (list, used) = rtps_proto::wire::ParameterList::parse(data, e)?;
            json!({
                "encapsulation": encapsulation_name([i0, i1]),
                "options": options,
                "parameters": parameters(&list),
                "trailing_bytes": data.len().saturating_sub(used),
            })
        }
        None => json!({
            "encapsulation": encapsulation_name([i0, i1]),
            "options": options,
            "length": data.len(),
            "hex": hex::format(data),
        }),
    })
}

/// The representation identifier's name (XTypes 1.3 §7.6.3.1.2, with the XCDR2 values
/// CycloneDDS, Fast DDS and rustdds write), or its hex.
fn encapsulation_name(id: [u8; 2]) -> String {
    match id {
        [0, 0x00] => "CDR_BE",
        [0, 0x01] => "CDR_LE",
        [0, 0x02] => "PL_CDR_BE",
        [0, 0x03] => "PL_CDR_LE",
        [0, 0x04] => "XML",
        [0, 0x06] => "CDR2_BE",
        [0, 0x07] => "CDR2_LE",
        [0, 0x08] => "D_CDR2_BE",
        [0, 0x09] => "D_CDR2_LE",
        [0, 0x0a] => "PL_CDR2_BE",
        [0, 0x0b] => "PL_CDR2_LE",
        other => return format!("0x{}", hex::format(&other)),
    }
    .to_string()
}

pub(super) fn endianness_name(e: Endianness) -> &'static str {
    match e {
        Endianness::Little => "little",
        Endianness::Big => "big",
    }
}

fn sn_set(set: &SequenceNumberSet) -> Value {
    json!({
        "base": set.base().0,
        "num_bits": set.num_bits(),
        "members": set.iter().map(|s| s.0).collect::<Vec<_>>(),
    })
}

fn timestamp(t: Timestamp) -> Value {
    json!({
        "seconds": f64::from(t.seconds) + f64::from(t.fraction) / 4_294_967_296.0,
        "raw": {"seconds": t.seconds, "fraction": t.fraction},
    })
}
