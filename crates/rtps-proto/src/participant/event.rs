//! What a participant reports and returns: the [`Event`]s it queues (with the [`Sample`]s its
//! readers receive, why a pair does not match, why a participant is gone), its [`Counters`] of
//! what it dropped or refused, the outcome of a write ([`Written`]) and why an endpoint was not
//! created ([`CreateError`]).

use alloc::collections::VecDeque;
use alloc::vec::Vec;

use super::Transmit;
use crate::discovery::QosMismatch;
use crate::endpoint::SampleInfo;
use crate::types::{EntityId, Guid, GuidPrefix, SequenceNumber, VendorId};
use crate::wire::WireErrorCounts;

/// Why a local and a remote endpoint on the same topic do not match.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum MatchError {
    /// Same topic, different type names.
    #[error("the type names differ")]
    TypeName,
    /// The QoS are incompatible.
    #[error("{0}")]
    Qos(QosMismatch),
}

/// Why a remote participant is gone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LostReason {
    /// Nothing heard for its lease duration.
    LeaseExpired,
    /// It said it is leaving (SPDP dispose).
    Left,
    /// Forgotten to make room for a participant announcing itself while `Limits::participants`
    /// were known: of them all, it was the one heard from least recently.
    Displaced,
}

/// A sample received by a local reader.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sample {
    /// Who sent it and what it answers.
    pub info: SampleInfo,
    /// The serialized payload with its 4-byte encapsulation header. Give the buffer back with
    /// [`Participant::recycle`] and the next samples reuse it (no allocation).
    ///
    /// [`Participant::recycle`]: super::Participant::recycle
    pub payload: Vec<u8>,
}

/// What happened, in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Event {
    /// A remote participant was discovered.
    ParticipantDiscovered {
        /// Its prefix.
        prefix: GuidPrefix,
        /// Its vendor.
        vendor: VendorId,
    },
    /// A remote participant is gone (with its endpoints).
    ParticipantLost {
        /// Its prefix.
        prefix: GuidPrefix,
        /// Why.
        reason: LostReason,
    },
    /// A remote writer or reader was discovered (see [`Participant::remote_endpoint`]).
    ///
    /// [`Participant::remote_endpoint`]: super::Participant::remote_endpoint
    EndpointDiscovered {
        /// Its GUID.
        guid: Guid,
    },
    /// A remote writer or reader is gone.
    EndpointLost {
        /// Its GUID.
        guid: Guid,
    },
    /// A local endpoint and a remote one matched.
    Matched {
        /// The local writer or reader.
        local: EntityId,
        /// The remote reader or writer.
        remote: Guid,
    },
    /// A match ended (the remote endpoint or its participant is gone).
    Unmatched {
        /// The local writer or reader.
        local: EntityId,
        /// The remote one.
        remote: Guid,
    },
    /// A local and a remote endpoint share a topic but cannot match.
    Incompatible {
        /// The local writer or reader.
        local: EntityId,
        /// The remote one.
        remote: Guid,
        /// Why.
        reason: MatchError,
    },
    /// A sample for a local reader.
    Sample(Sample),
}

/// What a participant dropped, refused or could not keep.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Counters {
    /// Datagrams received.
    pub datagrams: u64,
    /// Refusals of the wire layer, by kind.
    pub wire: WireErrorCounts,
    /// SPDP/SEDP data that did not parse.
    pub discovery_errors: u64,
    /// Participants that announced themselves while `Limits::participants` were known; each
    /// displaced the one heard from least recently ([`LostReason::Displaced`]).
    pub participants_at_limit: u64,
    /// Remote endpoints not kept: `Limits::endpoints_per_participant` reached.
    pub endpoints_at_limit: u64,
    /// Matches not made: a local endpoint has as many matches as `Limits::endpoints_per_participant`.
    pub matches_at_limit: u64,
    /// Submessages for another participant (INFO_DST).
    pub not_for_us: u64,
    /// Submessages from writers or readers not matched here.
    pub unmatched_source: u64,
    /// SPDP announcements for another domain.
    pub other_domain: u64,
    /// Events dropped because they were not polled (`Limits::events`).
    pub events_at_limit: u64,
    /// Datagrams that could not be built in the caller's buffer.
    pub transmit_too_small: u64,
}

/// The outcome of a write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Written {
    /// The sample's number.
    pub sequence: SequenceNumber,
    /// The datagram to send now (in the caller's buffer), `None` when no reader is matched or
    /// the sample is fragmented (its fragments come from `poll_transmit`).
    pub transmit: Option<Transmit>,
}

/// Why an endpoint was not created.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CreateError {
    /// `Limits::local_endpoints` reached.
    #[error("the participant has as many endpoints as its limit ({0})")]
    TooMany(usize),
    /// A KEEP_LAST depth of 0 or above `Limits::history_depth`.
    #[error("history depth {depth} is outside 1..={limit}")]
    Depth {
        /// The depth asked for.
        depth: u32,
        /// The limit.
        limit: usize,
    },
    /// Entity keys exhausted.
    #[error("entity keys exhausted")]
    Keys,
}

/// Queues an event within the bound, counting what does not fit.
pub(super) fn push_event(events: &mut VecDeque<Event>, counters: &mut Counters, limit: usize, e: Event) {
    if events.len() >= limit {
        counters.events_at_limit += 1;
        return;
    }
    events.push_back(e);
}
