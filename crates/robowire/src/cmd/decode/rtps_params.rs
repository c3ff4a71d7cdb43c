//! Parameter lists (SPDP/SEDP data, inline QoS) as JSON: each parameter's PID, name and length,
//! and its value decoded where the PID is known (strings, locators, GUIDs, durations, integers,
//! the common QoS policies), in hex otherwise. A value that does not hold what its PID says is
//! given in hex with `"malformed": true`; every read is checked against the value's bytes.

use rtps_proto::types::{EntityId, Locator, VendorId};
use rtps_proto::wire::{Endianness, Parameter, ParameterList, pid};
use serde_json::{Value, json};

use super::rtps_names::{entity, locator, vendor};
use crate::hex;

/// The list's parameters in order (PID_PAD and the sentinel left out).
pub(super) fn parameters(list: &ParameterList<'_>) -> Value {
    let e = list.endianness();
    Value::Array(list.iter().map(|p| parameter(p, e)).collect())
}

fn parameter(p: Parameter<'_>, e: Endianness) -> Value {
    let mut out = json!({
        "pid": format!("0x{:04x}", p.pid),
        "name": pid::name(p.pid),
        "length": p.value.len(),
    });
    match decode(p.pid, p.value, e) {
        Decoded::Value(v) => out["value"] = v,
        Decoded::Unknown => out["value"] = json!(hex::format(p.value)),
        Decoded::Malformed => {
            out["value"] = json!(hex::format(p.value));
            out["malformed"] = json!(true);
        }
    }
    out
}

enum Decoded {
    Value(Value),
    /// No decoder for the PID: the value in hex.
    Unknown,
    /// The PID's decoder found the value short or inconsistent.
    Malformed,
}

fn decode(id: u16, value: &[u8], e: Endianness) -> Decoded {
    if id & pid::VENDOR_SPECIFIC != 0 {
        // Vendor-specific PIDs mean what the sender's vendor says; only the legacy
        // PID_RELATED_SAMPLE_IDENTITY is shared by those that use it.
        return match id {
            pid::RELATED_SAMPLE_IDENTITY_LEGACY => decode_as(pid::RELATED_SAMPLE_IDENTITY, value, e),
            _ => Decoded::Unknown,
        };
    }
    // The PID as it is (PID_DOMAIN_TAG has the must-understand bit in its value), else without
    // the must-understand bit.
    match decode_as(id, value, e) {
        Decoded::Unknown if id & pid::MUST_UNDERSTAND != 0 => decode_as(id & !pid::MUST_UNDERSTAND, value, e),
        decoded => decoded,
    }
}

fn decode_as(base: u16, value: &[u8], e: Endianness) -> Decoded {
    let mut r = Cdr { bytes: value, at: 0, e };
    let decoded = match base {
        pid::TOPIC_NAME | pid::TYPE_NAME | pid::ENTITY_NAME | pid::DOMAIN_TAG => r.string().map(Value::String),
        pid::PARTITION => r.strings().map(|s| json!(s)),
        pid::UNICAST_LOCATOR
        | pid::MULTICAST_LOCATOR
        | pid::DEFAULT_UNICAST_LOCATOR
        | pid::DEFAULT_MULTICAST_LOCATOR
        | pid::METATRAFFIC_UNICAST_LOCATOR
        | pid::METATRAFFIC_MULTICAST_LOCATOR => r.locator().map(|l| json!(locator(&l))),
        pid::PARTICIPANT_GUID | pid::ENDPOINT_GUID | pid::GROUP_GUID => r.take(16).map(|g| json!(hex::format(g))),
        pid::PARTICIPANT_ENTITYID | pid::GROUP_ENTITYID => r.array::<4>().map(|b| entity(EntityId(b))),
        pid::PARTICIPANT_LEASE_DURATION
        | pid::DEADLINE
        | pid::LATENCY_BUDGET
        | pid::LIFESPAN
        | pid::TIME_BASED_FILTER => r.duration(),
        pid::DOMAIN_ID
        | pid::BUILTIN_ENDPOINT_SET
        | pid::PARTICIPANT_BUILTIN_ENDPOINTS
        | pid::BUILTIN_ENDPOINT_QOS
        | pid::TYPE_MAX_SIZE_SERIALIZED => r.u32().map(|v| json!(v)),
        pid::PARTICIPANT_MANUAL_LIVELINESS_COUNT | pid::TRANSPORT_PRIORITY | pid::OWNERSHIP_STRENGTH => {
            r.u32().map(|v| json!(v as i32))
        }
        pid::PROTOCOL_VERSION => r.array::<2>().map(|[major, minor]| json!(format!("{major}.{minor}"))),
        pid::VENDORID => r.array::<2>().map(|b| vendor(VendorId(b))),
        pid::EXPECTS_INLINE_QOS => r.array::<1>().map(|[b]| json!(b != 0)),
        // Always big-endian, whatever the list's byte order (RTPS 2.5 §9.6.4.9).
        pid::STATUS_INFO => r.array::<4>().map(|b| status_info(u32::from_be_bytes(b))),
        pid::RELATED_SAMPLE_IDENTITY => r.take(16).and_then(|guid| {
            let guid = hex::format(guid);
            let high = r.u32()? as i32;
            let sn = (i64::from(high) << 32) | i64::from(r.u32()?);
            Some(json!({ "writer_guid": guid, "sequence_number": sn }))
        }),
        pid::RELIABILITY => r
            .kind(&["?", "BEST_EFFORT", "RELIABLE"])
            .and_then(|kind| Some(json!({ "kind": kind, "max_blocking_time": r.duration()? }))),
        pid::DURABILITY => r.kind(&["VOLATILE", "TRANSIENT_LOCAL", "TRANSIENT", "PERSISTENT"]),
        pid::OWNERSHIP => r.kind(&["SHARED", "EXCLUSIVE"]),
        pid::DESTINATION_ORDER => r.kind(&["BY_RECEPTION_TIMESTAMP", "BY_SOURCE_TIMESTAMP"]),
        pid::HISTORY => {
            r.kind(&["KEEP_LAST", "KEEP_ALL"]).and_then(|kind| Some(json!({ "kind": kind, "depth": r.u32()? as i32 })))
        }
        pid::LIVELINESS => r
            .kind(&["AUTOMATIC", "MANUAL_BY_PARTICIPANT", "MANUAL_BY_TOPIC"])
            .and_then(|kind| Some(json!({ "kind": kind, "lease_duration": r.duration()? }))),
        pid::PRESENTATION => r.kind(&["INSTANCE", "TOPIC", "GROUP"]).and_then(|scope| {
            let [coherent, ordered] = r.array::<2>()?;
            Some(json!({ "access_scope": scope, "coherent_access": coherent != 0, "ordered_access": ordered != 0 }))
        }),
        pid::DATA_REPRESENTATION => r.data_representation(),
        pid::PROPERTY_LIST => r.properties(),
        _ => return Decoded::Unknown,
    };
    decoded.map_or(Decoded::Malformed, Decoded::Value)
}

fn status_info(bits: u32) -> Value {
    let names = [(1, "disposed"), (2, "unregistered"), (4, "filtered")];
    json!({
        "bits": bits,
        "flags": names.iter().filter(|&&(bit, _)| bits & bit != 0).map(|&(_, n)| n).collect::<Vec<_>>(),
    })
}

/// A checked CDR reader over one parameter's value (values start 4-aligned in their list, so
/// alignment is from the value's start).
struct Cdr<'a> {
    bytes: &'a [u8],
    at: usize,
    e: Endianness,
}

impl<'a> Cdr<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.at.checked_add(n)?;
        let b = self.bytes.get(self.at..end)?;
        self.at = end;
        Some(b)
    }

    fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        self.take(N)?.try_into().ok()
    }

    fn align(&mut self, n: usize) {
        self.at = self.at.next_multiple_of(n);
    }

    fn u16(&mut self) -> Option<u16> {
        self.align(2);
        let b = self.array()?;
        Some(match self.e {
            Endianness::Little => u16::from_le_bytes(b),
            Endianness::Big => u16::from_be_bytes(b),
        })
    }

    fn u32(&mut self) -> Option<u32> {
        self.align(4);
        let b = self.array()?;
        Some(match self.e {
            Endianness::Little => u32::from_le_bytes(b),
            Endianness::Big => u32::from_be_bytes(b),
        })
    }

    /// A count of items of at least `min_bytes` each, checked against the bytes left.
    fn count(&mut self, min_bytes: usize) -> Option<usize> {
        let n = usize::try_from(self.u32()?).ok()?;
        (n.checked_mul(min_bytes)? <= self.bytes.len().saturating_sub(self.at)).then_some(n)
    }

    /// A CDR string: length (the NUL included), bytes; invalid UTF-8 replaced.
    fn string(&mut self) -> Option<String> {
        let n = usize::try_from(self.u32()?).ok()?;
        let b = self.take(n)?;
        let b = b.strip_suffix(&[0]).unwrap_or(b);
        Some(String::from_utf8_lossy(b).into_owned())
    }

    fn strings(&mut self) -> Option<Vec<String>> {
        let n = self.count(4)?;
        (0..n).map(|_| self.string()).collect()
    }

    /// A `Duration_t` in seconds; DURATION_INFINITE as "infinite".
    fn duration(&mut self) -> Option<Value> {
        let seconds = self.u32()? as i32;
        let fraction = self.u32()?;
        Some(if (seconds, fraction) == (i32::MAX, u32::MAX) {
            json!("infinite")
        } else {
            json!(f64::from(seconds) + f64::from(fraction) / 4_294_967_296.0)
        })
    }

    fn locator(&mut self) -> Option<Locator> {
        let kind = self.u32()? as i32;
        let port = self.u32()?;
        Some(Locator { kind, port, address: self.array()? })
    }

    /// A QoS kind (`u32`) by its name in `names`, or the number when out of the table.
    fn kind(&mut self, names: &[&str]) -> Option<Value> {
        let k = self.u32()?;
        Some(match usize::try_from(k).ok().and_then(|i| names.get(i)) {
            Some(&name) if name != "?" => json!(name),
            _ => json!(k),
        })
    }

    fn data_representation(&mut self) -> Option<Value> {
        let n = self.count(2)?;
        let ids = (0..n)
            .map(|_| {
                Some(match self.u16()? {
                    0 => json!("XCDR"),
                    1 => json!("XML"),
                    2 => json!("XCDR2"),
                    other => json!(other as i16),
                })
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Value::Array(ids))
    }

    /// PROPERTY_LIST: the (name, value) string properties (binary properties after them are
    /// left out).
    fn properties(&mut self) -> Option<Value> {
        let n = self.count(8)?;
        let props = (0..n)
            .map(|_| Some(json!({ "name": self.string()?, "value": self.string()? })))
            .collect::<Option<Vec<_>>>()?;
        Some(Value::Array(props))
    }
}
