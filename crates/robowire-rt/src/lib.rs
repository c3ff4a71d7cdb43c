#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod thread;

pub use thread::{RtError, pin_current_thread, set_realtime_priority};

/// Time on the monotonic clock (`CLOCK_MONOTONIC`), ns: the clock of every robowire deadline
/// and of robowire's IMU timestamps.
pub fn monotonic_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    (t.tv_sec as u64).saturating_mul(1_000_000_000).saturating_add(t.tv_nsec as u64)
}
