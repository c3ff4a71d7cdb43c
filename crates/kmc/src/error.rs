//! Facade errors: bad arguments, bad options, a failed link and a failed start are kept apart.
//! (Bad bytes from the chassis are not errors: the decoder skips and counts them.)

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
    /// The driver's stream has ended (closed, or its thread died): nothing can be queued.
    #[error("the driver is not running")]
    NotRunning,
    /// A thread could not be placed (priority, CPU, memory lock) or started.
    #[error("the driver's threads")]
    Thread(#[from] RtError),
}
