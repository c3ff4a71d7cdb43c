//! What each bridged device did: samples published, services answered, the `cmd_vel` guard.

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use robowire_dds::StatsHandle;

use crate::guard::GuardCounters;

/// Counters of one bridged device, shared with whoever reports them.
#[derive(Debug, Default)]
pub struct DeviceReport {
    published: AtomicU64,
    service_calls: AtomicU64,
    guard: Mutex<GuardCounters>,
    /// The services' request readers.
    requests: Mutex<Vec<StatsHandle>>,
}

/// A snapshot of a [`DeviceReport`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct DeviceCounters {
    /// Samples published.
    pub published: u64,
    /// Service requests answered.
    pub service_calls: u64,
    /// Service requests of neither middleware's shape (not answered).
    pub malformed_requests: u64,
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

    /// Counts the requests of neither shape `requests` (a service's request reader) refuses.
    pub(crate) fn watch_requests(&self, requests: StatsHandle) {
        robowire_rt::lock(&self.requests).push(requests);
    }

    pub(crate) fn set_guard(&self, counters: GuardCounters) {
        *robowire_rt::lock(&self.guard) = counters;
    }

    /// The counters now.
    pub fn counters(&self) -> DeviceCounters {
        DeviceCounters {
            published: self.published.load(Ordering::Relaxed),
            service_calls: self.service_calls.load(Ordering::Relaxed),
            malformed_requests: robowire_rt::lock(&self.requests).iter().map(|r| r.get().decode_errors).sum(),
            cmd_vel: *robowire_rt::lock(&self.guard),
        }
    }
}
