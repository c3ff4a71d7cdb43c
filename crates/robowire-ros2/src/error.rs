//! Why the bridge could not start or stopped.

use robowire_dds::DdsError;
use robowire_devices::{DeviceAddress, DeviceError};

/// Why the bridge could not start or stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BridgeError {
    /// A bad option.
    #[error("{0}")]
    Option(String),
    /// DDS.
    #[error(transparent)]
    Dds(#[from] DdsError),
    /// A device could not be opened, or refused what the bridge needs of it.
    #[error("{address}")]
    Device {
        /// The device's address.
        address: DeviceAddress,
        /// Why.
        #[source]
        source: DeviceError,
    },
}
