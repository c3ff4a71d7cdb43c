//! The spline shared-memory interface (spec `spline-shm.md`), the controller's side:
//! [`SplineClient`] writes commands and reads fresh motor state on `/spline_shm` (in lockstep
//! with the daemon, in the caller's own loop), [`SplineMonitor`] watches that state in robowire's
//! device shape, [`ImuReader`] reads `/imu_shm` without tearing. The handshake itself is `robowire-shm`'s, on `zsl-proto`'s
//! layouts; the daemon's side is in `robowire-sim`.

mod client;
mod imu;
mod monitor;

pub use client::{DEFAULT_STALL_AFTER, SplineClient, SplineClientCounters, SplineError, SplineFlags};
pub use imu::{ImuError, ImuReader, ImuReaderCounters, ImuSample};
pub use monitor::{SplineMonitor, SplineMonitorOptions};
