//! The DDS 1.4 Request/Offered match of a writer's QoS with a reader's ([`check_match`]) and
//! why a pair does not match ([`QosMismatch`]), partition names and patterns included.

use super::qos::{
    DATA_REPRESENTATION_XCDR1, DestinationOrder, Durability, LivelinessKind, OwnershipKind, Qos, ReliabilityKind,
};
use crate::types::DdsDuration;
use alloc::string::String;
use alloc::vec::Vec;
use core::fmt;

/// Why a writer and a reader do not match: the policy, with what each side has where small.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum QosMismatch {
    /// The writer offers a weaker reliability than the reader requests.
    #[error("reliability: the writer offers {offered}, the reader requests {requested}")]
    Reliability {
        /// The writer's.
        offered: ReliabilityKind,
        /// The reader's.
        requested: ReliabilityKind,
    },
    /// The writer offers a weaker durability than the reader requests.
    #[error("durability: the writer offers {offered}, the reader requests {requested}")]
    Durability {
        /// The writer's.
        offered: Durability,
        /// The reader's.
        requested: Durability,
    },
    /// The writer's deadline period is longer than the reader's.
    #[error("deadline: the writer offers a period of {}, the reader requests {}", Dur(*offered), Dur(*requested))]
    Deadline {
        /// The writer's.
        offered: DdsDuration,
        /// The reader's.
        requested: DdsDuration,
    },
    /// The writer's latency budget is longer than the reader's.
    #[error("latency budget: the writer offers {}, the reader requests {}", Dur(*offered), Dur(*requested))]
    LatencyBudget {
        /// The writer's.
        offered: DdsDuration,
        /// The reader's.
        requested: DdsDuration,
    },
    /// The writer's liveliness kind is weaker than the reader's.
    #[error("liveliness: the writer offers {offered}, the reader requests {requested}")]
    LivelinessKind {
        /// The writer's.
        offered: LivelinessKind,
        /// The reader's.
        requested: LivelinessKind,
    },
    /// The writer's liveliness lease is longer than the reader's.
    #[error("liveliness: the writer offers a lease of {}, the reader requests {}", Dur(*offered), Dur(*requested))]
    LivelinessLease {
        /// The writer's.
        offered: DdsDuration,
        /// The reader's.
        requested: DdsDuration,
    },
    /// The ownership kinds differ.
    #[error("ownership: the writer offers {offered}, the reader requests {requested}")]
    Ownership {
        /// The writer's.
        offered: OwnershipKind,
        /// The reader's.
        requested: OwnershipKind,
    },
    /// The writer orders by reception, the reader requests by source timestamp.
    #[error("destination order: the writer offers {offered}, the reader requests {requested}")]
    DestinationOrder {
        /// The writer's.
        offered: DestinationOrder,
        /// The reader's.
        requested: DestinationOrder,
    },
    /// No partition of the writer matches one of the reader.
    #[error("partition: the writer and the reader share no partition")]
    Partition,
    /// The writer's data representation is not among the reader's.
    #[error("data representation: the writer uses {offered}, which the reader does not accept")]
    DataRepresentation {
        /// The writer's (its first, or XCDR1).
        offered: i16,
    },
}

/// Whether `writer` (offered) and `reader` (requested) match by the DDS 1.4 Request/Offered
/// rules: reliability, durability, deadline, latency budget, liveliness (kind and lease),
/// ownership, destination order; then a shared partition and the writer's data representation
/// among the reader's. The first mismatch found is returned.
pub fn check_match(writer: &Qos, reader: &Qos) -> Result<(), QosMismatch> {
    let (offered, requested) = (writer.reliability.kind(), reader.reliability.kind());
    if offered < requested {
        return Err(QosMismatch::Reliability { offered, requested });
    }
    let (offered, requested) = (writer.durability, reader.durability);
    if offered < requested {
        return Err(QosMismatch::Durability { offered, requested });
    }
    let (offered, requested) = (writer.deadline_period, reader.deadline_period);
    if offered > requested {
        return Err(QosMismatch::Deadline { offered, requested });
    }
    let (offered, requested) = (writer.latency_budget, reader.latency_budget);
    if offered > requested {
        return Err(QosMismatch::LatencyBudget { offered, requested });
    }
    let (offered, requested) = (writer.liveliness.kind, reader.liveliness.kind);
    if offered < requested {
        return Err(QosMismatch::LivelinessKind { offered, requested });
    }
    let (offered, requested) = (writer.liveliness.lease_duration, reader.liveliness.lease_duration);
    if offered > requested {
        return Err(QosMismatch::LivelinessLease { offered, requested });
    }
    let (offered, requested) = (writer.ownership.kind(), reader.ownership.kind());
    if offered != requested {
        return Err(QosMismatch::Ownership { offered, requested });
    }
    let (offered, requested) = (writer.destination_order, reader.destination_order);
    if offered < requested {
        return Err(QosMismatch::DestinationOrder { offered, requested });
    }
    if !partitions_match(&writer.partitions, &reader.partitions) {
        return Err(QosMismatch::Partition);
    }
    let offered = writer.data_representation.first().copied().unwrap_or(DATA_REPRESENTATION_XCDR1);
    let accepted = if reader.data_representation.is_empty() {
        offered == DATA_REPRESENTATION_XCDR1
    } else {
        reader.data_representation.contains(&offered)
    };
    if !accepted {
        return Err(QosMismatch::DataRepresentation { offered });
    }
    Ok(())
}

/// Some writer partition matches some reader partition (empty lists are the default partition
/// ""). A pattern matches a name; two patterns match only when equal (as DDS says).
fn partitions_match(writer: &[String], reader: &[String]) -> bool {
    const DEFAULT: &[&str] = &[""];
    let w: Vec<&str> = if writer.is_empty() { DEFAULT.to_vec() } else { writer.iter().map(String::as_str).collect() };
    let r: Vec<&str> = if reader.is_empty() { DEFAULT.to_vec() } else { reader.iter().map(String::as_str).collect() };
    w.iter().any(|w| r.iter().any(|r| partition_match(w, r)))
}

fn is_pattern(s: &str) -> bool {
    s.contains(['*', '?'])
}

fn partition_match(w: &str, r: &str) -> bool {
    match (is_pattern(w), is_pattern(r)) {
        (true, true) | (false, false) => w == r,
        (true, false) => fnmatch(w.as_bytes(), r.as_bytes()),
        (false, true) => fnmatch(r.as_bytes(), w.as_bytes()),
    }
}

/// `*` matches any run of bytes, `?` one byte, anything else itself (iterative, no recursion).
fn fnmatch(pattern: &[u8], name: &[u8]) -> bool {
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        match pattern.get(p) {
            Some(b'*') => {
                star = Some((p, n));
                p += 1;
            }
            Some(&c) if c == b'?' || c == name[n] => {
                p += 1;
                n += 1;
            }
            _ => match star {
                Some((sp, sn)) => {
                    p = sp + 1;
                    n = sn + 1;
                    star = Some((sp, sn + 1));
                }
                None => return false,
            },
        }
    }
    pattern[p..].iter().all(|&c| c == b'*')
}

/// A duration as people read it: "infinite" or e.g. "100ms".
struct Dur(DdsDuration);

impl fmt::Display for Dur {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.to_duration() {
            None => f.write_str("infinite"),
            Some(d) => write!(f, "{d:?}"),
        }
    }
}
