//! ZSL-1 links described to a recorder (feature `serde`): the HighLevel and LowLevel UDP links,
//! each frame one datagram decoded strictly by its length (either link's datagrams decode on
//! either description, as they always have in captures), as JSON under `zsl1.<datagram>`.
//!
//! ```
//! use robowire_core::Direction;
//! use robowire_core::json::LinkDescription;
//! use zsl_proto::description::HIGH_LEVEL;
//! use zsl_proto::udp::{HighLevelCommand, Model};
//!
//! let datagram = HighLevelCommand::stand_up().encode(Model::Zsl1);
//! let frame = HIGH_LEVEL.decode(Direction::Sent, &datagram).unwrap();
//! assert_eq!((HIGH_LEVEL.protocol(), frame.schema), ("zsl1.high_level", "zsl1.HighLevelCommand"));
//! assert_eq!(frame.value["mode_name"], "Stand");
//! assert!(HIGH_LEVEL.decode(Direction::Received, &[1, 2, 3]).is_err());
//! ```

use robowire_core::Direction;
use robowire_core::json::{
    ANY_VALUE, FrameError, JsonFrame, LinkDescription, LinkPlots, LinkProtocol, PanelSpec, SeriesSpec,
};

use crate::udp::AnyDatagram;

/// The layout both links follow.
const LAYOUT: &str = "zsl1-udp, vendor SDK v0.2.7";

/// A HighLevel link (`zsl1.high_level`): 40-byte commands, 560-byte states.
pub static HIGH_LEVEL: LinkProtocol =
    LinkProtocol { name: "zsl1.high_level", layout: LAYOUT, decode: datagram, wire_schema: None };

/// A LowLevel link (`zsl1.low_level`): 248-byte commands, 272-byte states.
pub static LOW_LEVEL: LinkProtocol =
    LinkProtocol { name: "zsl1.low_level", layout: LAYOUT, decode: datagram, wire_schema: None };

/// What `robowire plot` draws of a HighLevel link recorded at the client: commanded against
/// observed motion, the mode, the body's height.
pub static PLOTS: [LinkPlots; 1] = [LinkPlots {
    protocol: "zsl1.high_level",
    panels: &[
        PanelSpec {
            title: "forward velocity: commanded and observed (body frame)",
            y_label: "velocity (m/s)",
            series: &[command("commanded vx", "/vx_mps"), state("observed vx", "/body_velocity_mps/0")],
        },
        PanelSpec {
            title: "yaw rate: commanded and observed (gyro z)",
            y_label: "yaw rate (rad/s)",
            series: &[command("commanded", "/yaw_rate_radps"), state("observed", "/gyro_radps/2")],
        },
        PanelSpec {
            title: "control mode: commanded and reported",
            y_label: "mode (number)",
            series: &[command("commanded", "/mode"), state("reported", "/mode")],
        },
        PanelSpec { title: "body height", y_label: "height (m)", series: &[state("position z", "/position_m/2")] },
    ],
}];

/// A series of the commands the client sent.
const fn command(name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec {
        name,
        direction: Direction::Sent,
        schema: "zsl1.HighLevelCommand",
        pointer,
        held: true,
        range: ANY_VALUE,
    }
}

/// A series of the states the client received.
const fn state(name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec {
        name,
        direction: Direction::Received,
        schema: "zsl1.HighLevelState",
        pointer,
        held: false,
        range: ANY_VALUE,
    }
}

/// Every ZSL-1 link.
pub static DESCRIPTIONS: [&dyn LinkDescription; 2] = [&HIGH_LEVEL, &LOW_LEVEL];

/// A datagram of either link as JSON: `zsl1.HighLevelState`, ….
fn datagram(protocol: &'static str, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    JsonFrame::parse(protocol, frame, AnyDatagram::decode, |datagram| match datagram {
        AnyDatagram::HighLevelCommand(_) => "zsl1.HighLevelCommand",
        AnyDatagram::HighLevelState(_) => "zsl1.HighLevelState",
        AnyDatagram::LowLevelCommand(_) => "zsl1.LowLevelCommand",
        AnyDatagram::LowLevelState(_) => "zsl1.LowLevelState",
    })
}
