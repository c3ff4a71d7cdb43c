//! The QoS Unitree's software gets from CycloneDDS's defaults (spec `unitree-dds.md`): writers
//! reliable (blocking at most 100 ms), keep last 1, volatile; readers best effort, keep last 1.
//! A stream thread's writer is the same on the wire but never blocks.
//! A reader of requests or answers keeps a few more samples locally (history depth is not
//! matched between peers), so that two calls in a row are not one.

use rtps_proto::discovery::{Durability, History, Reliability};
use rtps_proto::types::DdsDuration;

/// How a writer or reader is set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Reliable (with the writer's blocking bound) or best effort.
    pub reliable: bool,
    /// How long a reliable writer's `write` may wait for room in its send window (a reader that
    /// does not acknowledge), ms; 0: never, a full window refuses the sample at once. Local to
    /// the writer: it is not matched against readers.
    pub max_blocking_ms: i64,
    /// Samples kept.
    pub depth: i32,
    /// Transient local: a late-joining reader gets the samples kept (ROS 2's `/tf_static`).
    pub transient_local: bool,
}

/// Writer blocking bound of CycloneDDS's default reliable QoS.
pub const MAX_BLOCKING_MS: i64 = 100;

impl Qos {
    /// A writer as Unitree's: reliable, keep last 1, volatile.
    pub const WRITER: Self =
        Self { reliable: true, max_blocking_ms: MAX_BLOCKING_MS, depth: 1, transient_local: false };
    /// A writer on a real-time stream thread: as [`WRITER`](Self::WRITER) on the wire, but a
    /// write never waits (a full send window is a dropped sample, counted).
    pub const STREAM_WRITER: Self = Self { max_blocking_ms: 0, ..Self::WRITER };
    /// A reader as Unitree's: best effort, keep last 1.
    pub const READER: Self = Self { reliable: false, max_blocking_ms: 0, depth: 1, transient_local: false };
    /// A reader of requests or answers: best effort, keep last 16.
    pub const RPC_READER: Self = Self { depth: 16, ..Self::READER };
    /// ROS 2's sensor data profile: best effort, keep last 5.
    pub const ROS_SENSOR_DATA: Self = Self { depth: 5, ..Self::READER };
    /// ROS 2's default profile (commands, odometry, `/tf`, services): reliable, keep last 10.
    pub const ROS_DEFAULT: Self = Self { depth: 10, ..Self::WRITER };
    /// ROS 2's `/tf_static`: reliable, keep last 1, transient local.
    pub const ROS_TF_STATIC: Self = Self { transient_local: true, ..Self::WRITER };

    /// The QoS as announced on the wire and matched.
    pub(crate) fn to_rtps(self) -> rtps_proto::discovery::Qos {
        let reliability = if self.reliable {
            let ms = u64::try_from(self.max_blocking_ms).unwrap_or(0);
            Reliability::Reliable {
                max_blocking_time: DdsDuration::from_duration(std::time::Duration::from_millis(ms)),
            }
        } else {
            Reliability::BestEffort
        };
        rtps_proto::discovery::Qos {
            reliability,
            history: History::KeepLast { depth: u32::try_from(self.depth.max(1)).unwrap_or(1) },
            durability: if self.transient_local { Durability::TransientLocal } else { Durability::Volatile },
            ..rtps_proto::discovery::Qos::default()
        }
    }
}
