//! The protocols a link can carry, and how their frames decode for the JSON channels.

use serde_json::Value;

/// What a link carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Protocol {
    /// ZSL-1 / ZSL-1W HighLevel datagrams (40-byte commands, 560-byte states).
    ZslHighLevel,
    /// ZSL-1 LowLevel datagrams (248-byte commands, 272-byte states).
    ZslLowLevel,
}

impl Protocol {
    /// The name in the capture's metadata: `zsl1.high_level`, `zsl1.low_level`.
    pub fn name(self) -> &'static str {
        match self {
            Self::ZslHighLevel => "zsl1.high_level",
            Self::ZslLowLevel => "zsl1.low_level",
        }
    }

    /// The protocol named `name` in a capture.
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::ZslHighLevel, Self::ZslLowLevel].into_iter().find(|p| p.name() == name)
    }

    /// The layout the protocol's frames follow (the spec they were measured against).
    pub fn layout(self) -> &'static str {
        match self {
            Self::ZslHighLevel | Self::ZslLowLevel => "zsl1-udp, vendor SDK v0.2.7",
        }
    }

    /// A frame decoded: its schema name (`zsl1.HighLevelState`) and its JSON, or why not.
    pub fn decode(self, bytes: &[u8]) -> Result<(&'static str, Value), String> {
        match self {
            Self::ZslHighLevel | Self::ZslLowLevel => {
                let datagram = zsl_proto::udp::AnyDatagram::decode(bytes).map_err(|e| e.to_string())?;
                let name = match datagram {
                    zsl_proto::udp::AnyDatagram::HighLevelCommand(_) => "zsl1.HighLevelCommand",
                    zsl_proto::udp::AnyDatagram::HighLevelState(_) => "zsl1.HighLevelState",
                    zsl_proto::udp::AnyDatagram::LowLevelCommand(_) => "zsl1.LowLevelCommand",
                    zsl_proto::udp::AnyDatagram::LowLevelState(_) => "zsl1.LowLevelState",
                };
                Ok((name, serde_json::to_value(datagram).map_err(|e| e.to_string())?))
            }
        }
    }
}
