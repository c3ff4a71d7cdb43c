//! The DDS QoS policies SEDP carries and their wire form; the match of an offered with a requested
//! QoS is in the sibling `matching` module.

use super::{DiscoveryError, ValueReader, pid, put};
use crate::Limits;
use crate::types::DdsDuration;
use crate::wire::ParameterWriter;
use alloc::string::String;
use alloc::vec::Vec;
use core::fmt;
use core::time::Duration;
use robowire_core::BufferTooSmall;

/// DATA_REPRESENTATION id of XCDR version 1 (what an absent DATA_REPRESENTATION means).
pub const DATA_REPRESENTATION_XCDR1: i16 = 0;
/// DATA_REPRESENTATION id of XML.
pub const DATA_REPRESENTATION_XML: i16 = 1;
/// DATA_REPRESENTATION id of XCDR version 2.
pub const DATA_REPRESENTATION_XCDR2: i16 = 2;

/// RELIABILITY: whether a writer resends what a reader missed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Reliability {
    /// Samples may be lost (wire kind 1).
    BestEffort,
    /// Samples are resent until acknowledged (wire kind 2); a writer's `write` blocks at most
    /// `max_blocking_time` on a full history.
    Reliable {
        /// How long a write may block.
        max_blocking_time: DdsDuration,
    },
}

impl Reliability {
    /// The kind, without the blocking time.
    pub fn kind(&self) -> ReliabilityKind {
        match self {
            Self::BestEffort => ReliabilityKind::BestEffort,
            Self::Reliable { .. } => ReliabilityKind::Reliable,
        }
    }
}

/// RELIABILITY's kind, ordered best effort < reliable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ReliabilityKind {
    /// BEST_EFFORT.
    BestEffort,
    /// RELIABLE.
    Reliable,
}

/// DURABILITY: which past samples a late-joining reader gets; ordered as DDS ranks them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub enum Durability {
    /// None (wire kind 0).
    #[default]
    Volatile,
    /// The writer's history while the writer lives (1).
    TransientLocal,
    /// Kept by a durability service beyond the writer (2).
    Transient,
    /// Kept on permanent storage (3).
    Persistent,
}

/// HISTORY: how many samples per instance a writer or reader keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum History {
    /// The last `depth` (≥ 1) samples (wire kind 0).
    KeepLast {
        /// Samples kept per instance.
        depth: u32,
    },
    /// All of them, up to the resource limits (wire kind 1).
    KeepAll,
}

impl Default for History {
    fn default() -> Self {
        Self::KeepLast { depth: 1 }
    }
}

/// LIVELINESS's kind, ordered automatic < manual by participant < manual by topic.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub enum LivelinessKind {
    /// The middleware asserts liveliness (wire kind 0).
    #[default]
    Automatic,
    /// The application asserts it for the participant (1).
    ManualByParticipant,
    /// The application asserts it per writer (2).
    ManualByTopic,
}

/// LIVELINESS: how a writer shows it is alive, and how long it may stay silent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Liveliness {
    /// Who asserts it.
    pub kind: LivelinessKind,
    /// How long after the last assertion the writer counts as alive.
    pub lease_duration: DdsDuration,
}

impl Default for Liveliness {
    fn default() -> Self {
        Self { kind: LivelinessKind::Automatic, lease_duration: DdsDuration::INFINITE }
    }
}

/// OWNERSHIP (and OWNERSHIP_STRENGTH): whether several writers may update one instance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Ownership {
    /// All writers' samples reach readers (wire kind 0).
    #[default]
    Shared,
    /// Only the strongest live writer's (wire kind 1).
    Exclusive {
        /// OWNERSHIP_STRENGTH.
        strength: i32,
    },
}

impl Ownership {
    /// The kind, without the strength.
    pub fn kind(&self) -> OwnershipKind {
        match self {
            Self::Shared => OwnershipKind::Shared,
            Self::Exclusive { .. } => OwnershipKind::Exclusive,
        }
    }
}

/// OWNERSHIP's kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OwnershipKind {
    /// SHARED.
    Shared,
    /// EXCLUSIVE.
    Exclusive,
}

/// DESTINATION_ORDER: which timestamp orders samples of one instance; by reception < by source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub enum DestinationOrder {
    /// The reader's reception time (wire kind 0).
    #[default]
    ByReceptionTimestamp,
    /// The writer's source timestamp (1).
    BySourceTimestamp,
}

/// The QoS of a writer or reader as SEDP carries it.
///
/// `Qos::default()` is the DDS default of a *writer*: reliable with a 100 ms max blocking time,
/// volatile, keep last 1, infinite deadline, zero latency budget, automatic liveliness with an
/// infinite lease, shared ownership, by reception timestamp, infinite lifespan, the default
/// partition, no data representation given (XCDR1). [`Qos::reader_default`] differs only in
/// being best effort.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Qos {
    /// RELIABILITY.
    pub reliability: Reliability,
    /// DURABILITY.
    pub durability: Durability,
    /// HISTORY.
    pub history: History,
    /// DEADLINE: the longest period between samples of an instance.
    pub deadline_period: DdsDuration,
    /// LATENCY_BUDGET: the delay the application accepts.
    pub latency_budget: DdsDuration,
    /// LIVELINESS.
    pub liveliness: Liveliness,
    /// OWNERSHIP and OWNERSHIP_STRENGTH.
    pub ownership: Ownership,
    /// DESTINATION_ORDER.
    pub destination_order: DestinationOrder,
    /// LIFESPAN: how long a sample stays valid.
    pub lifespan: DdsDuration,
    /// PARTITION names (patterns with `*` and `?` allowed); empty is the default partition "".
    pub partitions: Vec<String>,
    /// DATA_REPRESENTATION ids in preference order (a writer uses the first); empty is XCDR1.
    pub data_representation: Vec<i16>,
    /// USER_DATA.
    pub user_data: Vec<u8>,
    /// TOPIC_DATA.
    pub topic_data: Vec<u8>,
    /// GROUP_DATA (the publisher's or subscriber's).
    pub group_data: Vec<u8>,
}

impl Default for Qos {
    fn default() -> Self {
        Self {
            reliability: Reliability::Reliable {
                max_blocking_time: DdsDuration::from_duration(Duration::from_millis(100)),
            },
            durability: Durability::Volatile,
            history: History::default(),
            deadline_period: DdsDuration::INFINITE,
            latency_budget: DdsDuration::ZERO,
            liveliness: Liveliness::default(),
            ownership: Ownership::Shared,
            destination_order: DestinationOrder::ByReceptionTimestamp,
            lifespan: DdsDuration::INFINITE,
            partitions: Vec::new(),
            data_representation: Vec::new(),
            user_data: Vec::new(),
            topic_data: Vec::new(),
            group_data: Vec::new(),
        }
    }
}

impl Qos {
    /// The DDS default of a *reader*: as [`Qos::default`] but best effort.
    pub fn reader_default() -> Self {
        Self { reliability: Reliability::BestEffort, ..Self::default() }
    }

    /// Reliable (not best effort).
    pub fn is_reliable(&self) -> bool {
        matches!(self.reliability, Reliability::Reliable { .. })
    }

    /// Transient-local or a stronger durability (late joiners get the history).
    pub fn is_transient_local(&self) -> bool {
        !matches!(self.durability, Durability::Volatile)
    }

    /// Writes every policy: the fixed-size ones always, the sequences when not empty.
    pub(crate) fn emit(&self, w: &mut ParameterWriter<'_>) -> Result<(), BufferTooSmall> {
        let (kind, mbt) = match self.reliability {
            Reliability::BestEffort => (1, DdsDuration::ZERO),
            Reliability::Reliable { max_blocking_time } => (2, max_blocking_time),
        };
        put::kind_duration(w, pid::RELIABILITY, kind, mbt)?;
        put::u32(w, pid::DURABILITY, self.durability as u32)?;
        let (kind, depth) = match self.history {
            History::KeepLast { depth } => (0u32, i32::try_from(depth).unwrap_or(i32::MAX)),
            History::KeepAll => (1, 1),
        };
        let mut b = [0; 8];
        b[..4].copy_from_slice(&kind.to_le_bytes());
        b[4..].copy_from_slice(&depth.to_le_bytes());
        w.push(pid::HISTORY, &b)?;
        put::duration(w, pid::DEADLINE, self.deadline_period)?;
        put::duration(w, pid::LATENCY_BUDGET, self.latency_budget)?;
        put::kind_duration(w, pid::LIVELINESS, self.liveliness.kind as u32, self.liveliness.lease_duration)?;
        match self.ownership {
            Ownership::Shared => put::u32(w, pid::OWNERSHIP, 0)?,
            Ownership::Exclusive { strength } => {
                put::u32(w, pid::OWNERSHIP, 1)?;
                put::i32(w, pid::OWNERSHIP_STRENGTH, strength)?;
            }
        }
        put::u32(w, pid::DESTINATION_ORDER, self.destination_order as u32)?;
        put::duration(w, pid::LIFESPAN, self.lifespan)?;
        if !self.partitions.is_empty() {
            put::strings(w, pid::PARTITION, &self.partitions)?;
        }
        if !self.data_representation.is_empty() {
            put::i16s(w, pid::DATA_REPRESENTATION, &self.data_representation)?;
        }
        for (p, v) in [
            (pid::USER_DATA, &self.user_data),
            (pid::TOPIC_DATA, &self.topic_data),
            (pid::GROUP_DATA, &self.group_data),
        ] {
            if !v.is_empty() {
                put::octets(w, p, v)?;
            }
        }
        Ok(())
    }
}

/// Reads QoS parameters into a [`Qos`]; OWNERSHIP_STRENGTH may come before OWNERSHIP.
pub(crate) struct QosReader {
    qos: Qos,
    exclusive: bool,
    strength: i32,
}

impl QosReader {
    pub(crate) fn new(defaults: Qos) -> Self {
        let (exclusive, strength) = match defaults.ownership {
            Ownership::Shared => (false, 0),
            Ownership::Exclusive { strength } => (true, strength),
        };
        Self { qos: defaults, exclusive, strength }
    }

    /// Reads the parameter if it is a QoS policy; `Ok(false)` if it is not one.
    pub(crate) fn read(&mut self, r: &mut ValueReader<'_>, pid: u16, limits: &Limits) -> Result<bool, DiscoveryError> {
        let q = &mut self.qos;
        match pid {
            pid::RELIABILITY => {
                let kind = r.u32()?;
                let max_blocking_time = r.duration()?;
                q.reliability = match kind {
                    1 => Reliability::BestEffort,
                    2 => Reliability::Reliable { max_blocking_time },
                    _ => return Err(DiscoveryError::InvalidValue { pid }),
                };
            }
            pid::DURABILITY => {
                const KINDS: [Durability; 4] =
                    [Durability::Volatile, Durability::TransientLocal, Durability::Transient, Durability::Persistent];
                q.durability = KINDS[r.kind(4)? as usize];
            }
            pid::HISTORY => {
                let kind = r.kind(2)?;
                let depth = r.i32()?;
                q.history = match kind {
                    0 => History::KeepLast {
                        depth: u32::try_from(depth)
                            .ok()
                            .filter(|&d| d >= 1)
                            .ok_or(DiscoveryError::InvalidValue { pid })?,
                    },
                    _ => History::KeepAll,
                };
            }
            pid::DEADLINE => q.deadline_period = r.duration()?,
            pid::LATENCY_BUDGET => q.latency_budget = r.duration()?,
            pid::LIVELINESS => {
                const KINDS: [LivelinessKind; 3] =
                    [LivelinessKind::Automatic, LivelinessKind::ManualByParticipant, LivelinessKind::ManualByTopic];
                let kind = KINDS[r.kind(3)? as usize];
                q.liveliness = Liveliness { kind, lease_duration: r.duration()? };
            }
            pid::OWNERSHIP => self.exclusive = r.kind(2)? == 1,
            pid::OWNERSHIP_STRENGTH => self.strength = r.i32()?,
            pid::DESTINATION_ORDER => {
                q.destination_order = match r.kind(2)? {
                    0 => DestinationOrder::ByReceptionTimestamp,
                    _ => DestinationOrder::BySourceTimestamp,
                }
            }
            pid::LIFESPAN => q.lifespan = r.duration()?,
            pid::PARTITION => q.partitions = r.strings(limits)?,
            pid::DATA_REPRESENTATION => q.data_representation = r.i16s(limits)?,
            pid::USER_DATA => q.user_data = r.octets(limits)?,
            pid::TOPIC_DATA => q.topic_data = r.octets(limits)?,
            pid::GROUP_DATA => q.group_data = r.octets(limits)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    pub(crate) fn finish(self) -> Qos {
        let ownership =
            if self.exclusive { Ownership::Exclusive { strength: self.strength } } else { Ownership::Shared };
        Qos { ownership, ..self.qos }
    }
}

impl fmt::Display for ReliabilityKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::BestEffort => "best effort",
            Self::Reliable => "reliable",
        })
    }
}

impl fmt::Display for Durability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Volatile => "volatile",
            Self::TransientLocal => "transient local",
            Self::Transient => "transient",
            Self::Persistent => "persistent",
        })
    }
}

impl fmt::Display for LivelinessKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Automatic => "automatic",
            Self::ManualByParticipant => "manual by participant",
            Self::ManualByTopic => "manual by topic",
        })
    }
}

impl fmt::Display for OwnershipKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Shared => "shared",
            Self::Exclusive => "exclusive",
        })
    }
}

impl fmt::Display for DestinationOrder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::ByReceptionTimestamp => "by reception timestamp",
            Self::BySourceTimestamp => "by source timestamp",
        })
    }
}
