//! RTPS identities as a reader names them: GUID prefixes, vendors, entity ids (the builtin ones
//! by name) and locators.

use rtps_proto::types::{EntityId, GuidPrefix, Locator, VendorId};
use serde_json::{Value, json};

use crate::hex;

pub(super) fn prefix(p: GuidPrefix) -> String {
    hex::format(&p.0)
}

pub(super) fn vendor(v: VendorId) -> Value {
    json!({ "hex": hex::format(&v.0), "name": v.name() })
}

pub(super) fn entity(e: EntityId) -> Value {
    json!({ "hex": hex::format(&e.0), "name": entity_name(e) })
}

/// Names of the builtin (and the unknown) entity ids: RTPS 2.5 table 9.1, DDS-XTypes' type
/// lookup service, DDS-Security's stateless and volatile endpoints. rtps-proto names them only as
/// constants, so the table is here.
fn entity_name(e: EntityId) -> Option<&'static str> {
    Some(match e.0 {
        [0, 0, 0, 0] => "UNKNOWN",
        [0, 0, 1, 0xc1] => "PARTICIPANT",
        [0, 0, 2, 0xc2] => "SEDP_TOPICS_WRITER",
        [0, 0, 2, 0xc7] => "SEDP_TOPICS_READER",
        [0, 0, 3, 0xc2] => "SEDP_PUBLICATIONS_WRITER",
        [0, 0, 3, 0xc7] => "SEDP_PUBLICATIONS_READER",
        [0, 0, 4, 0xc2] => "SEDP_SUBSCRIPTIONS_WRITER",
        [0, 0, 4, 0xc7] => "SEDP_SUBSCRIPTIONS_READER",
        [0, 1, 0, 0xc2] => "SPDP_WRITER",
        [0, 1, 0, 0xc7] => "SPDP_READER",
        [0, 2, 0, 0xc2] => "P2P_MESSAGE_WRITER",
        [0, 2, 0, 0xc7] => "P2P_MESSAGE_READER",
        [0, 2, 1, 0xc3] => "P2P_STATELESS_WRITER",
        [0, 2, 1, 0xc4] => "P2P_STATELESS_READER",
        [0, 3, 0, 0xc3] => "TL_SVC_REQUEST_WRITER",
        [0, 3, 0, 0xc4] => "TL_SVC_REQUEST_READER",
        [0, 3, 1, 0xc3] => "TL_SVC_REPLY_WRITER",
        [0, 3, 1, 0xc4] => "TL_SVC_REPLY_READER",
        [0xff, 0, 3, 0xc2] => "SEDP_PUBLICATIONS_SECURE_WRITER",
        [0xff, 0, 3, 0xc7] => "SEDP_PUBLICATIONS_SECURE_READER",
        [0xff, 0, 4, 0xc2] => "SEDP_SUBSCRIPTIONS_SECURE_WRITER",
        [0xff, 0, 4, 0xc7] => "SEDP_SUBSCRIPTIONS_SECURE_READER",
        [0xff, 1, 0, 0xc2] => "SPDP_SECURE_WRITER",
        [0xff, 1, 0, 0xc7] => "SPDP_SECURE_READER",
        [0xff, 2, 0, 0xc2] => "P2P_MESSAGE_SECURE_WRITER",
        [0xff, 2, 0, 0xc7] => "P2P_MESSAGE_SECURE_READER",
        [0xff, 2, 2, 0xc3] => "P2P_VOLATILE_SECURE_WRITER",
        [0xff, 2, 2, 0xc4] => "P2P_VOLATILE_SECURE_READER",
        _ => return None,
    })
}

/// A locator as `udp/1.2.3.4:7410` (`udp/[::1]:7410`, `tcp/…`, `shm/<address hex>:<port>`,
/// `invalid`, `kind<k>/<address hex>:<port>`).
pub(super) fn locator(l: &Locator) -> String {
    let v4 = || {
        let a = l.address.get(12..16).unwrap_or_default();
        a.iter().map(u8::to_string).collect::<Vec<_>>().join(".")
    };
    let v6 = || std::net::Ipv6Addr::from(l.address).to_string();
    match l.kind {
        Locator::KIND_UDPV4 => format!("udp/{}:{}", v4(), l.port),
        Locator::KIND_UDPV6 => format!("udp/[{}]:{}", v6(), l.port),
        4 => format!("tcp/{}:{}", v4(), l.port),
        8 => format!("tcp/[{}]:{}", v6(), l.port),
        16 => format!("shm/{}:{}", hex::format(&l.address), l.port),
        -1 => "invalid".to_string(),
        k => format!("kind{k}/{}:{}", hex::format(&l.address), l.port),
    }
}
