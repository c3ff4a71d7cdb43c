//! Why a device could not be opened or did not do what it was asked, and such an error on one
//! line.

use crate::{AddressError, DeviceAddress};

/// Why a device could not be opened or did not do what it was asked; the facade's error is the
/// source.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DeviceError {
    /// The address is not one.
    #[error(transparent)]
    Address(#[from] AddressError),
    /// The KMC chassis.
    #[cfg(feature = "kmc")]
    #[error("KMC chassis")]
    Kmc(#[from] ::kmc::KmcError),
    /// A ZSL-1 could not be reached.
    #[cfg(feature = "zsl1")]
    #[error("ZSL-1 client")]
    ZslConnect(#[from] ::zsl::udp::ConnectError),
    /// A ZSL-1 call did not go out.
    #[cfg(feature = "zsl1")]
    #[error("ZSL-1 call")]
    ZslCall(#[from] ::zsl::udp::CallError),
    /// A Unitree robot's client.
    #[cfg(feature = "unitree")]
    #[error("Unitree low-level client")]
    Unitree(#[from] unitree::UnitreeError),
    /// A Unitree G1's client.
    #[cfg(feature = "unitree")]
    #[error("Unitree G1 client")]
    G1(#[from] unitree::g1::G1Error),
    /// The spline daemon's shared memory.
    #[cfg(feature = "zsl1")]
    #[error("spline shared memory")]
    Spline(#[from] ::zsl::SplineError),
    /// A simulator could not start.
    #[error("the simulator of {address}")]
    Simulator {
        /// The address.
        address: DeviceAddress,
        /// Why.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A device kind this build leaves out (its feature of robowire-devices is off).
    #[error("{address}: this build has no {kind} devices (the `{feature}` feature of robowire-devices is off)")]
    NotBuilt {
        /// The address.
        address: DeviceAddress,
        /// The kind.
        kind: &'static str,
        /// The feature that builds it.
        feature: &'static str,
    },
    /// A `sim:` address in a build without the `sim` feature.
    #[error("{address}: this build has no simulators (the `sim` feature of robowire-devices is off)")]
    NoSimulators {
        /// The address.
        address: DeviceAddress,
    },
    /// Physics asked of a device without a simulated body.
    #[error("{address} has no physics: MuJoCo simulates the bodies of sim:go2 and sim:g1 only")]
    NoPhysics {
        /// The address.
        address: DeviceAddress,
    },
    /// Physics asked of a build without MuJoCo.
    #[error(
        "{address}: this build is without physics: build it with the `mujoco` feature (robowire's, robowire-py's \
         or robowire-devices': `cargo build --release -p robowire --features mujoco`), MUJOCO_DYNAMIC_LINK_DIR \
         naming a directory with MuJoCo 3.17.0's libmujoco.so (`cargo xtask mujoco` fetches it), and run it with \
         that directory on LD_LIBRARY_PATH"
    )]
    PhysicsNotBuilt {
        /// The address.
        address: DeviceAddress,
    },
    /// The device has no such action.
    #[error("no service {service:?} on this device")]
    NoSuchService {
        /// The name asked for.
        service: String,
    },
    /// The device cannot do this (a Go2 is not driven by a velocity).
    #[error("this device does not support {what}")]
    Unsupported {
        /// What was asked.
        what: &'static str,
    },
}

/// An error and its sources on one line, each once: `ZSL-1 call: refused in mode LieDown: …`.
pub fn error_chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        if !text.contains(&cause_text) {
            text.push_str(": ");
            text.push_str(&cause_text);
        }
        source = cause.source();
    }
    text
}
