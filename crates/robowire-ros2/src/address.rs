//! `--device` addresses: one syntax for every device.

use std::path::PathBuf;
use std::str::FromStr;

/// A device to bridge.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DeviceAddress {
    /// `kmc:/dev/ttyUSB0`: a KMC chassis on a serial port.
    Kmc(PathBuf),
    /// `zsl1:192.168.234.1` or `zsl1w:…`: a ZSL-1 / ZSL-1W HighLevel interface.
    Zsl {
        /// ZSL-1W (wheel-legged) rather than ZSL-1.
        wheeled: bool,
        /// The robot's IP.
        ip: std::net::IpAddr,
    },
    /// `go2:eth0`: a Unitree Go2 on the DDS domain of that interface.
    Go2 {
        /// The network interface.
        interface: String,
    },
    /// `sim:kmc|zsl1|zsl1w|go2`: an in-process simulator.
    Sim(SimKind),
}

/// The simulators a bridge can start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimKind {
    /// A KMC chassis on a pseudo-terminal.
    Kmc,
    /// A ZSL-1 on loopback UDP.
    Zsl1,
    /// A ZSL-1W on loopback UDP.
    Zsl1w,
    /// A Go2 on DDS.
    Go2,
}

/// Why a `--device` address was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "--device {address:?}: {reason} (kmc:/dev/ttyUSB0, zsl1:192.168.234.1, zsl1w:IP, go2:eth0, sim:kmc|zsl1|zsl1w|go2)"
)]
pub struct AddressError {
    /// The address given.
    pub address: String,
    /// What is wrong with it.
    pub reason: String,
}

impl FromStr for DeviceAddress {
    type Err = AddressError;

    fn from_str(address: &str) -> Result<Self, AddressError> {
        let refuse = |reason: &str| AddressError { address: address.into(), reason: reason.into() };
        let (kind, rest) = address.split_once(':').ok_or_else(|| refuse("no kind: KIND:WHERE"))?;
        if rest.is_empty() {
            return Err(refuse("nothing after the kind"));
        }
        match kind {
            "kmc" => Ok(Self::Kmc(rest.into())),
            "zsl1" | "zsl1w" => {
                Ok(Self::Zsl { wheeled: kind == "zsl1w", ip: rest.parse().map_err(|_| refuse("not an IP address"))? })
            }
            "go2" => Ok(Self::Go2 { interface: rest.into() }),
            "sim" => Ok(Self::Sim(match rest {
                "kmc" => SimKind::Kmc,
                "zsl1" => SimKind::Zsl1,
                "zsl1w" => SimKind::Zsl1w,
                "go2" => SimKind::Go2,
                _ => return Err(refuse("no such simulator")),
            })),
            _ => Err(refuse("unknown kind")),
        }
    }
}

impl DeviceAddress {
    /// The kind's name, the stem of its default namespace: `kmc`, `zsl1`, `zsl1w`, `go2`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Kmc(_) | Self::Sim(SimKind::Kmc) => "kmc",
            Self::Zsl { wheeled: false, .. } | Self::Sim(SimKind::Zsl1) => "zsl1",
            Self::Zsl { wheeled: true, .. } | Self::Sim(SimKind::Zsl1w) => "zsl1w",
            Self::Go2 { .. } | Self::Sim(SimKind::Go2) => "go2",
        }
    }
}

/// The namespace of each device: with one device and no `--namespace`, the root; with one
/// device and a namespace, that namespace; with several, `NS/KIND INDEX`, the index counted per
/// kind (`/kmc0`, `/kmc1`, `/zsl1_0`: an underscore after a kind that ends in a digit).
pub fn namespaces(devices: &[DeviceAddress], namespace: Option<&str>) -> Vec<String> {
    let base = namespace.map(|ns| ns.trim_matches('/')).filter(|ns| !ns.is_empty());
    if devices.len() == 1 {
        return vec![base.map(|ns| format!("/{ns}")).unwrap_or_default()];
    }
    devices
        .iter()
        .enumerate()
        .map(|(n, device)| {
            let kind = device.kind();
            let i = devices[..n].iter().filter(|d| d.kind() == kind).count();
            let sep = if kind.ends_with(|c: char| c.is_ascii_digit()) { "_" } else { "" };
            let own = format!("{kind}{sep}{i}");
            match base {
                Some(ns) => format!("/{ns}/{own}"),
                None => format!("/{own}"),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_parses_and_bad_addresses_say_why() {
        assert_eq!("kmc:/dev/ttyUSB0".parse(), Ok(DeviceAddress::Kmc("/dev/ttyUSB0".into())));
        assert_eq!(
            "zsl1w:192.168.234.1".parse(),
            Ok(DeviceAddress::Zsl { wheeled: true, ip: [192, 168, 234, 1].into() })
        );
        assert_eq!("go2:eth0".parse(), Ok(DeviceAddress::Go2 { interface: "eth0".into() }));
        assert_eq!("sim:zsl1".parse(), Ok(DeviceAddress::Sim(SimKind::Zsl1)));
        for bad in ["kmc", "kmc:", "zsl1:robot", "sim:tank", "tank:1"] {
            let e = bad.parse::<DeviceAddress>().unwrap_err();
            assert_eq!(e.address, bad);
        }
    }

    #[test]
    fn one_device_is_at_the_root_several_by_kind_and_index() {
        let kmc: DeviceAddress = "sim:kmc".parse().unwrap();
        let dog: DeviceAddress = "sim:zsl1".parse().unwrap();
        assert_eq!(namespaces(std::slice::from_ref(&kmc), None), [""]);
        assert_eq!(namespaces(std::slice::from_ref(&kmc), Some("/robot1/")), ["/robot1"]);
        assert_eq!(namespaces(&[kmc.clone(), dog.clone(), kmc.clone()], None), ["/kmc0", "/zsl1_0", "/kmc1"]);
        assert_eq!(namespaces(&[kmc, dog], Some("lab")), ["/lab/kmc0", "/lab/zsl1_0"]);
    }
}
