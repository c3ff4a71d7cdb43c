//! Why a datagram, submessage or parameter is refused, and counters of refusals by kind.

/// Why bytes are not valid RTPS (or exceed what a field may hold). `Copy`, no allocation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum WireError {
    /// Shorter than the 20-byte header, or not "RTPS".
    #[error("not an RTPS message")]
    NotRtps,
}

/// A refusal's kind without its values: an index into [`WireErrorCounts`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum WireErrorKind {
    /// [`WireError::NotRtps`].
    NotRtps,
}

impl WireError {
    /// The kind, for counting.
    pub fn kind(&self) -> WireErrorKind {
        match self {
            Self::NotRtps => WireErrorKind::NotRtps,
        }
    }
}

/// Refusals counted by kind.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct WireErrorCounts {
    counts: [u64; 1],
}

impl WireErrorCounts {
    /// Counts one refusal.
    pub fn count(&mut self, e: WireError) {
        self.counts[e.kind() as usize] += 1;
    }
}
