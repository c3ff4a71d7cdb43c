//! Discovery data: what SPDP says about a participant ([`ParticipantData`]) and SEDP about a
//! writer or reader ([`EndpointData`]), parsed from and emitted into parameter lists, and the
//! DDS QoS policies they carry with the Request/Offered matching rules ([`check_match`]).
//!
//! Parsing follows the wire's rules: values in the list's endianness, unknown PIDs skipped and
//! counted, an unknown PID with the must-understand bit (0x4000) refuses the whole data,
//! vendor-specific PIDs (0x8000) skipped. Every string, octet sequence and sequence count read
//! from the wire is checked against the value's length and [`Limits::parameter_bytes`] before
//! anything is allocated; locators beyond [`Limits::locators_per_endpoint`] are dropped and
//! counted. Emission is little-endian and writes only standard PIDs.
//!
//! Value encodings (RTPS 2.5 §9.3, §9.6; checked against CycloneDDS `ddsi_plist.c` and Fast DDS
//! `QosPoliciesSerializer.hpp`): `Duration_t` is `i32` seconds + `u32` 1/2³² fractions;
//! reliability kind 1 = best effort, 2 = reliable.
//!
//! [`Limits::parameter_bytes`]: crate::Limits::parameter_bytes
//! [`Limits::locators_per_endpoint`]: crate::Limits::locators_per_endpoint

mod error;
mod matching;
mod qos;
mod sedp;
mod spdp;

pub use error::DiscoveryError;
pub use matching::{QosMismatch, check_match};
pub use qos::{
    DATA_REPRESENTATION_XCDR1, DATA_REPRESENTATION_XCDR2, DATA_REPRESENTATION_XML, DestinationOrder, Durability,
    History, Liveliness, LivelinessKind, Ownership, OwnershipKind, Qos, Reliability, ReliabilityKind,
};
pub use sedp::EndpointData;
pub use spdp::{BuiltinEndpointSet, ParticipantData};

use crate::Limits;
use crate::types::{DdsDuration, Guid, Locator};
use crate::wire::{Endianness, Parameter, ParameterList, ParameterWriter};
use alloc::string::String;
use alloc::vec::Vec;
use robowire_core::BufferTooSmall;

/// Parameter ids this module reads and writes (RTPS 2.5 table 9.13, DDS-XTypes 7.6.3).
pub(crate) mod pid {
    pub(crate) const PARTICIPANT_LEASE_DURATION: u16 = 0x0002;
    pub(crate) const TOPIC_NAME: u16 = 0x0005;
    pub(crate) const OWNERSHIP_STRENGTH: u16 = 0x0006;
    pub(crate) const TYPE_NAME: u16 = 0x0007;
    pub(crate) const DOMAIN_ID: u16 = 0x000f;
    pub(crate) const PROTOCOL_VERSION: u16 = 0x0015;
    pub(crate) const VENDOR_ID: u16 = 0x0016;
    pub(crate) const RELIABILITY: u16 = 0x001a;
    pub(crate) const LIVELINESS: u16 = 0x001b;
    pub(crate) const DURABILITY: u16 = 0x001d;
    pub(crate) const OWNERSHIP: u16 = 0x001f;
    pub(crate) const DEADLINE: u16 = 0x0023;
    pub(crate) const DESTINATION_ORDER: u16 = 0x0025;
    pub(crate) const LATENCY_BUDGET: u16 = 0x0027;
    pub(crate) const PARTITION: u16 = 0x0029;
    pub(crate) const LIFESPAN: u16 = 0x002b;
    pub(crate) const USER_DATA: u16 = 0x002c;
    pub(crate) const GROUP_DATA: u16 = 0x002d;
    pub(crate) const TOPIC_DATA: u16 = 0x002e;
    pub(crate) const UNICAST_LOCATOR: u16 = 0x002f;
    pub(crate) const MULTICAST_LOCATOR: u16 = 0x0030;
    pub(crate) const DEFAULT_UNICAST_LOCATOR: u16 = 0x0031;
    pub(crate) const METATRAFFIC_UNICAST_LOCATOR: u16 = 0x0032;
    pub(crate) const METATRAFFIC_MULTICAST_LOCATOR: u16 = 0x0033;
    pub(crate) const PARTICIPANT_MANUAL_LIVELINESS_COUNT: u16 = 0x0034;
    pub(crate) const HISTORY: u16 = 0x0040;
    pub(crate) const EXPECTS_INLINE_QOS: u16 = 0x0043;
    pub(crate) const DEFAULT_MULTICAST_LOCATOR: u16 = 0x0048;
    pub(crate) const PARTICIPANT_GUID: u16 = 0x0050;
    pub(crate) const BUILTIN_ENDPOINT_SET: u16 = 0x0058;
    pub(crate) const ENDPOINT_GUID: u16 = 0x005a;
    pub(crate) const TYPE_MAX_SIZE_SERIALIZED: u16 = 0x0060;
    pub(crate) const ENTITY_NAME: u16 = 0x0062;
    pub(crate) const DATA_REPRESENTATION: u16 = 0x0073;
    pub(crate) const TYPE_INFORMATION: u16 = 0x0075;
    pub(crate) const DOMAIN_TAG: u16 = 0x4014;

    /// The vendor-specific bit: the PID means something only to its vendor.
    pub(crate) const VENDOR_SPECIFIC: u16 = 0x8000;
    /// The must-understand bit: a receiver that does not know the PID ignores the whole data.
    pub(crate) const MUST_UNDERSTAND: u16 = 0x4000;
}

/// PL_CDR_BE: a big-endian parameter list payload.
pub(crate) const PL_CDR_BE: [u8; 2] = [0x00, 0x02];
/// PL_CDR_LE: a little-endian parameter list payload.
pub(crate) const PL_CDR_LE: [u8; 2] = [0x00, 0x03];

/// A PID this module does not read: `Ok` (to count it) unless it must be understood.
pub(crate) fn skip_unknown(pid: u16) -> Result<(), DiscoveryError> {
    if pid & pid::VENDOR_SPECIFIC == 0 && pid & pid::MUST_UNDERSTAND != 0 {
        return Err(DiscoveryError::MustUnderstand { pid });
    }
    Ok(())
}

/// The parameter list inside a DATA's serialized payload (4-byte encapsulation header first).
pub(crate) fn payload_list<'a>(serialized: &'a [u8], limits: &Limits) -> Result<ParameterList<'a>, DiscoveryError> {
    let (header, body) =
        serialized.split_at_checked(4).ok_or(DiscoveryError::ShortPayload { length: serialized.len() })?;
    let endianness = match [header[0], header[1]] {
        PL_CDR_BE => Endianness::Big,
        PL_CDR_LE => Endianness::Little,
        other => return Err(DiscoveryError::Encapsulation(other)),
    };
    let (list, used) = ParameterList::parse(body, endianness)?;
    if used > limits.parameter_list_bytes {
        return Err(DiscoveryError::ListTooLong { length: used, limit: limits.parameter_list_bytes });
    }
    Ok(list)
}

/// Writes PL_CDR_LE, the list `emit` writes and the sentinel; returns the bytes written.
pub(crate) fn emit_payload(
    buf: &mut [u8],
    emit: impl FnOnce(&mut ParameterWriter<'_>) -> Result<(), BufferTooSmall>,
) -> Result<usize, BufferTooSmall> {
    let available = buf.len();
    let (header, body) = buf.split_at_mut_checked(4).ok_or(BufferTooSmall { needed: 4, available })?;
    header.copy_from_slice(&[PL_CDR_LE[0], PL_CDR_LE[1], 0, 0]);
    let mut w = ParameterWriter::new(body);
    emit(&mut w).map_err(|e| BufferTooSmall { needed: e.needed + 4, available })?;
    let len = w.finish().map_err(|e| BufferTooSmall { needed: e.needed + 4, available })?;
    Ok(len + 4)
}

/// Locator lists of one entity, bounded together by [`Limits::locators_per_endpoint`].
pub(crate) struct LocatorBudget {
    left: usize,
    /// Locators dropped for the bound.
    pub(crate) dropped: u32,
}

impl LocatorBudget {
    pub(crate) fn new(limits: &Limits) -> Self {
        Self { left: limits.locators_per_endpoint, dropped: 0 }
    }

    /// Reads a locator parameter into `list`, or counts it dropped when the budget is spent.
    pub(crate) fn add(&mut self, list: &mut Vec<Locator>, r: &mut ValueReader<'_>) -> Result<(), DiscoveryError> {
        let locator = r.locator()?;
        if self.left == 0 {
            self.dropped = self.dropped.saturating_add(1);
        } else {
            self.left -= 1;
            list.push(locator);
        }
        Ok(())
    }
}

/// Reads one parameter's value in the list's byte order; every read is bounds-checked and
/// alignment is relative to the value's start (values start 4-aligned in the payload).
pub(crate) struct ValueReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    big: bool,
    pid: u16,
}

impl<'a> ValueReader<'a> {
    pub(crate) fn new(p: Parameter<'a>, endianness: Endianness) -> Self {
        Self { bytes: p.value, pos: 0, big: endianness == Endianness::Big, pid: p.pid }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], DiscoveryError> {
        let end = self.pos.saturating_add(n);
        let out = self.bytes.get(self.pos..end).ok_or(DiscoveryError::ValueLength {
            pid: self.pid,
            expected: end,
            found: self.bytes.len(),
        })?;
        self.pos = end;
        Ok(out)
    }

    fn take4(&mut self) -> Result<[u8; 4], DiscoveryError> {
        let b = self.take(4)?;
        Ok([b[0], b[1], b[2], b[3]])
    }

    fn align(&mut self, n: usize) {
        self.pos = self.pos.next_multiple_of(n);
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    pub(crate) fn u8(&mut self) -> Result<u8, DiscoveryError> {
        Ok(self.take(1)?[0])
    }

    pub(crate) fn bool(&mut self) -> Result<bool, DiscoveryError> {
        Ok(self.u8()? != 0)
    }

    pub(crate) fn u32(&mut self) -> Result<u32, DiscoveryError> {
        self.align(4);
        let b = self.take4()?;
        Ok(if self.big { u32::from_be_bytes(b) } else { u32::from_le_bytes(b) })
    }

    pub(crate) fn i32(&mut self) -> Result<i32, DiscoveryError> {
        Ok(self.u32()? as i32)
    }

    pub(crate) fn i16(&mut self) -> Result<i16, DiscoveryError> {
        self.align(2);
        let b = self.take(2)?;
        let b = [b[0], b[1]];
        Ok(if self.big { i16::from_be_bytes(b) } else { i16::from_le_bytes(b) })
    }

    pub(crate) fn duration(&mut self) -> Result<DdsDuration, DiscoveryError> {
        Ok(DdsDuration { seconds: self.i32()?, fraction: self.u32()? })
    }

    pub(crate) fn guid(&mut self) -> Result<Guid, DiscoveryError> {
        let b = self.take(16)?;
        let mut g = [0; 16];
        g.copy_from_slice(b);
        Ok(Guid::from_bytes(g))
    }

    pub(crate) fn locator(&mut self) -> Result<Locator, DiscoveryError> {
        let kind = self.i32()?;
        let port = self.u32()?;
        let mut address = [0; 16];
        address.copy_from_slice(self.take(16)?);
        Ok(Locator { kind, port, address })
    }

    /// A kind enumerated as `u32`, checked to be below `count`.
    pub(crate) fn kind(&mut self, count: u32) -> Result<u32, DiscoveryError> {
        let k = self.u32()?;
        if k >= count {
            return Err(DiscoveryError::InvalidValue { pid: self.pid });
        }
        Ok(k)
    }

    /// A CDR string: `u32` length (NUL included), bytes, NUL. The length is checked against the
    /// value and the limit before anything is allocated; a zero length reads as "".
    pub(crate) fn string(&mut self, limits: &Limits) -> Result<String, DiscoveryError> {
        let length = self.u32()?;
        let n = length as usize;
        if n > self.remaining() {
            return Err(DiscoveryError::StringLength { pid: self.pid, length });
        }
        if n > limits.parameter_bytes {
            return Err(DiscoveryError::TooLong { pid: self.pid, length: n, limit: limits.parameter_bytes });
        }
        let bytes = self.take(n)?;
        let text = match bytes.split_last() {
            None => &[][..],
            Some((0, text)) => text,
            Some(_) => return Err(DiscoveryError::StringLength { pid: self.pid, length }),
        };
        let text = core::str::from_utf8(text).map_err(|_| DiscoveryError::NotUtf8 { pid: self.pid })?;
        Ok(String::from(text))
    }

    /// A CDR `sequence<octet>`: `u32` count and bytes, checked before allocating.
    pub(crate) fn octets(&mut self, limits: &Limits) -> Result<Vec<u8>, DiscoveryError> {
        let count = self.u32()? as usize;
        self.check_count(count, 1, limits)?;
        Ok(self.take(count)?.to_vec())
    }

    /// A CDR `sequence<string>`.
    pub(crate) fn strings(&mut self, limits: &Limits) -> Result<Vec<String>, DiscoveryError> {
        let count = self.u32()? as usize;
        // Each string takes at least its 4-byte length.
        self.check_count(count, 4, limits)?;
        (0..count).map(|_| self.string(limits)).collect()
    }

    /// A CDR `sequence<short>`.
    pub(crate) fn i16s(&mut self, limits: &Limits) -> Result<Vec<i16>, DiscoveryError> {
        let count = self.u32()? as usize;
        self.check_count(count, 2, limits)?;
        (0..count).map(|_| self.i16()).collect()
    }

    /// All the value's bytes (a value passed through), bounded by the limit.
    pub(crate) fn rest(&mut self, limits: &Limits) -> Result<Vec<u8>, DiscoveryError> {
        let n = self.remaining();
        if n > limits.parameter_bytes {
            return Err(DiscoveryError::TooLong { pid: self.pid, length: n, limit: limits.parameter_bytes });
        }
        Ok(self.take(n)?.to_vec())
    }

    /// `count` elements of at least `min_size` bytes each fit in the value and the limit.
    fn check_count(&self, count: usize, min_size: usize, limits: &Limits) -> Result<(), DiscoveryError> {
        let bytes = count.saturating_mul(min_size);
        if bytes > self.remaining() {
            return Err(DiscoveryError::ValueLength {
                pid: self.pid,
                expected: self.pos.saturating_add(bytes),
                found: self.bytes.len(),
            });
        }
        if bytes > limits.parameter_bytes {
            return Err(DiscoveryError::TooLong { pid: self.pid, length: bytes, limit: limits.parameter_bytes });
        }
        Ok(())
    }
}

/// Little-endian value writers over [`ParameterWriter`].
pub(crate) mod put {
    use super::*;

    pub(crate) fn u32(w: &mut ParameterWriter<'_>, pid: u16, v: u32) -> Result<(), BufferTooSmall> {
        w.push(pid, &v.to_le_bytes())
    }

    pub(crate) fn i32(w: &mut ParameterWriter<'_>, pid: u16, v: i32) -> Result<(), BufferTooSmall> {
        w.push(pid, &v.to_le_bytes())
    }

    pub(crate) fn bool(w: &mut ParameterWriter<'_>, pid: u16, v: bool) -> Result<(), BufferTooSmall> {
        w.push(pid, &[u8::from(v)])
    }

    pub(crate) fn duration_bytes(d: DdsDuration) -> [u8; 8] {
        let mut b = [0; 8];
        b[..4].copy_from_slice(&d.seconds.to_le_bytes());
        b[4..].copy_from_slice(&d.fraction.to_le_bytes());
        b
    }

    pub(crate) fn duration(w: &mut ParameterWriter<'_>, pid: u16, d: DdsDuration) -> Result<(), BufferTooSmall> {
        w.push(pid, &duration_bytes(d))
    }

    /// A kind (`u32`) followed by a duration.
    pub(crate) fn kind_duration(
        w: &mut ParameterWriter<'_>,
        pid: u16,
        kind: u32,
        d: DdsDuration,
    ) -> Result<(), BufferTooSmall> {
        let mut b = [0; 12];
        b[..4].copy_from_slice(&kind.to_le_bytes());
        b[4..].copy_from_slice(&duration_bytes(d));
        w.push(pid, &b)
    }

    pub(crate) fn guid(w: &mut ParameterWriter<'_>, pid: u16, g: Guid) -> Result<(), BufferTooSmall> {
        w.push(pid, &g.to_bytes())
    }

    pub(crate) fn locators(w: &mut ParameterWriter<'_>, pid: u16, ls: &[Locator]) -> Result<(), BufferTooSmall> {
        for l in ls {
            let mut b = [0; 24];
            b[..4].copy_from_slice(&l.kind.to_le_bytes());
            b[4..8].copy_from_slice(&l.port.to_le_bytes());
            b[8..].copy_from_slice(&l.address);
            w.push(pid, &b)?;
        }
        Ok(())
    }

    /// Bytes of a CDR string of `s` at a 4-aligned offset (length, bytes, NUL).
    fn string_len(s: &str) -> usize {
        4 + s.len() + 1
    }

    fn write_string(dst: &mut [u8], s: &str) -> usize {
        let n = s.len() + 1;
        dst[..4].copy_from_slice(&(n as u32).to_le_bytes());
        dst[4..4 + s.len()].copy_from_slice(s.as_bytes());
        dst[4 + s.len()] = 0;
        4 + n
    }

    pub(crate) fn string(w: &mut ParameterWriter<'_>, pid: u16, s: &str) -> Result<(), BufferTooSmall> {
        w.push_with(pid, string_len(s), |dst| {
            write_string(dst, s);
        })
    }

    pub(crate) fn strings(w: &mut ParameterWriter<'_>, pid: u16, ss: &[String]) -> Result<(), BufferTooSmall> {
        let mut len = 4usize;
        for s in ss {
            len = len.next_multiple_of(4) + string_len(s);
        }
        w.push_with(pid, len, |dst| {
            dst[..4].copy_from_slice(&(ss.len() as u32).to_le_bytes());
            let mut pos = 4usize;
            for s in ss {
                let aligned = pos.next_multiple_of(4);
                dst[pos..aligned].fill(0);
                pos = aligned + write_string(&mut dst[aligned..], s);
            }
        })
    }

    pub(crate) fn octets(w: &mut ParameterWriter<'_>, pid: u16, v: &[u8]) -> Result<(), BufferTooSmall> {
        w.push_with(pid, 4 + v.len(), |dst| {
            dst[..4].copy_from_slice(&(v.len() as u32).to_le_bytes());
            dst[4..].copy_from_slice(v);
        })
    }

    pub(crate) fn i16s(w: &mut ParameterWriter<'_>, pid: u16, v: &[i16]) -> Result<(), BufferTooSmall> {
        w.push_with(pid, 4 + 2 * v.len(), |dst| {
            dst[..4].copy_from_slice(&(v.len() as u32).to_le_bytes());
            for (d, x) in dst[4..].chunks_exact_mut(2).zip(v) {
                d.copy_from_slice(&x.to_le_bytes());
            }
        })
    }
}
