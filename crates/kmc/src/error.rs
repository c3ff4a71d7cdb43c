//! Facade errors: bad arguments, bad options, a failed link and a failed start are kept apart.
//! (Bad bytes from the chassis are not errors: the decoder skips and counts them.)

use std::io;

use kmc_proto::EncodeError;
use robowire_core::NonFinite;
use robowire_rt::RtError;
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
    /// `realtime_priority` or `cpu_affinity` could not be applied to the driver thread.
    #[error("the driver thread could not be placed as asked")]
    Placement(#[from] RtError),
    /// The driver thread or its runtime could not be created.
    #[error("cannot start the driver thread")]
    Thread(#[source] io::Error),
}
