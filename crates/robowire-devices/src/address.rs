//! Device addresses: one syntax for every device, `KIND:WHERE`.

use std::fmt;
use std::net::IpAddr;
use std::path::PathBuf;
use std::str::FromStr;

/// A device, as every robowire command and library names it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum DeviceAddress {
    /// `kmc:/dev/ttyUSB0`: a KMC chassis on a serial port.
    Kmc(PathBuf),
    /// `zsl1:192.168.234.1`: a ZSL-1's HighLevel interface over UDP.
    Zsl1(IpAddr),
    /// `zsl1w:192.168.234.1`: a ZSL-1W's HighLevel interface over UDP.
    Zsl1w(IpAddr),
    /// `go2:eth0`: a Unitree Go2's low-level interface on the DDS domain of that interface.
    Go2(String),
    /// `hg:eth0` (or `h1:eth0`): a Unitree HG robot's (H1-2; a G1 without its own rules) low-level
    /// interface on that interface. A G1 is `g1:`.
    Hg(String),
    /// `g1:eth0`: a Unitree G1 humanoid on that interface, through `unitree::g1`.
    G1(String),
    /// `spline:/spline_shm`: a ZSL-1's spline daemon on shared memory, watched.
    Spline(String),
    /// `sim:kmc|zsl1|zsl1w|go2|g1|spline`: an in-process simulator of that kind and a client of
    /// it (every kind but `hg` has one: [`DeviceKind::simulated`]).
    Sim(DeviceKind),
}

/// What kind of device an address names, whatever its link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DeviceKind {
    /// A KMC wheeled chassis.
    Kmc,
    /// A ZSL-1 quadruped.
    Zsl1,
    /// A ZSL-1W wheel-legged quadruped.
    Zsl1w,
    /// A Unitree Go2.
    Go2,
    /// A Unitree HG robot (G1, H1-2).
    Hg,
    /// A Unitree G1 humanoid.
    G1,
    /// A ZSL-1's spline daemon.
    Spline,
}

impl DeviceKind {
    /// Every kind, in the order addresses list them.
    pub const ALL: [Self; 7] = [Self::Kmc, Self::Zsl1, Self::Zsl1w, Self::Go2, Self::Hg, Self::G1, Self::Spline];

    /// Whether `sim:` starts one (every kind but the HG family's generic client).
    pub fn simulated(self) -> bool {
        self != Self::Hg
    }

    /// Its name in addresses: `kmc`, `zsl1`, `zsl1w`, `go2`, `hg`, `g1`, `spline`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Kmc => "kmc",
            Self::Zsl1 => "zsl1",
            Self::Zsl1w => "zsl1w",
            Self::Go2 => "go2",
            Self::Hg => "hg",
            Self::G1 => "g1",
            Self::Spline => "spline",
        }
    }
}

/// The addresses every error message shows as examples.
pub const ADDRESS_EXAMPLES: &str = "kmc:/dev/ttyUSB0, zsl1:192.168.234.1, zsl1w:IP, go2:eth0, hg:eth0, g1:eth0, spline:/spline_shm, sim:kmc|zsl1|zsl1w|go2|g1|spline";

/// The reason a `sim:` address of no simulated kind is refused.
const NO_SUCH_SIMULATOR: &str = "no such simulator (kmc, zsl1, zsl1w, go2, g1, spline)";

/// Why an address was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("device address {address:?}: {reason} (addresses look like {ADDRESS_EXAMPLES})")]
pub struct AddressError {
    /// The address given.
    pub address: String,
    /// What is wrong with it.
    pub reason: &'static str,
}

impl FromStr for DeviceAddress {
    type Err = AddressError;

    fn from_str(address: &str) -> Result<Self, AddressError> {
        let refuse = |reason| AddressError { address: address.into(), reason };
        let (kind, rest) = address.split_once(':').ok_or_else(|| refuse("no kind: write KIND:WHERE"))?;
        if rest.is_empty() {
            return Err(refuse("nothing after the kind"));
        }
        let ip = || rest.parse::<IpAddr>().map_err(|_| refuse("not an IP address"));
        let interface = || {
            if rest.len() > 15 || rest.contains(['/', ' ', '\0']) {
                Err(refuse("not a network interface name"))
            } else {
                Ok(rest.to_owned())
            }
        };
        match kind {
            "kmc" => Ok(Self::Kmc(rest.into())),
            "zsl1" => Ok(Self::Zsl1(ip()?)),
            "zsl1w" => Ok(Self::Zsl1w(ip()?)),
            "go2" => Ok(Self::Go2(interface()?)),
            "hg" | "h1" => Ok(Self::Hg(interface()?)),
            "g1" => Ok(Self::G1(interface()?)),
            "spline" if rest.starts_with('/') && rest.len() > 1 && !rest[1..].contains('/') => {
                Ok(Self::Spline(rest.into()))
            }
            "spline" => Err(refuse("not a shared-memory object name (/spline_shm)")),
            "sim" => DeviceKind::ALL
                .into_iter()
                .find(|kind| kind.simulated() && kind.name() == rest)
                .map(Self::Sim)
                .ok_or_else(|| refuse(NO_SUCH_SIMULATOR)),
            _ => Err(refuse("unknown kind")),
        }
    }
}

impl fmt::Display for DeviceAddress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Kmc(path) => write!(f, "kmc:{}", path.display()),
            Self::Zsl1(ip) => write!(f, "zsl1:{ip}"),
            Self::Zsl1w(ip) => write!(f, "zsl1w:{ip}"),
            Self::Go2(interface) => write!(f, "go2:{interface}"),
            Self::Hg(interface) => write!(f, "hg:{interface}"),
            Self::G1(interface) => write!(f, "g1:{interface}"),
            Self::Spline(name) => write!(f, "spline:{name}"),
            Self::Sim(kind) => write!(f, "sim:{}", kind.name()),
        }
    }
}

impl DeviceAddress {
    /// The kind of device it names.
    pub fn kind(&self) -> DeviceKind {
        match self {
            Self::Kmc(_) => DeviceKind::Kmc,
            Self::Zsl1(_) => DeviceKind::Zsl1,
            Self::Zsl1w(_) => DeviceKind::Zsl1w,
            Self::Go2(_) => DeviceKind::Go2,
            Self::Hg(_) => DeviceKind::Hg,
            Self::G1(_) => DeviceKind::G1,
            Self::Spline(_) => DeviceKind::Spline,
            Self::Sim(kind) => *kind,
        }
    }

    /// Whether it names an in-process simulator.
    pub fn is_simulated(&self) -> bool {
        matches!(self, Self::Sim(_))
    }

    /// Whether its link is DDS (on one machine, DDS discovery needs multicast on loopback).
    pub fn uses_dds(&self) -> bool {
        matches!(self.kind(), DeviceKind::Go2 | DeviceKind::Hg | DeviceKind::G1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_parses_prints_back_and_bad_addresses_say_why() {
        for text in [
            "kmc:/dev/ttyUSB0",
            "zsl1:192.168.234.1",
            "zsl1w:10.0.0.2",
            "go2:eth0",
            "hg:enp3s0",
            "g1:eth0",
            "spline:/spline_shm",
            "sim:zsl1",
            "sim:spline",
            "sim:g1",
        ] {
            let address: DeviceAddress = text.parse().unwrap();
            assert_eq!(address.to_string(), text);
        }
        assert_eq!("zsl1w:192.168.234.1".parse::<DeviceAddress>().unwrap().kind(), DeviceKind::Zsl1w);
        assert!("sim:go2".parse::<DeviceAddress>().unwrap().uses_dds());
        let g1: DeviceAddress = "g1:enp3s0".parse().unwrap();
        assert_eq!((g1.kind(), g1.kind().name(), g1.uses_dds()), (DeviceKind::G1, "g1", true));
        let sim: DeviceAddress = "sim:g1".parse().unwrap();
        assert_eq!((sim.kind(), sim.is_simulated(), sim.uses_dds()), (DeviceKind::G1, true, true));
        assert_eq!("hg:eth0".parse::<DeviceAddress>().unwrap().kind(), DeviceKind::Hg, "hg: stays the generic client");
        assert_eq!(
            "h1:eth0".parse::<DeviceAddress>().unwrap(),
            DeviceAddress::Hg("eth0".into()),
            "h1: names the HG client"
        );
        let simulated: Vec<_> = DeviceKind::ALL.into_iter().filter(|k| k.simulated()).map(DeviceKind::name).collect();
        assert_eq!(NO_SUCH_SIMULATOR, format!("no such simulator ({})", simulated.join(", ")), "one list of kinds");
        assert!("sim:hg".parse::<DeviceAddress>().is_err(), "the HG client has no simulator of its own");
        for (bad, reason) in [
            ("kmc", "no kind: write KIND:WHERE"),
            ("kmc:", "nothing after the kind"),
            ("zsl1:robot", "not an IP address"),
            ("go2:a/b", "not a network interface name"),
            ("g1:a-very-long-interface-name", "not a network interface name"),
            ("g1:", "nothing after the kind"),
            ("sim:tank", "no such simulator (kmc, zsl1, zsl1w, go2, g1, spline)"),
            ("spline:spline_shm", "not a shared-memory object name (/spline_shm)"),
            ("tank:1", "unknown kind"),
        ] {
            let e = bad.parse::<DeviceAddress>().unwrap_err();
            assert_eq!((e.address.as_str(), e.reason), (bad, reason));
            assert!(e.to_string().contains("kmc:/dev/ttyUSB0"), "the message shows what an address looks like");
        }
    }
}
