//! SEDP: what a participant announces about its writers and readers (DiscoveredWriterData,
//! DiscoveredReaderData).

use super::qos::QosReader;
use super::{DiscoveryError, LocatorBudget, Qos, ValueReader, pid, put, skip_unknown};
use crate::Limits;
use crate::types::{Guid, Locator};
use crate::wire::{ParameterList, ParameterWriter};
use alloc::string::String;
use alloc::vec::Vec;
use robowire_core::BufferTooSmall;

/// What SEDP says about a writer or a reader (its GUID's entity kind says which).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct EndpointData {
    /// The endpoint (PID_ENDPOINT_GUID, or the DATA's key hash when that is absent).
    pub guid: Guid,
    /// PID_PARTICIPANT_GUID, when sent (the endpoint GUID's prefix names the participant too).
    pub participant_guid: Option<Guid>,
    /// PID_TOPIC_NAME (required).
    pub topic_name: String,
    /// PID_TYPE_NAME (required).
    pub type_name: String,
    /// The QoS; policies absent on the wire take the DDS defaults of a writer or a reader
    /// ([`Qos::default`], [`Qos::reader_default`]) by the GUID's entity kind.
    pub qos: Qos,
    /// PID_UNICAST_LOCATOR (empty: the participant's default locators).
    pub unicast_locators: Vec<Locator>,
    /// PID_MULTICAST_LOCATOR.
    pub multicast_locators: Vec<Locator>,
    /// PID_EXPECTS_INLINE_QOS (readers; false when absent).
    pub expects_inline_qos: bool,
    /// PID_TYPE_INFORMATION (DDS-XTypes TypeInformation, XCDR2), passed through as it came.
    pub type_information: Option<Vec<u8>>,
    /// PID_TYPE_MAX_SIZE_SERIALIZED.
    pub type_max_serialized_size: Option<u32>,
    /// PID_ENTITY_NAME.
    pub entity_name: Option<String>,
    /// Parameters skipped on parse: unknown or vendor-specific PIDs, and standard ones this
    /// type does not keep (PRESENTATION, RESOURCE_LIMITS, …).
    pub unknown_parameters: u32,
    /// Locators dropped on parse past `Limits::locators_per_endpoint` (both lists together).
    pub dropped_locators: u32,
}

impl EndpointData {
    /// Data for endpoint `guid` on `topic_name` of `type_name` with the DDS default QoS of its
    /// kind, no locators and nothing else.
    pub fn new(guid: Guid, topic_name: String, type_name: String) -> Self {
        let qos = if guid.entity.is_reader() { Qos::reader_default() } else { Qos::default() };
        Self {
            guid,
            participant_guid: None,
            topic_name,
            type_name,
            qos,
            unicast_locators: Vec::new(),
            multicast_locators: Vec::new(),
            expects_inline_qos: false,
            type_information: None,
            type_max_serialized_size: None,
            entity_name: None,
            unknown_parameters: 0,
            dropped_locators: 0,
        }
    }

    /// Reads the data from a parameter list (values in the list's endianness). `key_hash` is
    /// the DATA's PID_KEY_HASH (inline QoS), the endpoint GUID when PID_ENDPOINT_GUID is absent.
    pub fn parse(
        list: &ParameterList<'_>,
        key_hash: Option<[u8; 16]>,
        limits: &Limits,
    ) -> Result<Self, DiscoveryError> {
        let guid = match list.find(pid::ENDPOINT_GUID) {
            Some(p) => ValueReader::new(p, list.endianness()).guid()?,
            None => Guid::from_bytes(key_hash.ok_or(DiscoveryError::MissingGuid)?),
        };
        let mut d = Self::new(guid, String::new(), String::new());
        let mut qos = QosReader::new(core::mem::take(&mut d.qos));
        let (mut topic_name, mut type_name) = (None, None);
        let mut locators = LocatorBudget::new(limits);
        for p in list.iter() {
            let mut r = ValueReader::new(p, list.endianness());
            match p.pid {
                pid::ENDPOINT_GUID => {}
                pid::PARTICIPANT_GUID => d.participant_guid = Some(r.guid()?),
                pid::TOPIC_NAME => topic_name = Some(r.string(limits)?),
                pid::TYPE_NAME => type_name = Some(r.string(limits)?),
                pid::UNICAST_LOCATOR => locators.add(&mut d.unicast_locators, &mut r)?,
                pid::MULTICAST_LOCATOR => locators.add(&mut d.multicast_locators, &mut r)?,
                pid::EXPECTS_INLINE_QOS => d.expects_inline_qos = r.bool()?,
                pid::TYPE_INFORMATION => d.type_information = Some(r.rest(limits)?),
                pid::TYPE_MAX_SIZE_SERIALIZED => d.type_max_serialized_size = Some(r.u32()?),
                pid::ENTITY_NAME => d.entity_name = Some(r.string(limits)?),
                other => {
                    if !qos.read(&mut r, other, limits)? {
                        skip_unknown(other)?;
                        d.unknown_parameters = d.unknown_parameters.saturating_add(1);
                    }
                }
            }
        }
        d.qos = qos.finish();
        d.topic_name = topic_name.ok_or(DiscoveryError::Missing { pid: pid::TOPIC_NAME })?;
        d.type_name = type_name.ok_or(DiscoveryError::Missing { pid: pid::TYPE_NAME })?;
        d.dropped_locators = locators.dropped;
        Ok(d)
    }

    /// Reads the data from a DATA's serialized payload: PL_CDR_BE or PL_CDR_LE, then the list.
    pub fn parse_payload(
        serialized: &[u8],
        key_hash: Option<[u8; 16]>,
        limits: &Limits,
    ) -> Result<Self, DiscoveryError> {
        Self::parse(&super::payload_list(serialized, limits)?, key_hash, limits)
    }

    /// Writes the parameters: standard PIDs only, little-endian, every QoS policy's fixed-size
    /// value and the non-empty sequences; no sentinel (the caller finishes the list).
    pub fn emit(&self, w: &mut ParameterWriter<'_>) -> Result<(), BufferTooSmall> {
        put::guid(w, pid::ENDPOINT_GUID, self.guid)?;
        if let Some(g) = self.participant_guid {
            put::guid(w, pid::PARTICIPANT_GUID, g)?;
        }
        put::string(w, pid::TOPIC_NAME, &self.topic_name)?;
        put::string(w, pid::TYPE_NAME, &self.type_name)?;
        self.qos.emit(w)?;
        put::locators(w, pid::UNICAST_LOCATOR, &self.unicast_locators)?;
        put::locators(w, pid::MULTICAST_LOCATOR, &self.multicast_locators)?;
        if self.expects_inline_qos {
            put::bool(w, pid::EXPECTS_INLINE_QOS, true)?;
        }
        if let Some(info) = &self.type_information {
            w.push(pid::TYPE_INFORMATION, info)?;
        }
        if let Some(size) = self.type_max_serialized_size {
            put::u32(w, pid::TYPE_MAX_SIZE_SERIALIZED, size)?;
        }
        if let Some(name) = &self.entity_name {
            put::string(w, pid::ENTITY_NAME, name)?;
        }
        Ok(())
    }

    /// Writes a DATA's serialized payload: PL_CDR_LE (00 03 00 00), the list, the sentinel.
    /// Returns the bytes written.
    pub fn emit_payload(&self, buf: &mut [u8]) -> Result<usize, BufferTooSmall> {
        super::emit_payload(buf, |w| self.emit(w))
    }
}
