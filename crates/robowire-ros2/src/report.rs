//! What each bridged device did: samples published, services answered, the `cmd_vel` guard.

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::guard::GuardCounters;

/// Counters of one bridged device, shared with whoever reports them.
#[derive(Debug, Default)]
pub struct DeviceReport {
    published: AtomicU64,
    service_calls: AtomicU64,
    guard: Mutex<GuardCounters>,
}

/// A snapshot of a [`DeviceReport`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct DeviceCounters {
    /// Samples published.
    pub published: u64,
    /// Service requests answered.
    pub service_calls: u64,
    /// The `cmd_vel` guard.
    pub cmd_vel: GuardCounters,
}

impl DeviceReport {
    pub(crate) fn published(&self, samples: u64) {
        self.published.fetch_add(samples, Ordering::Relaxed);
    }

    pub(crate) fn service_call(&self) {
        self.service_calls.fetch_add(1, Ordering::Relaxed);
    }

    pub(crate) fn set_guard(&self, counters: GuardCounters) {
        *robowire_rt::lock(&self.guard) = counters;
    }

    /// The counters now.
    pub fn counters(&self) -> DeviceCounters {
        DeviceCounters {
            published: self.published.load(Ordering::Relaxed),
            service_calls: self.service_calls.load(Ordering::Relaxed),
            cmd_vel: *robowire_rt::lock(&self.guard),
        }
    }
}
