//! KMC chassis links described to a recorder (feature `serde`): each frame one whole frame as
//! the stream decoders cut it, decoded strictly ([`HostFrame::parse`] for host → chassis,
//! [`ChassisFrame::parse`] for chassis → host) and named `kmc.<Frame>`. The two frame sets share
//! IDs (`0xB3`, `0xAF`), so which one a frame is follows from which end recorded the link and
//! which way the frame went: [`HostLink`] for the host's end (a driver), [`ChassisLink`] for the
//! chassis' end (a simulator).
//!
//! ```
//! use kmc_proto::description::{ChassisLink, HostLink};
//! use robowire_core::Direction;
//! use robowire_core::json::LinkDescription;
//!
//! let speed = [0xb3, 0x00, 0x00, 0xa0, 0x3f];
//! let frame = HostLink.decode(Direction::Received, &speed).unwrap();
//! assert_eq!((frame.schema, frame.value["speed_mps"].as_f64()), ("kmc.VehicleSpeed", Some(1.25)));
//! assert_eq!(ChassisLink.decode(Direction::Sent, &speed).unwrap().schema, "kmc.VehicleSpeed");
//! assert!(HostLink.decode(Direction::Sent, &speed).is_err(), "a host sends 0xB3 alone");
//! ```

use robowire_core::Direction;
use robowire_core::json::{FrameError, JsonFrame, LinkDescription};

use crate::{ChassisFrame, HostFrame};

/// The layout both ends follow.
const LAYOUT: &str = "kmc-uart, one whole frame per record";

/// A chassis link recorded at the host (`kmc.host`): it sends host frames and receives chassis
/// frames.
#[derive(Debug, Clone, Copy, Default)]
pub struct HostLink;

/// A chassis link recorded at the chassis (`kmc.chassis`): it sends chassis frames and receives
/// host frames.
#[derive(Debug, Clone, Copy, Default)]
pub struct ChassisLink;

/// Both ends of a KMC link.
pub static DESCRIPTIONS: [&dyn LinkDescription; 2] = [&HostLink, &ChassisLink];

/// A host → chassis frame as JSON: `kmc.PcControl`, `kmc.VehicleSpeedRequest`, `kmc.AfRequest`.
fn host_frame(protocol: &'static str, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    let parsed = HostFrame::parse(frame).map_err(|e| FrameError::decode(protocol, frame, e))?;
    let schema = match parsed {
        HostFrame::PcControl(_) => "kmc.PcControl",
        HostFrame::VehicleSpeedRequest => "kmc.VehicleSpeedRequest",
        HostFrame::Af(_) => "kmc.AfRequest",
    };
    JsonFrame::serialize(protocol, schema, &parsed)
}

/// A chassis → host frame as JSON: `kmc.VehicleSpeed`, `kmc.BatteryVoltage`, `kmc.AllState`,
/// `kmc.AfResponse`.
fn chassis_frame(protocol: &'static str, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    let parsed = ChassisFrame::parse(frame).map_err(|e| FrameError::decode(protocol, frame, e))?;
    let schema = match parsed {
        ChassisFrame::VehicleSpeed(_) => "kmc.VehicleSpeed",
        ChassisFrame::BatteryVoltage(_) => "kmc.BatteryVoltage",
        ChassisFrame::AllState(_) => "kmc.AllState",
        ChassisFrame::Af(_) => "kmc.AfResponse",
    };
    JsonFrame::serialize(protocol, schema, &parsed)
}

impl LinkDescription for HostLink {
    fn protocol(&self) -> &'static str {
        "kmc.host"
    }

    fn layout(&self) -> &'static str {
        LAYOUT
    }

    fn decode(&self, direction: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
        match direction {
            Direction::Sent => host_frame(self.protocol(), frame),
            Direction::Received => chassis_frame(self.protocol(), frame),
        }
    }
}

impl LinkDescription for ChassisLink {
    fn protocol(&self) -> &'static str {
        "kmc.chassis"
    }

    fn layout(&self) -> &'static str {
        LAYOUT
    }

    fn decode(&self, direction: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
        match direction {
            Direction::Sent => chassis_frame(self.protocol(), frame),
            Direction::Received => host_frame(self.protocol(), frame),
        }
    }
}
