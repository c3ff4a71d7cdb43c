//! The field-level tools every submessage family shares: `Reader`, which reads a body's fields
//! in order in the submessage's byte order, each checked to be there, and the little-endian
//! writers of sequence numbers, bitmap words and flag bits that emission uses.

use super::FLAG_E;
use crate::types::{EntityId, FragmentNumberSet, Locator, SequenceNumber, SequenceNumberSet, SetError};
use crate::wire::{Endianness, LocatorList, ParameterList, WireError};
use robowire_core::BufferTooSmall;
use robowire_core::le::LeWriter;

/// Reads a submessage body's fields in order, each checked to be there.
pub(super) struct Reader<'a> {
    pub(super) kind: u8,
    body: &'a [u8],
    at: usize,
    e: Endianness,
}

impl<'a> Reader<'a> {
    pub(super) fn new(kind: u8, flags: u8, body: &'a [u8]) -> Self {
        let e = if flags & FLAG_E != 0 { Endianness::Little } else { Endianness::Big };
        Self { kind, body, at: 0, e }
    }

    fn too_short(&self, needed: usize) -> WireError {
        WireError::SubmessageTooShort { kind: self.kind, length: self.body.len(), needed }
    }

    fn bytes(&mut self, n: usize) -> Result<&'a [u8], WireError> {
        let end = self.at.saturating_add(n);
        let b = self.body.get(self.at..end).ok_or_else(|| self.too_short(end))?;
        self.at = end;
        Ok(b)
    }

    pub(super) fn array<const N: usize>(&mut self) -> Result<[u8; N], WireError> {
        let b = self.bytes(N)?;
        <[u8; N]>::try_from(b).map_err(|_| self.too_short(self.at))
    }

    pub(super) fn u16(&mut self) -> Result<u16, WireError> {
        let b = self.array()?;
        Ok(match self.e {
            Endianness::Little => u16::from_le_bytes(b),
            Endianness::Big => u16::from_be_bytes(b),
        })
    }

    pub(super) fn u32(&mut self) -> Result<u32, WireError> {
        let b = self.array()?;
        Ok(match self.e {
            Endianness::Little => u32::from_le_bytes(b),
            Endianness::Big => u32::from_be_bytes(b),
        })
    }

    pub(super) fn i32(&mut self) -> Result<i32, WireError> {
        self.u32().map(|v| v as i32)
    }

    pub(super) fn entity(&mut self) -> Result<EntityId, WireError> {
        self.array().map(EntityId)
    }

    pub(super) fn sn(&mut self) -> Result<SequenceNumber, WireError> {
        let high = self.i32()?;
        Ok(SequenceNumber::from_parts(high, self.u32()?))
    }

    /// A sequence number that names a sample (≥ 1).
    pub(super) fn sample_sn(&mut self) -> Result<SequenceNumber, WireError> {
        let sn = self.sn()?;
        if !sn.is_valid() {
            return Err(WireError::SequenceNumber { kind: self.kind, sn: sn.0 });
        }
        Ok(sn)
    }

    fn words(&mut self, num_bits: u32) -> Result<[u32; 8], WireError> {
        let mut words = [0u32; 8];
        for w in words.iter_mut().take(num_bits.div_ceil(32) as usize) {
            *w = self.u32()?;
        }
        Ok(words)
    }

    pub(super) fn sn_set(&mut self) -> Result<SequenceNumberSet, WireError> {
        let base = self.sn()?;
        let num_bits = self.u32()?;
        let refused = WireError::SequenceNumberSet { base: base.0, num_bits };
        if num_bits > 256 {
            return Err(refused);
        }
        let words = self.words(num_bits)?;
        SequenceNumberSet::from_words(base, num_bits, &words).map_err(|_| refused)
    }

    pub(super) fn fragment_set(&mut self) -> Result<FragmentNumberSet, WireError> {
        let base = self.u32()?;
        let num_bits = self.u32()?;
        let refused = WireError::FragmentNumberSet { base, num_bits };
        if num_bits > 256 {
            return Err(refused);
        }
        let words = self.words(num_bits)?;
        FragmentNumberSet::from_words(base, num_bits, &words).map_err(|e| match e {
            SetError::Base => WireError::FragmentNumberZero { kind: self.kind },
            SetError::NumBits | SetError::Overflow => refused,
        })
    }

    pub(super) fn locators(&mut self) -> Result<LocatorList<'a>, WireError> {
        let count = self.u32()?;
        let available = self.body.len().saturating_sub(self.at);
        let len = u64::from(count) * 24;
        if len > available as u64 {
            return Err(WireError::LocatorCount { count, available });
        }
        Ok(LocatorList { bytes: self.bytes(len as usize)?, endianness: self.e })
    }

    pub(super) fn udpv4(&mut self) -> Result<Locator, WireError> {
        let address = self.u32()?;
        let port = self.u32()?;
        let mut a = [0; 16];
        if let Some(last) = a.get_mut(12..) {
            last.copy_from_slice(&address.to_be_bytes());
        }
        Ok(Locator { kind: Locator::KIND_UDPV4, port, address: a })
    }

    /// Moves to `4 + octets_to_inline_qos`, which must be past the `fixed` fields and in the body.
    pub(super) fn seek_inline_qos(&mut self, octets: u16, fixed: usize) -> Result<(), WireError> {
        let at = 4 + usize::from(octets);
        if at < fixed || at > self.body.len() {
            return Err(WireError::InlineQosOffset { kind: self.kind, octets, length: self.body.len() });
        }
        self.at = at;
        Ok(())
    }

    pub(super) fn inline_qos(&mut self, present: bool) -> Result<Option<ParameterList<'a>>, WireError> {
        if !present {
            return Ok(None);
        }
        let (list, used) = ParameterList::parse(self.rest(), self.e)?;
        self.at = self.at.saturating_add(used);
        Ok(Some(list))
    }

    pub(super) fn rest(&self) -> &'a [u8] {
        self.body.get(self.at..).unwrap_or_default()
    }
}

pub(super) fn put_sn(w: &mut LeWriter<'_>, sn: SequenceNumber) -> Result<(), BufferTooSmall> {
    let (high, low) = sn.to_parts();
    w.put_bytes(&high.to_le_bytes())?;
    w.put_u32(low)
}

pub(super) fn put_words(w: &mut LeWriter<'_>, words: &[u32]) -> Result<(), BufferTooSmall> {
    words.iter().try_for_each(|&v| w.put_u32(v))
}

pub(super) fn flag(set: bool, bit: u8) -> u8 {
    if set { bit } else { 0 }
}
