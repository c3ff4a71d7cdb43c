//! The RTPS value types every layer of the crate shares: GUIDs, sequence numbers and their sets,
//! fragment-number sets, locators, timestamps, vendor ids. Each is `Copy`; the sets are bounded
//! by construction (at most 256 members, as the wire allows) and live in their own module,
//! re-exported here.

mod sets;

pub use sets::{FragmentNumberSet, SequenceNumberSet, SetError};

use core::fmt;
use core::net::{Ipv4Addr, Ipv6Addr, SocketAddr, SocketAddrV4, SocketAddrV6};
use core::time::Duration;

/// The 12 bytes that name a participant; every entity of it shares them.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct GuidPrefix(pub [u8; 12]);

impl GuidPrefix {
    /// All zeros: "unknown" on the wire (INFO_DST to everyone).
    pub const UNKNOWN: Self = Self([0; 12]);
}

impl fmt::Debug for GuidPrefix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, b) in self.0.iter().enumerate() {
            if i > 0 && i % 4 == 0 {
                f.write_str(".")?;
            }
            write!(f, "{b:02x}")?;
        }
        Ok(())
    }
}

impl fmt::Display for GuidPrefix {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

/// An entity within a participant: a 3-byte key and a kind byte (writer, reader, builtin or
/// user-defined, keyed or not).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct EntityId(pub [u8; 4]);

impl EntityId {
    /// ENTITYID_UNKNOWN: any reader (or writer) of the destination participant.
    pub const UNKNOWN: Self = Self([0, 0, 0, 0]);
    /// The participant itself.
    pub const PARTICIPANT: Self = Self([0, 0, 1, 0xc1]);
    /// SPDP's builtin participant writer.
    pub const SPDP_WRITER: Self = Self([0, 1, 0, 0xc2]);
    /// SPDP's builtin participant reader.
    pub const SPDP_READER: Self = Self([0, 1, 0, 0xc7]);
    /// SEDP's publications writer (announces this participant's writers).
    pub const SEDP_PUBLICATIONS_WRITER: Self = Self([0, 0, 3, 0xc2]);
    /// SEDP's publications reader.
    pub const SEDP_PUBLICATIONS_READER: Self = Self([0, 0, 3, 0xc7]);
    /// SEDP's subscriptions writer (announces this participant's readers).
    pub const SEDP_SUBSCRIPTIONS_WRITER: Self = Self([0, 0, 4, 0xc2]);
    /// SEDP's subscriptions reader.
    pub const SEDP_SUBSCRIPTIONS_READER: Self = Self([0, 0, 4, 0xc7]);
    /// The participant message writer (WLP: automatic and manual liveliness).
    pub const P2P_MESSAGE_WRITER: Self = Self([0, 2, 0, 0xc2]);
    /// The participant message reader.
    pub const P2P_MESSAGE_READER: Self = Self([0, 2, 0, 0xc7]);

    /// Kind byte of a user-defined writer with a key.
    pub const KIND_WRITER_WITH_KEY: u8 = 0x02;
    /// Kind byte of a user-defined writer without a key.
    pub const KIND_WRITER_NO_KEY: u8 = 0x03;
    /// Kind byte of a user-defined reader without a key.
    pub const KIND_READER_NO_KEY: u8 = 0x04;
    /// Kind byte of a user-defined reader with a key.
    pub const KIND_READER_WITH_KEY: u8 = 0x07;

    /// A user-defined entity: `key` (24 bits, big-endian on the wire) and a kind byte.
    pub const fn user(key: u32, kind: u8) -> Self {
        let k = key.to_be_bytes();
        Self([k[1], k[2], k[3], kind])
    }

    /// The kind byte.
    pub const fn kind(self) -> u8 {
        self.0[3]
    }

    /// A builtin entity (kind bits 0xc0 = 0xc0).
    pub const fn is_builtin(self) -> bool {
        self.0[3] & 0xc0 == 0xc0
    }

    /// A writer (kinds 0x02, 0x03 and their builtin forms 0xc2, 0xc3).
    pub const fn is_writer(self) -> bool {
        matches!(self.0[3] & 0x3f, 0x02 | 0x03)
    }

    /// A reader (kinds 0x04, 0x07 and their builtin forms 0xc4, 0xc7).
    pub const fn is_reader(self) -> bool {
        matches!(self.0[3] & 0x3f, 0x04 | 0x07)
    }
}

impl fmt::Debug for EntityId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:02x}{:02x}{:02x}.{:02x}", self.0[0], self.0[1], self.0[2], self.0[3])
    }
}

/// A globally unique entity name: participant prefix and entity id (16 bytes on the wire).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Guid {
    /// The participant.
    pub prefix: GuidPrefix,
    /// The entity within it.
    pub entity: EntityId,
}

impl Guid {
    /// GUID_UNKNOWN.
    pub const UNKNOWN: Self = Self { prefix: GuidPrefix::UNKNOWN, entity: EntityId::UNKNOWN };

    /// `entity` of participant `prefix`.
    pub const fn new(prefix: GuidPrefix, entity: EntityId) -> Self {
        Self { prefix, entity }
    }

    /// The 16 bytes as on the wire (the same in either endianness).
    pub fn to_bytes(self) -> [u8; 16] {
        let mut b = [0; 16];
        b[..12].copy_from_slice(&self.prefix.0);
        b[12..].copy_from_slice(&self.entity.0);
        b
    }

    /// From the 16 wire bytes.
    pub fn from_bytes(b: [u8; 16]) -> Self {
        let mut prefix = [0; 12];
        prefix.copy_from_slice(&b[..12]);
        Self { prefix: GuidPrefix(prefix), entity: EntityId([b[12], b[13], b[14], b[15]]) }
    }
}

impl fmt::Debug for Guid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}:{:?}", self.prefix, self.entity)
    }
}

impl fmt::Display for Guid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

/// A writer's sample number. On the wire a signed high word and an unsigned low word; valid
/// numbers are 1 ..= `i64::MAX` (`SequenceNumber::UNKNOWN` is the only negative one used).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct SequenceNumber(pub i64);

impl SequenceNumber {
    /// SEQUENCENUMBER_UNKNOWN: high −1, low 0.
    pub const UNKNOWN: Self = Self(-(1 << 32));
    /// The first number a writer gives.
    pub const FIRST: Self = Self(1);

    /// From the wire's two words.
    pub const fn from_parts(high: i32, low: u32) -> Self {
        Self(((high as i64) << 32) | low as i64)
    }

    /// The wire's two words: (high, low).
    pub const fn to_parts(self) -> (i32, u32) {
        ((self.0 >> 32) as i32, self.0 as u32)
    }

    /// A number a writer can give (≥ 1).
    pub const fn is_valid(self) -> bool {
        self.0 >= 1
    }

    /// The next number, `None` past `i64::MAX`.
    pub const fn checked_next(self) -> Option<Self> {
        match self.0.checked_add(1) {
            Some(n) => Some(Self(n)),
            None => None,
        }
    }
}

impl fmt::Debug for SequenceNumber {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.0)
    }
}

/// Where an endpoint listens: a kind, a port and a 16-byte address (24 bytes on the wire).
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Locator {
    /// LOCATOR_KIND_*: 1 UDPv4, 2 UDPv6; others (shared memory, TCP) kept as they came.
    pub kind: i32,
    /// The port (0 when invalid).
    pub port: u32,
    /// The address; an IPv4 address sits in the last four bytes.
    pub address: [u8; 16],
}

impl Locator {
    /// LOCATOR_KIND_UDPv4.
    pub const KIND_UDPV4: i32 = 1;
    /// LOCATOR_KIND_UDPv6.
    pub const KIND_UDPV6: i32 = 2;
    /// LOCATOR_INVALID.
    pub const INVALID: Self = Self { kind: -1, port: 0, address: [0; 16] };

    /// A UDPv4 locator.
    pub fn udpv4(addr: SocketAddrV4) -> Self {
        let mut address = [0; 16];
        address[12..].copy_from_slice(&addr.ip().octets());
        Self { kind: Self::KIND_UDPV4, port: u32::from(addr.port()), address }
    }

    /// A UDP locator from either address family.
    pub fn udp(addr: SocketAddr) -> Self {
        match addr {
            SocketAddr::V4(a) => Self::udpv4(a),
            SocketAddr::V6(a) => Self { kind: Self::KIND_UDPV6, port: u32::from(a.port()), address: a.ip().octets() },
        }
    }

    /// The socket address of a UDP locator whose port fits 16 bits; `None` for other kinds.
    pub fn socket_addr(&self) -> Option<SocketAddr> {
        let port = u16::try_from(self.port).ok().filter(|&p| p != 0)?;
        match self.kind {
            Self::KIND_UDPV4 => {
                let a = &self.address[12..];
                Some(SocketAddr::V4(SocketAddrV4::new(Ipv4Addr::new(a[0], a[1], a[2], a[3]), port)))
            }
            Self::KIND_UDPV6 => Some(SocketAddr::V6(SocketAddrV6::new(Ipv6Addr::from(self.address), port, 0, 0))),
            _ => None,
        }
    }

    /// Whether the address is IPv4 multicast (224.0.0.0/4) or IPv6 multicast.
    pub fn is_multicast(&self) -> bool {
        self.socket_addr().is_some_and(|a| a.ip().is_multicast())
    }
}

impl fmt::Debug for Locator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.socket_addr() {
            Some(a) => write!(f, "udp/{a}"),
            None => write!(f, "locator(kind {}, port {}, {:02x?})", self.kind, self.port, self.address),
        }
    }
}

/// An RTPS `Time_t`: seconds and 1/2³² fractions since the Unix epoch (INFO_TS, source
/// timestamps). This is a wall-clock value the caller supplies; the core never reads a clock.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, Debug)]
pub struct Timestamp {
    /// Whole seconds.
    pub seconds: i32,
    /// Fractions of a second, 1/2³² each.
    pub fraction: u32,
}

impl Timestamp {
    /// TIME_ZERO.
    pub const ZERO: Self = Self { seconds: 0, fraction: 0 };
    /// TIME_INVALID.
    pub const INVALID: Self = Self { seconds: -1, fraction: u32::MAX };
    /// TIME_INFINITE.
    pub const INFINITE: Self = Self { seconds: i32::MAX, fraction: u32::MAX };

    /// From nanoseconds since the Unix epoch (saturating at TIME_INFINITE's seconds).
    pub fn from_unix_nanos(ns: u64) -> Self {
        let seconds = i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX);
        let fraction = (((ns % 1_000_000_000) << 32) / 1_000_000_000) as u32;
        Self { seconds, fraction }
    }

    /// Nanoseconds since the Unix epoch; `None` before it (or for TIME_INVALID).
    pub fn to_unix_nanos(self) -> Option<u64> {
        let s = u64::try_from(self.seconds).ok()?;
        Some(s * 1_000_000_000 + ((u64::from(self.fraction) * 1_000_000_000) >> 32))
    }
}

/// An RTPS `Duration_t` (lease durations, QoS periods): seconds and 1/2³² fractions;
/// `DdsDuration::INFINITE` is the DDS infinite duration.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, Debug)]
pub struct DdsDuration {
    /// Whole seconds.
    pub seconds: i32,
    /// Fractions of a second, 1/2³² each.
    pub fraction: u32,
}

impl DdsDuration {
    /// DURATION_ZERO.
    pub const ZERO: Self = Self { seconds: 0, fraction: 0 };
    /// DURATION_INFINITE.
    pub const INFINITE: Self = Self { seconds: i32::MAX, fraction: u32::MAX };

    /// From a `Duration` (saturating to INFINITE).
    pub fn from_duration(d: Duration) -> Self {
        match i32::try_from(d.as_secs()) {
            Ok(seconds) if seconds < i32::MAX => {
                Self { seconds, fraction: ((u64::from(d.subsec_nanos()) << 32) / 1_000_000_000) as u32 }
            }
            _ => Self::INFINITE,
        }
    }

    /// The duration; `None` for INFINITE; a negative duration is zero.
    pub fn to_duration(self) -> Option<Duration> {
        if self == Self::INFINITE {
            return None;
        }
        let s = u64::try_from(self.seconds).unwrap_or(0);
        let frac = if self.seconds < 0 { 0 } else { self.fraction };
        Some(Duration::new(s, ((u64::from(frac) * 1_000_000_000) >> 32) as u32))
    }
}

/// The implementation that sent a message (RTPS vendor id, two bytes).
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct VendorId(pub [u8; 2]);

impl VendorId {
    /// Unknown.
    pub const UNKNOWN: Self = Self([0, 0]);
    /// RTI Connext DDS.
    pub const RTI_CONNEXT: Self = Self([1, 1]);
    /// OpenDDS (OCI).
    pub const OPENDDS: Self = Self([1, 3]);
    /// eProsima Fast DDS.
    pub const FAST_DDS: Self = Self([1, 0x0f]);
    /// Eclipse CycloneDDS.
    pub const CYCLONEDDS: Self = Self([1, 0x10]);
    /// Atostek RustDDS.
    pub const RUSTDDS: Self = Self([1, 0x12]);
    /// robowire's own RTPS (an id outside the OMG's assigned range; robowire sends no
    /// vendor-specific parameters).
    pub const ROBOWIRE: Self = Self([1, 0xf2]);

    /// The implementation's name, where known.
    pub fn name(self) -> Option<&'static str> {
        Some(match self.0 {
            [1, 1] => "RTI Connext DDS",
            [1, 2] => "ADLink OpenSplice",
            [1, 3] => "OpenDDS",
            [1, 4] => "Milsoft Mil-DDS",
            [1, 5] => "Kongsberg InterCOM DDS",
            [1, 6] => "TwinOaks CoreDX",
            [1, 7] => "Lakota Technical Solutions",
            [1, 8] => "ICOUP Consulting",
            [1, 9] => "ETRI Diamond DDS",
            [1, 0x0a] => "RTI Connext DDS Micro",
            [1, 0x0b] => "ADLink Vortex Cafe",
            [1, 0x0c] => "PrismTech",
            [1, 0x0d] => "ADLink Vortex Lite",
            [1, 0x0e] => "Technicolor Qeo",
            [1, 0x0f] => "eProsima Fast DDS",
            [1, 0x10] => "Eclipse CycloneDDS",
            [1, 0x11] => "GurumNetworks GurumDDS",
            [1, 0x12] => "Atostek RustDDS",
            [1, 0x13] => "Zhenrong DDS",
            [1, 0x14] => "S2E Software Systems Dust DDS",
            [1, 0xf2] => "robowire",
            _ => return None,
        })
    }
}

impl fmt::Debug for VendorId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.name() {
            Some(n) => write!(f, "{:02x}{:02x} ({n})", self.0[0], self.0[1]),
            None => write!(f, "{:02x}{:02x}", self.0[0], self.0[1]),
        }
    }
}

/// The RTPS protocol version of a message (2.1 … 2.5 from the implementations robowire meets).
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Debug)]
pub struct ProtocolVersion {
    /// Major version (2).
    pub major: u8,
    /// Minor version.
    pub minor: u8,
}

impl ProtocolVersion {
    /// RTPS 2.4, what robowire sends (any 2.x is parsed).
    pub const V2_4: Self = Self { major: 2, minor: 4 };
}
