#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod device;
mod latest;
mod placement;
pub mod runner;
pub mod stats;
pub mod sync;
mod thread;

pub use latest::Latest;
pub use placement::Placement;
pub use robowire_core::schedule;
pub use robowire_core::schedule::Time;
pub use sync::lock;
pub use thread::{RtError, lock_memory, pin_current_thread, set_fine_timer_slack, set_realtime_priority};

/// Time on the monotonic clock (`CLOCK_MONOTONIC`), ns: the clock of every robowire deadline
/// and of robowire's IMU timestamps.
pub fn monotonic_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    (t.tv_sec as u64).saturating_mul(1_000_000_000).saturating_add(t.tv_nsec as u64)
}

/// Now on the monotonic clock, as the [`Time`] of `robowire-core`'s schedules.
pub fn now() -> Time {
    Time::from_nanos(monotonic_ns())
}
