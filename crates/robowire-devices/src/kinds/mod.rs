//! The device kinds, each behind its feature (`kmc`, `zsl1`, `unitree`): how each is opened, its
//! simulator with it (feature `sim`), and what it observes. [`open`] picks the kind by address.

#[cfg(feature = "unitree")]
pub(crate) mod g1;
#[cfg(feature = "kmc")]
pub(crate) mod kmc;
#[cfg(feature = "zsl1")]
pub(crate) mod spline;
#[cfg(feature = "unitree")]
pub(crate) mod unitree;
#[cfg(feature = "zsl1")]
pub(crate) mod zsl1;

use crate::facade::Facade;
use crate::{DeviceAddress, DeviceError, OpenOptions};

/// The client of the real device at `address` (a `sim:` address is [`crate::sim`]'s).
pub(crate) fn open(address: &DeviceAddress, options: &OpenOptions) -> Result<Box<dyn Facade>, DeviceError> {
    Ok(match address {
        #[cfg(feature = "kmc")]
        DeviceAddress::Kmc(path) => kmc::open(path, options)?,
        #[cfg(feature = "zsl1")]
        DeviceAddress::Zsl1(ip) => zsl1::open(*ip, ::zsl::udp::Model::Zsl1, options)?,
        #[cfg(feature = "zsl1")]
        DeviceAddress::Zsl1w(ip) => zsl1::open(*ip, ::zsl::udp::Model::Zsl1W, options)?,
        #[cfg(feature = "zsl1")]
        DeviceAddress::Spline(name) => spline::open(name, options)?,
        #[cfg(feature = "unitree")]
        DeviceAddress::Go2(interface) => unitree::open::<::unitree::Go2>(interface, options)?,
        #[cfg(feature = "unitree")]
        DeviceAddress::Hg(interface) => unitree::open::<::unitree::Hg>(interface, options)?,
        #[cfg(feature = "unitree")]
        DeviceAddress::G1(interface) => g1::open(interface, options)?,
        other => return Err(not_built(other)),
    })
}

/// The error for an address whose kind this build leaves out.
pub(crate) fn not_built(address: &DeviceAddress) -> DeviceError {
    use crate::DeviceKind;
    let (kind, feature) = match address {
        DeviceAddress::Kmc(_) | DeviceAddress::Sim(DeviceKind::Kmc) => ("KMC chassis", "kmc"),
        DeviceAddress::Zsl1(_)
        | DeviceAddress::Zsl1w(_)
        | DeviceAddress::Spline(_)
        | DeviceAddress::Sim(DeviceKind::Zsl1 | DeviceKind::Zsl1w | DeviceKind::Spline) => ("ZSL-1", "zsl1"),
        DeviceAddress::Go2(_) | DeviceAddress::Hg(_) | DeviceAddress::G1(_) | DeviceAddress::Sim(_) => {
            ("Unitree", "unitree")
        }
    };
    DeviceError::NotBuilt { address: address.clone(), kind, feature }
}

#[cfg(all(test, feature = "kmc", feature = "zsl1", feature = "unitree"))]
mod tests {
    use std::time::Duration;

    use crate::OpenOptions;

    #[test]
    fn a_state_timeout_reaches_every_facade_and_none_keeps_their_defaults() {
        let quick = OpenOptions { state_timeout: Some(Duration::from_millis(250)), ..OpenOptions::default() };
        let zsl_client = || ::zsl::udp::ClientOptions::high_level([127, 0, 0, 1].into(), 0, [127, 0, 0, 1].into());
        let zsl_options = super::zsl1::client_options;
        let (go2_options, g1_options) =
            (super::unitree::low_level_options::<::unitree::Go2>, super::g1::client_options);

        assert_eq!(super::kmc::driver_options(&quick).state_timeout, Duration::from_millis(250));
        assert_eq!(zsl_options(zsl_client(), ::zsl::udp::Model::Zsl1W, &quick).watchdog, Duration::from_millis(250));
        assert_eq!(go2_options(Some("lo"), &quick).state_timeout, Duration::from_millis(250));
        assert_eq!(g1_options(Some("lo"), &quick).low_level.state_timeout, Duration::from_millis(250));

        let default = OpenOptions::default();
        assert_eq!(super::kmc::driver_options(&default).state_timeout, ::kmc::DriverOptions::default().state_timeout);
        let zsl = zsl_options(zsl_client(), ::zsl::udp::Model::Zsl1W, &default);
        assert_eq!((zsl.watchdog, zsl.model), (zsl_client().watchdog, ::zsl::udp::Model::Zsl1W));
        assert_eq!(go2_options(None, &default).state_timeout, ::unitree::STATE_TIMEOUT);
        assert_eq!(g1_options(None, &default).low_level.state_timeout, ::unitree::STATE_TIMEOUT);
    }
}
