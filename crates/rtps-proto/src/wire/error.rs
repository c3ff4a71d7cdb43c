//! Why a datagram, submessage or parameter is refused, and counters of refusals by kind.

/// Why bytes are not valid RTPS (or exceed what a field may hold). `Copy`, no allocation.
///
/// `kind` fields are submessage ids (0x15 DATA, 0x16 DATA_FRAG, …); sequence numbers are the
/// wire's 64-bit values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum WireError {
    /// Shorter than the 20-byte header, or not "RTPS".
    #[error("not an RTPS message")]
    NotRtps,
    /// A protocol major version other than 2.
    #[error("RTPS version {major}.{minor} (only 2.x is spoken)")]
    Version {
        /// Major version.
        major: u8,
        /// Minor version.
        minor: u8,
    },
    /// Fewer than the 4 bytes of a submessage header left after the last submessage.
    #[error("{available} trailing bytes, too few for a submessage header")]
    SubmessageHeader {
        /// Bytes left.
        available: usize,
    },
    /// octetsToNextHeader past the end of the datagram.
    #[error("submessage 0x{kind:02x} of {length} bytes, but only {available} bytes follow its header")]
    SubmessageLength {
        /// Submessage id.
        kind: u8,
        /// octetsToNextHeader.
        length: u16,
        /// Bytes after the submessage header.
        available: usize,
    },
    /// A body shorter than the submessage's fields (fixed fields, a set's words, a locator).
    #[error("submessage 0x{kind:02x} body of {length} bytes, its fields need {needed}")]
    SubmessageTooShort {
        /// Submessage id.
        kind: u8,
        /// Body length.
        length: usize,
        /// Bytes the fields read so far need.
        needed: usize,
    },
    /// DATA or DATA_FRAG octetsToInlineQos pointing inside the fixed fields or past the body.
    #[error("submessage 0x{kind:02x} octetsToInlineQos {octets} outside its body of {length} bytes")]
    InlineQosOffset {
        /// Submessage id.
        kind: u8,
        /// octetsToInlineQos.
        octets: u16,
        /// Body length.
        length: usize,
    },
    /// DATA with both D and K flags.
    #[error("DATA with both the data (D) and key (K) flags")]
    DataFlags,
    /// A sequence number naming a sample below 1.
    #[error("submessage 0x{kind:02x} names sample {sn}, below 1")]
    SequenceNumber {
        /// Submessage id.
        kind: u8,
        /// The number.
        sn: i64,
    },
    /// HEARTBEAT lastSN below firstSN − 1.
    #[error("HEARTBEAT range {first}..={last} (last below first - 1)")]
    HeartbeatRange {
        /// firstSN.
        first: i64,
        /// lastSN.
        last: i64,
    },
    /// GAP gapList.base below gapStart.
    #[error("GAP list base {base} below gapStart {start}")]
    GapRange {
        /// gapStart.
        start: i64,
        /// gapList.bitmapBase.
        base: i64,
    },
    /// A sequence-number set with base below 1, more than 256 bits, or past `i64::MAX`.
    #[error("sequence number set base {base} with {num_bits} bits (base < 1, bits > 256 or overflow)")]
    SequenceNumberSet {
        /// bitmapBase.
        base: i64,
        /// numBits.
        num_bits: u32,
    },
    /// A fragment-number set with more than 256 bits or past `u32::MAX`.
    #[error("fragment number set base {base} with {num_bits} bits (bits > 256 or overflow)")]
    FragmentNumberSet {
        /// bitmapBase.
        base: u32,
        /// numBits.
        num_bits: u32,
    },
    /// A fragment number of 0 (DATA_FRAG start, HEARTBEAT_FRAG last, NACK_FRAG base).
    #[error("submessage 0x{kind:02x} names fragment 0")]
    FragmentNumberZero {
        /// Submessage id.
        kind: u8,
    },
    /// DATA_FRAG fragmentSize or sampleSize of 0.
    #[error("DATA_FRAG fragmentSize {fragment_size}, sampleSize {sample_size} (both must be at least 1)")]
    FragmentSize {
        /// fragmentSize.
        fragment_size: u16,
        /// sampleSize.
        sample_size: u32,
    },
    /// DATA_FRAG fragments past the sample's last fragment, or none.
    #[error("DATA_FRAG fragments {start} + {count} of a sample of {total} fragments")]
    FragmentRange {
        /// fragmentStartingNum.
        start: u32,
        /// fragmentsInSubmessage.
        count: u16,
        /// Fragments of the whole sample.
        total: u32,
    },
    /// DATA_FRAG payload not the bytes its fragments occupy (at most 3 bytes of padding more).
    #[error("DATA_FRAG payload of {available} bytes, its fragments occupy {needed}")]
    FragmentPayload {
        /// Bytes the fragments occupy.
        needed: u64,
        /// Bytes of payload in the submessage.
        available: usize,
    },
    /// A parameter whose value runs past the list's bytes.
    #[error("parameter 0x{pid:04x} of {length} bytes, only {available} left")]
    ParameterLength {
        /// The PID.
        pid: u16,
        /// Its length field.
        length: u16,
        /// Bytes after its header.
        available: usize,
    },
    /// A parameter list without PID_SENTINEL.
    #[error("parameter list without PID_SENTINEL")]
    ParameterListUnterminated,
    /// A locator count more than the bytes hold.
    #[error("{count} locators in {available} bytes")]
    LocatorCount {
        /// The count.
        count: u32,
        /// Bytes after the count.
        available: usize,
    },
}

/// A refusal's kind without its values: an index into [`WireErrorCounts`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(usize)]
#[non_exhaustive]
pub enum WireErrorKind {
    /// [`WireError::NotRtps`].
    NotRtps,
    /// [`WireError::Version`].
    Version,
    /// [`WireError::SubmessageHeader`].
    SubmessageHeader,
    /// [`WireError::SubmessageLength`].
    SubmessageLength,
    /// [`WireError::SubmessageTooShort`].
    SubmessageTooShort,
    /// [`WireError::InlineQosOffset`].
    InlineQosOffset,
    /// [`WireError::DataFlags`].
    DataFlags,
    /// [`WireError::SequenceNumber`].
    SequenceNumber,
    /// [`WireError::HeartbeatRange`].
    HeartbeatRange,
    /// [`WireError::GapRange`].
    GapRange,
    /// [`WireError::SequenceNumberSet`].
    SequenceNumberSet,
    /// [`WireError::FragmentNumberSet`].
    FragmentNumberSet,
    /// [`WireError::FragmentNumberZero`].
    FragmentNumberZero,
    /// [`WireError::FragmentSize`].
    FragmentSize,
    /// [`WireError::FragmentRange`].
    FragmentRange,
    /// [`WireError::FragmentPayload`].
    FragmentPayload,
    /// [`WireError::ParameterLength`].
    ParameterLength,
    /// [`WireError::ParameterListUnterminated`].
    ParameterListUnterminated,
    /// [`WireError::LocatorCount`].
    LocatorCount,
}

impl WireErrorKind {
    /// How many kinds there are.
    pub const COUNT: usize = Self::ALL.len();

    /// Every kind, in index order.
    pub const ALL: [Self; 19] = [
        Self::NotRtps,
        Self::Version,
        Self::SubmessageHeader,
        Self::SubmessageLength,
        Self::SubmessageTooShort,
        Self::InlineQosOffset,
        Self::DataFlags,
        Self::SequenceNumber,
        Self::HeartbeatRange,
        Self::GapRange,
        Self::SequenceNumberSet,
        Self::FragmentNumberSet,
        Self::FragmentNumberZero,
        Self::FragmentSize,
        Self::FragmentRange,
        Self::FragmentPayload,
        Self::ParameterLength,
        Self::ParameterListUnterminated,
        Self::LocatorCount,
    ];

    /// The kind's name in snake_case (for counters and logs).
    pub const fn name(self) -> &'static str {
        match self {
            Self::NotRtps => "not_rtps",
            Self::Version => "version",
            Self::SubmessageHeader => "submessage_header",
            Self::SubmessageLength => "submessage_length",
            Self::SubmessageTooShort => "submessage_too_short",
            Self::InlineQosOffset => "inline_qos_offset",
            Self::DataFlags => "data_flags",
            Self::SequenceNumber => "sequence_number",
            Self::HeartbeatRange => "heartbeat_range",
            Self::GapRange => "gap_range",
            Self::SequenceNumberSet => "sequence_number_set",
            Self::FragmentNumberSet => "fragment_number_set",
            Self::FragmentNumberZero => "fragment_number_zero",
            Self::FragmentSize => "fragment_size",
            Self::FragmentRange => "fragment_range",
            Self::FragmentPayload => "fragment_payload",
            Self::ParameterLength => "parameter_length",
            Self::ParameterListUnterminated => "parameter_list_unterminated",
            Self::LocatorCount => "locator_count",
        }
    }

    /// The kind's index into [`WireErrorCounts`] (`0..COUNT`).
    pub const fn index(self) -> usize {
        self as usize
    }
}

impl WireError {
    /// The kind, for counting.
    pub fn kind(&self) -> WireErrorKind {
        match self {
            Self::NotRtps => WireErrorKind::NotRtps,
            Self::Version { .. } => WireErrorKind::Version,
            Self::SubmessageHeader { .. } => WireErrorKind::SubmessageHeader,
            Self::SubmessageLength { .. } => WireErrorKind::SubmessageLength,
            Self::SubmessageTooShort { .. } => WireErrorKind::SubmessageTooShort,
            Self::InlineQosOffset { .. } => WireErrorKind::InlineQosOffset,
            Self::DataFlags => WireErrorKind::DataFlags,
            Self::SequenceNumber { .. } => WireErrorKind::SequenceNumber,
            Self::HeartbeatRange { .. } => WireErrorKind::HeartbeatRange,
            Self::GapRange { .. } => WireErrorKind::GapRange,
            Self::SequenceNumberSet { .. } => WireErrorKind::SequenceNumberSet,
            Self::FragmentNumberSet { .. } => WireErrorKind::FragmentNumberSet,
            Self::FragmentNumberZero { .. } => WireErrorKind::FragmentNumberZero,
            Self::FragmentSize { .. } => WireErrorKind::FragmentSize,
            Self::FragmentRange { .. } => WireErrorKind::FragmentRange,
            Self::FragmentPayload { .. } => WireErrorKind::FragmentPayload,
            Self::ParameterLength { .. } => WireErrorKind::ParameterLength,
            Self::ParameterListUnterminated => WireErrorKind::ParameterListUnterminated,
            Self::LocatorCount { .. } => WireErrorKind::LocatorCount,
        }
    }
}

/// Refusals counted by kind (saturating).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct WireErrorCounts {
    counts: [u64; WireErrorKind::COUNT],
}

impl WireErrorCounts {
    /// Counts one refusal.
    pub fn count(&mut self, e: WireError) {
        if let Some(n) = self.counts.get_mut(e.kind().index()) {
            *n = n.saturating_add(1);
        }
    }

    /// Refusals of `kind` counted.
    pub fn get(&self, kind: WireErrorKind) -> u64 {
        self.counts.get(kind.index()).copied().unwrap_or(0)
    }

    /// Every kind with its count, in index order.
    pub fn iter(&self) -> impl Iterator<Item = (WireErrorKind, u64)> + '_ {
        WireErrorKind::ALL.into_iter().zip(self.counts.iter().copied())
    }

    /// Refusals of every kind together (saturating).
    pub fn total(&self) -> u64 {
        self.counts.iter().fold(0u64, |a, &n| a.saturating_add(n))
    }
}
