//! The QoS Unitree's software gets from CycloneDDS's defaults (spec `unitree-dds.md`): writers
//! reliable (blocking at most 100 ms), keep last 1, volatile; readers best effort, keep last 1.
//! A reader of requests or answers keeps a few more samples locally (history depth is not
//! matched between peers), so that two calls in a row are not one.

use rustdds::policy::{Durability, History, Reliability};
use rustdds::{QosPolicies, QosPolicyBuilder};

/// How a writer or reader is set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Reliable (with the writer's blocking bound) or best effort.
    pub reliable: bool,
    /// Samples kept.
    pub depth: i32,
    /// Transient local: a late-joining reader gets the samples kept (ROS 2's `/tf_static`).
    pub transient_local: bool,
}

/// Writer blocking bound of CycloneDDS's default reliable QoS.
pub const MAX_BLOCKING_MS: i64 = 100;

impl Qos {
    /// A writer as Unitree's: reliable, keep last 1, volatile.
    pub const WRITER: Self = Self { reliable: true, depth: 1, transient_local: false };
    /// A reader as Unitree's: best effort, keep last 1.
    pub const READER: Self = Self { reliable: false, depth: 1, transient_local: false };
    /// A reader of requests or answers: best effort, keep last 16.
    pub const RPC_READER: Self = Self { reliable: false, depth: 16, transient_local: false };
    /// ROS 2's sensor data profile: best effort, keep last 5.
    pub const ROS_SENSOR_DATA: Self = Self { reliable: false, depth: 5, transient_local: false };
    /// ROS 2's default profile (commands, odometry, `/tf`, services): reliable, keep last 10.
    pub const ROS_DEFAULT: Self = Self { reliable: true, depth: 10, transient_local: false };
    /// ROS 2's `/tf_static`: reliable, keep last 1, transient local.
    pub const ROS_TF_STATIC: Self = Self { reliable: true, depth: 1, transient_local: true };

    pub(crate) fn policies(self) -> QosPolicies {
        let reliability = if self.reliable {
            Reliability::Reliable { max_blocking_time: rustdds::Duration::from_millis(MAX_BLOCKING_MS) }
        } else {
            Reliability::BestEffort
        };
        QosPolicyBuilder::new()
            .reliability(reliability)
            .history(History::KeepLast { depth: self.depth })
            .durability(if self.transient_local { Durability::TransientLocal } else { Durability::Volatile })
            .build()
    }
}
