//! One sample put back together from its DATA_FRAG fragments, in a buffer of the announced
//! sample size (checked against `Limits::reassembly_bytes` before anything is allocated) and a
//! bitmap of the fragments received.

use alloc::vec::Vec;

use crate::Time;
use crate::types::SequenceNumber;
use crate::wire::DataFrag;

/// Why a fragment was not taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ReassemblyError {
    /// The announced sample is larger than the limit.
    #[error("a fragmented sample of {size} bytes is larger than the limit of {limit}")]
    TooLarge {
        /// The sample size announced.
        size: u32,
        /// The limit.
        limit: usize,
    },
    /// A fragment disagrees with the sample's earlier fragments (sizes differ).
    #[error("a fragment disagrees with the sample's earlier fragments")]
    Inconsistent,
}

/// A sample in reassembly.
#[derive(Debug, Clone)]
pub struct Reassembly {
    sequence: SequenceNumber,
    sample_size: u32,
    fragment_size: u16,
    data: Vec<u8>,
    received: Vec<u32>,
    missing: u32,
    expires_at: Time,
}

impl Reassembly {
    /// Starts reassembling the sample `frag` belongs to, reusing `buffer`.
    pub fn new(frag: &DataFrag<'_>, limit: usize, expires_at: Time, buffer: Vec<u8>) -> Result<Self, ReassemblyError> {
        let size = usize::try_from(frag.sample_size).unwrap_or(usize::MAX);
        if size > limit {
            return Err(ReassemblyError::TooLarge { size: frag.sample_size, limit });
        }
        let total = frag.total_fragments();
        let mut data = buffer;
        data.clear();
        data.resize(size, 0);
        let received = alloc::vec![0; total.div_ceil(32) as usize];
        Ok(Self {
            sequence: frag.writer_sn,
            sample_size: frag.sample_size,
            fragment_size: frag.fragment_size,
            data,
            received,
            missing: total,
            expires_at,
        })
    }

    /// Bytes its buffer holds (the announced sample size).
    pub fn bytes(&self) -> usize {
        self.data.len()
    }

    /// The sample's number.
    pub fn sequence(&self) -> SequenceNumber {
        self.sequence
    }

    /// When it is given up.
    pub fn expires_at(&self) -> Time {
        self.expires_at
    }

    /// Fragments of the whole sample.
    pub fn total_fragments(&self) -> u32 {
        self.sample_size.div_ceil(u32::from(self.fragment_size))
    }

    /// Whether fragment `n` (1-based) is here.
    pub fn has(&self, n: u32) -> bool {
        let i = n.wrapping_sub(1);
        self.received.get((i / 32) as usize).is_some_and(|w| w & (1 << (i % 32)) != 0)
    }

    /// Takes the fragments of `frag` (the wire layer checked that they lie inside the sample);
    /// true once every fragment is here.
    pub fn insert(&mut self, frag: &DataFrag<'_>) -> Result<bool, ReassemblyError> {
        if frag.sample_size != self.sample_size || frag.fragment_size != self.fragment_size {
            return Err(ReassemblyError::Inconsistent);
        }
        let size = usize::from(self.fragment_size);
        for k in 0..u32::from(frag.fragments_in_submessage) {
            let n = frag.fragment_starting_num.saturating_add(k);
            let start = (n as usize).saturating_sub(1).saturating_mul(size);
            let end = start.saturating_add(size).min(self.data.len());
            let from = (k as usize).saturating_mul(size);
            if self.has(n) {
                continue;
            }
            let (Some(dst), Some(src)) = (self.data.get_mut(start..end), frag.payload.get(from..from + (end - start)))
            else {
                return Err(ReassemblyError::Inconsistent);
            };
            {
                dst.copy_from_slice(src);
                let i = n - 1;
                if let Some(w) = self.received.get_mut((i / 32) as usize) {
                    *w |= 1 << (i % 32);
                    self.missing -= 1;
                }
            }
        }
        Ok(self.missing == 0)
    }

    /// The missing fragments from the first missing one, as many as a NACK_FRAG holds.
    pub fn missing(&self, up_to: u32) -> Option<crate::types::FragmentNumberSet> {
        let last = up_to.min(self.total_fragments());
        let first = (1..=last).find(|&n| !self.has(n))?;
        let mut set = crate::types::FragmentNumberSet::new(first, (last - first + 1).min(256)).ok()?;
        for n in first..=last.min(first + 255) {
            if !self.has(n) {
                set.insert(n);
            }
        }
        Some(set)
    }

    /// The whole sample (once complete) and its buffer back.
    pub fn into_data(self) -> Vec<u8> {
        self.data
    }
}
