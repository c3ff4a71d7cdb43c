//! Facade errors: bad arguments, bad options, a failed link and a failed start are kept apart.
//! (Bad bytes from the chassis are not errors: the decoder skips and counts them.)

use std::io;

use kmc_proto::EncodeError;
use robowire_core::NonFinite;
use robowire_serial::SerialError;

/// Everything the KMC facade can fail with.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum KmcError {
    /// Refused before anything was queued or sent.
    #[error("invalid argument: {0}")]
    Argument(#[from] NonFinite),
    /// A [`DriverOptions`](crate::DriverOptions) value out of range.
    #[error("invalid driver option {name}: {reason}")]
    Option {
        /// The option.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The serial link failed (open, disconnect, reopen).
    #[error(transparent)]
    Link(#[from] SerialError),
    /// A frame could not be encoded (cannot happen for validated arguments).
    #[error("cannot encode frame: {0}")]
    Encode(#[from] EncodeError),
    /// The driver is not running.
    #[error("the driver is not running")]
    NotRunning,
    /// [`Driver::start`](crate::Driver::start) on a running driver.
    #[error("the driver is already running")]
    AlreadyRunning,
    /// `realtime_priority` could not be applied.
    #[error(
        "cannot run the driver thread at SCHED_FIFO priority {priority}: {reason} \
         (needs CAP_SYS_NICE or an rtprio limit; set realtime_priority to None for normal scheduling)"
    )]
    RealtimePriority {
        /// The requested priority.
        priority: u8,
        /// What the system said.
        reason: String,
    },
    /// `cpu_affinity` could not be applied.
    #[error("cannot pin the driver thread to CPU {cpu}: {source}")]
    CpuAffinity {
        /// The requested CPU index.
        cpu: usize,
        /// What the system said.
        #[source]
        source: io::Error,
    },
    /// The driver thread or its runtime could not be created.
    #[error("cannot start the driver thread: {0}")]
    Thread(#[source] io::Error),
}
