//! SPDP: what a participant announces about itself (SPDPdiscoveredParticipantData).

use super::{DiscoveryError, LocatorBudget, ValueReader, pid, put, skip_unknown};
use crate::Limits;
use crate::types::{DdsDuration, GuidPrefix, Locator, ProtocolVersion, VendorId};
use crate::wire::{ParameterList, ParameterWriter};
use alloc::string::String;
use alloc::vec::Vec;
use robowire_core::BufferTooSmall;

/// PID_BUILTIN_ENDPOINT_SET: which builtin endpoints a participant has (RTPS 2.5 §9.3.2,
/// DDS-XTypes for the type lookup service, DDS-Security's secure endpoints not named here).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct BuiltinEndpointSet(pub u32);

impl BuiltinEndpointSet {
    /// SPDP participant writer.
    pub const PARTICIPANT_ANNOUNCER: u32 = 1 << 0;
    /// SPDP participant reader.
    pub const PARTICIPANT_DETECTOR: u32 = 1 << 1;
    /// SEDP publications writer.
    pub const PUBLICATIONS_ANNOUNCER: u32 = 1 << 2;
    /// SEDP publications reader.
    pub const PUBLICATIONS_DETECTOR: u32 = 1 << 3;
    /// SEDP subscriptions writer.
    pub const SUBSCRIPTIONS_ANNOUNCER: u32 = 1 << 4;
    /// SEDP subscriptions reader.
    pub const SUBSCRIPTIONS_DETECTOR: u32 = 1 << 5;
    /// Participant proxy writer (deprecated).
    pub const PARTICIPANT_PROXY_ANNOUNCER: u32 = 1 << 6;
    /// Participant proxy reader (deprecated).
    pub const PARTICIPANT_PROXY_DETECTOR: u32 = 1 << 7;
    /// Participant state writer (deprecated).
    pub const PARTICIPANT_STATE_ANNOUNCER: u32 = 1 << 8;
    /// Participant state reader (deprecated).
    pub const PARTICIPANT_STATE_DETECTOR: u32 = 1 << 9;
    /// WLP participant message writer.
    pub const PARTICIPANT_MESSAGE_DATA_WRITER: u32 = 1 << 10;
    /// WLP participant message reader.
    pub const PARTICIPANT_MESSAGE_DATA_READER: u32 = 1 << 11;
    /// Type lookup service request writer (DDS-XTypes).
    pub const TYPE_LOOKUP_REQUEST_DATA_WRITER: u32 = 1 << 12;
    /// Type lookup service request reader.
    pub const TYPE_LOOKUP_REQUEST_DATA_READER: u32 = 1 << 13;
    /// Type lookup service reply writer.
    pub const TYPE_LOOKUP_REPLY_DATA_WRITER: u32 = 1 << 14;
    /// Type lookup service reply reader.
    pub const TYPE_LOOKUP_REPLY_DATA_READER: u32 = 1 << 15;
    /// SEDP topics writer.
    pub const TOPICS_ANNOUNCER: u32 = 1 << 28;
    /// SEDP topics reader.
    pub const TOPICS_DETECTOR: u32 = 1 << 29;

    /// What robowire's participant has: SPDP, SEDP publications and subscriptions. Not WLP
    /// (liveliness is the participant's lease): a participant message reader announced but never
    /// served makes CycloneDDS heartbeat it forever, and a writer announced, ACKNACK it every
    /// second.
    pub const ROBOWIRE: Self = Self(
        Self::PARTICIPANT_ANNOUNCER
            | Self::PARTICIPANT_DETECTOR
            | Self::PUBLICATIONS_ANNOUNCER
            | Self::PUBLICATIONS_DETECTOR
            | Self::SUBSCRIPTIONS_ANNOUNCER
            | Self::SUBSCRIPTIONS_DETECTOR,
    );

    /// Whether every bit of `bits` is set.
    pub const fn contains(self, bits: u32) -> bool {
        self.0 & bits == bits
    }
}

/// What SPDP says about a participant (SPDPdiscoveredParticipantData).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ParticipantData {
    /// The participant's GUID prefix (PID_PARTICIPANT_GUID, required).
    pub guid_prefix: GuidPrefix,
    /// PID_PROTOCOL_VERSION (2.0 when absent).
    pub protocol_version: ProtocolVersion,
    /// PID_VENDORID (unknown when absent).
    pub vendor_id: VendorId,
    /// PID_DOMAIN_ID (absent: the domain the datagram arrived on).
    pub domain_id: Option<u32>,
    /// PID_DOMAIN_TAG ("" when absent).
    pub domain_tag: String,
    /// PID_BUILTIN_ENDPOINT_SET.
    pub builtin_endpoints: BuiltinEndpointSet,
    /// PID_EXPECTS_INLINE_QOS (false when absent).
    pub expects_inline_qos: bool,
    /// PID_METATRAFFIC_UNICAST_LOCATOR: where to send SPDP/SEDP to this participant alone.
    pub metatraffic_unicast_locators: Vec<Locator>,
    /// PID_METATRAFFIC_MULTICAST_LOCATOR.
    pub metatraffic_multicast_locators: Vec<Locator>,
    /// PID_DEFAULT_UNICAST_LOCATOR: user traffic to endpoints that name none.
    pub default_unicast_locators: Vec<Locator>,
    /// PID_DEFAULT_MULTICAST_LOCATOR.
    pub default_multicast_locators: Vec<Locator>,
    /// PID_PARTICIPANT_LEASE_DURATION (100 s when absent).
    pub lease_duration: DdsDuration,
    /// PID_USER_DATA.
    pub user_data: Vec<u8>,
    /// PID_ENTITY_NAME.
    pub entity_name: Option<String>,
    /// PID_PARTICIPANT_MANUAL_LIVELINESS_COUNT (0 when absent).
    pub manual_liveliness_count: i32,
    /// Parameters skipped on parse: unknown or vendor-specific PIDs.
    pub unknown_parameters: u32,
    /// Locators dropped on parse past `Limits::locators_per_endpoint` (all four lists together).
    pub dropped_locators: u32,
}

impl ParticipantData {
    /// DURATION of a lease when PID_PARTICIPANT_LEASE_DURATION is absent (RTPS: 100 s).
    pub const DEFAULT_LEASE_DURATION: DdsDuration = DdsDuration { seconds: 100, fraction: 0 };

    /// Data for participant `guid_prefix` with robowire's version, vendor and builtin endpoints,
    /// no locators, and the defaults of the absent parameters.
    pub fn new(guid_prefix: GuidPrefix) -> Self {
        Self {
            guid_prefix,
            protocol_version: ProtocolVersion::V2_4,
            vendor_id: VendorId::ROBOWIRE,
            domain_id: None,
            domain_tag: String::new(),
            builtin_endpoints: BuiltinEndpointSet::ROBOWIRE,
            expects_inline_qos: false,
            metatraffic_unicast_locators: Vec::new(),
            metatraffic_multicast_locators: Vec::new(),
            default_unicast_locators: Vec::new(),
            default_multicast_locators: Vec::new(),
            lease_duration: Self::DEFAULT_LEASE_DURATION,
            user_data: Vec::new(),
            entity_name: None,
            manual_liveliness_count: 0,
            unknown_parameters: 0,
            dropped_locators: 0,
        }
    }

    /// Reads the data from a parameter list (values in the list's endianness).
    pub fn parse(list: &ParameterList<'_>, limits: &Limits) -> Result<Self, DiscoveryError> {
        let mut guid = None;
        let mut d = Self::new(GuidPrefix::UNKNOWN);
        d.protocol_version = ProtocolVersion { major: 2, minor: 0 };
        d.vendor_id = VendorId::UNKNOWN;
        d.builtin_endpoints = BuiltinEndpointSet(0);
        let mut locators = LocatorBudget::new(limits);
        for p in list.iter() {
            let mut r = ValueReader::new(p, list.endianness());
            match p.pid {
                pid::PARTICIPANT_GUID => guid = Some(r.guid()?.prefix),
                pid::PROTOCOL_VERSION => d.protocol_version = ProtocolVersion { major: r.u8()?, minor: r.u8()? },
                pid::VENDOR_ID => d.vendor_id = VendorId([r.u8()?, r.u8()?]),
                pid::DOMAIN_ID => d.domain_id = Some(r.u32()?),
                pid::DOMAIN_TAG => d.domain_tag = r.string(limits)?,
                pid::BUILTIN_ENDPOINT_SET => d.builtin_endpoints = BuiltinEndpointSet(r.u32()?),
                pid::EXPECTS_INLINE_QOS => d.expects_inline_qos = r.bool()?,
                pid::METATRAFFIC_UNICAST_LOCATOR => locators.add(&mut d.metatraffic_unicast_locators, &mut r)?,
                pid::METATRAFFIC_MULTICAST_LOCATOR => locators.add(&mut d.metatraffic_multicast_locators, &mut r)?,
                pid::DEFAULT_UNICAST_LOCATOR => locators.add(&mut d.default_unicast_locators, &mut r)?,
                pid::DEFAULT_MULTICAST_LOCATOR => locators.add(&mut d.default_multicast_locators, &mut r)?,
                pid::PARTICIPANT_LEASE_DURATION => d.lease_duration = r.duration()?,
                pid::USER_DATA => d.user_data = r.octets(limits)?,
                pid::ENTITY_NAME => d.entity_name = Some(r.string(limits)?),
                pid::PARTICIPANT_MANUAL_LIVELINESS_COUNT => d.manual_liveliness_count = r.i32()?,
                other => {
                    skip_unknown(other)?;
                    d.unknown_parameters = d.unknown_parameters.saturating_add(1);
                }
            }
        }
        d.guid_prefix = guid.ok_or(DiscoveryError::MissingGuid)?;
        d.dropped_locators = locators.dropped;
        Ok(d)
    }

    /// Reads the data from a DATA's serialized payload: PL_CDR_BE or PL_CDR_LE, then the list.
    pub fn parse_payload(serialized: &[u8], limits: &Limits) -> Result<Self, DiscoveryError> {
        Self::parse(&super::payload_list(serialized, limits)?, limits)
    }

    /// Writes the parameters (standard PIDs only, little-endian; no sentinel: the caller
    /// finishes the list). Absent-by-default values (no domain id, an empty tag or user data, no
    /// name, a zero liveliness count, no inline QoS) are left out.
    pub fn emit(&self, w: &mut ParameterWriter<'_>) -> Result<(), BufferTooSmall> {
        let mut guid = [0; 16];
        guid[..12].copy_from_slice(&self.guid_prefix.0);
        guid[12..].copy_from_slice(&crate::types::EntityId::PARTICIPANT.0);
        w.push(pid::PARTICIPANT_GUID, &guid)?;
        w.push(pid::PROTOCOL_VERSION, &[self.protocol_version.major, self.protocol_version.minor])?;
        w.push(pid::VENDOR_ID, &self.vendor_id.0)?;
        if let Some(id) = self.domain_id {
            put::u32(w, pid::DOMAIN_ID, id)?;
        }
        if !self.domain_tag.is_empty() {
            put::string(w, pid::DOMAIN_TAG, &self.domain_tag)?;
        }
        put::u32(w, pid::BUILTIN_ENDPOINT_SET, self.builtin_endpoints.0)?;
        if self.expects_inline_qos {
            put::bool(w, pid::EXPECTS_INLINE_QOS, true)?;
        }
        put::locators(w, pid::METATRAFFIC_UNICAST_LOCATOR, &self.metatraffic_unicast_locators)?;
        put::locators(w, pid::METATRAFFIC_MULTICAST_LOCATOR, &self.metatraffic_multicast_locators)?;
        put::locators(w, pid::DEFAULT_UNICAST_LOCATOR, &self.default_unicast_locators)?;
        put::locators(w, pid::DEFAULT_MULTICAST_LOCATOR, &self.default_multicast_locators)?;
        put::duration(w, pid::PARTICIPANT_LEASE_DURATION, self.lease_duration)?;
        if !self.user_data.is_empty() {
            put::octets(w, pid::USER_DATA, &self.user_data)?;
        }
        if let Some(name) = &self.entity_name {
            put::string(w, pid::ENTITY_NAME, name)?;
        }
        if self.manual_liveliness_count != 0 {
            put::i32(w, pid::PARTICIPANT_MANUAL_LIVELINESS_COUNT, self.manual_liveliness_count)?;
        }
        Ok(())
    }

    /// Writes a DATA's serialized payload: PL_CDR_LE (00 03 00 00), the list, the sentinel.
    /// Returns the bytes written.
    pub fn emit_payload(&self, buf: &mut [u8]) -> Result<usize, BufferTooSmall> {
        super::emit_payload(buf, |w| self.emit(w))
    }
}
