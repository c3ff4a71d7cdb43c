//! Writers and readers as sans-IO state machines: the history a writer keeps and what each
//! matched reader has acknowledged (HEARTBEAT, ACKNACK, GAP, NACK_FRAG), and what a reader has
//! received from each matched writer (ordering, acknowledgement, reassembly of DATA_FRAG).
//!
//! The [`Participant`](crate::participant::Participant) owns them, routes submessages to them
//! and builds datagrams from what they say is due; their memory is bounded by [`Limits`].
//!
//! [`Limits`]: crate::Limits

mod history;
mod reader;
mod reassembly;
mod writer;

pub use history::{Change, ChangeKind, History};
pub use reader::ReaderCounters;
pub(crate) use reader::{Delivery, Reader, ReaderConfig, WriterProxy};
pub use reassembly::{Reassembly, ReassemblyError};
pub use writer::WriterCounters;
pub(crate) use writer::{ReaderProxy, Writer, WriterConfig};

use crate::types::{Guid, SequenceNumber, Timestamp};

/// Names a sample: its writer and sequence number (DDS `SampleIdentity`; what a reply names in
/// its related sample identity).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SampleIdentity {
    /// The writer.
    pub writer: Guid,
    /// The sample's number.
    pub sequence: SequenceNumber,
}

impl SampleIdentity {
    /// Bytes of the inline QoS value (GUID then high and low words).
    pub const LEN: usize = 24;
}

/// What a write carries beside its payload.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// The source timestamp (an INFO_TS before the DATA); wall clock, supplied by the caller.
    pub source_timestamp: Option<Timestamp>,
    /// The sample this one answers (inline QoS PID_RELATED_SAMPLE_IDENTITY, both ids).
    pub related: Option<SampleIdentity>,
    /// The instance's key hash (inline QoS PID_KEY_HASH), for keyed topics.
    pub key_hash: Option<[u8; 16]>,
}

/// What a reader learns about a received sample besides its payload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleInfo {
    /// The local reader it was delivered to.
    pub reader: crate::types::EntityId,
    /// The writer.
    pub writer: Guid,
    /// Its sequence number.
    pub sequence: SequenceNumber,
    /// The source timestamp, if the writer sent one.
    pub source_timestamp: Option<Timestamp>,
    /// The sample it answers, if the writer named one.
    pub related: Option<SampleIdentity>,
    /// The key hash, if sent.
    pub key_hash: Option<[u8; 16]>,
    /// PID_STATUS_INFO: 1 disposed, 2 unregistered (0 for an ordinary sample).
    pub status_info: u32,
}

/// Why a write was refused. Nothing was queued or sent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// No local writer with that id.
    #[error("no local writer {0:?}")]
    UnknownWriter(crate::types::EntityId),
    /// The payload is larger than `Limits::sample_bytes`.
    #[error("a sample of {len} bytes is larger than the limit of {limit}")]
    TooLarge {
        /// The payload's length.
        len: usize,
        /// The limit.
        limit: usize,
    },
    /// A reliable writer's history is full of samples some reader has not acknowledged (KEEP_ALL,
    /// or KEEP_LAST with `WriteMode::RefuseWhenFull`).
    #[error("the writer's history is full of unacknowledged samples ({depth})")]
    HistoryFull {
        /// The history's depth.
        depth: usize,
    },
    /// The writer has written `i64::MAX` samples.
    #[error("sequence numbers exhausted")]
    SequenceNumbersExhausted,
    /// A payload whose length is not a multiple of 4: RTPS submessages are 4-byte aligned
    /// (CycloneDDS drops such a DATA). Pad it, saying so in the encapsulation options' last two
    /// bits (XTypes 7.6.3.1.2).
    #[error("a payload of {len} bytes is not padded to a multiple of 4")]
    Unaligned {
        /// The payload's length.
        len: usize,
    },
    /// The caller's buffer cannot hold the datagram.
    #[error("the datagram buffer is too small")]
    BufferTooSmall,
}

/// What a write does when a reliable writer's history is full of unacknowledged samples.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum WriteMode {
    /// KEEP_LAST: the oldest sample is removed (readers that miss it get a GAP), counted.
    #[default]
    ReplaceOldest,
    /// The write is refused with [`WriteError::HistoryFull`].
    RefuseWhenFull,
}
