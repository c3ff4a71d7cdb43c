//! ZSL-1 links described to a recorder (feature `serde`): the HighLevel and LowLevel UDP links,
//! each frame one datagram decoded strictly by its length (either link's datagrams decode on
//! either description, as they always have in captures), as JSON under `zsl1.<datagram>`.
//!
//! ```
//! use robowire_core::Direction;
//! use robowire_core::json::LinkDescription;
//! use zsl_proto::description::HighLevelDatagrams;
//! use zsl_proto::udp::{HighLevelCommand, Model};
//!
//! let datagram = HighLevelCommand::stand_up().encode(Model::Zsl1);
//! let frame = HighLevelDatagrams.decode(Direction::Sent, &datagram).unwrap();
//! assert_eq!((HighLevelDatagrams.protocol(), frame.schema), ("zsl1.high_level", "zsl1.HighLevelCommand"));
//! assert_eq!(frame.value["mode_name"], "Stand");
//! assert!(HighLevelDatagrams.decode(Direction::Received, &[1, 2, 3]).is_err());
//! ```

use robowire_core::Direction;
use robowire_core::json::{FrameError, JsonFrame, LinkDescription};

use crate::udp::AnyDatagram;

/// The layout both links follow.
const LAYOUT: &str = "zsl1-udp, vendor SDK v0.2.7";

/// A HighLevel link (`zsl1.high_level`): 40-byte commands, 560-byte states.
#[derive(Debug, Clone, Copy, Default)]
pub struct HighLevelDatagrams;

/// A LowLevel link (`zsl1.low_level`): 248-byte commands, 272-byte states.
#[derive(Debug, Clone, Copy, Default)]
pub struct LowLevelDatagrams;

/// Every ZSL-1 link.
pub static DESCRIPTIONS: [&dyn LinkDescription; 2] = [&HighLevelDatagrams, &LowLevelDatagrams];

/// A datagram of either link as JSON: `zsl1.HighLevelState`, ….
fn decode(protocol: &'static str, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    let datagram = AnyDatagram::decode(frame).map_err(|e| FrameError::decode(protocol, frame, e))?;
    let schema = match datagram {
        AnyDatagram::HighLevelCommand(_) => "zsl1.HighLevelCommand",
        AnyDatagram::HighLevelState(_) => "zsl1.HighLevelState",
        AnyDatagram::LowLevelCommand(_) => "zsl1.LowLevelCommand",
        AnyDatagram::LowLevelState(_) => "zsl1.LowLevelState",
    };
    JsonFrame::serialize(protocol, schema, &datagram)
}

impl LinkDescription for HighLevelDatagrams {
    fn protocol(&self) -> &'static str {
        "zsl1.high_level"
    }

    fn layout(&self) -> &'static str {
        LAYOUT
    }

    fn decode(&self, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
        decode(self.protocol(), frame)
    }
}

impl LinkDescription for LowLevelDatagrams {
    fn protocol(&self) -> &'static str {
        "zsl1.low_level"
    }

    fn layout(&self) -> &'static str {
        LAYOUT
    }

    fn decode(&self, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
        decode(self.protocol(), frame)
    }
}
