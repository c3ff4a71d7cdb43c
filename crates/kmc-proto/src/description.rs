//! KMC chassis links described to a recorder (feature `serde`): each frame one whole frame as
//! the stream decoders cut it, decoded strictly ([`HostFrame::parse`] for host → chassis,
//! [`ChassisFrame::parse`] for chassis → host) and named `kmc.<Frame>`. The two frame sets share
//! IDs (`0xB3`, `0xAF`), so which one a frame is follows from which end recorded the link and
//! which way the frame went: [`HOST`] for the host's end (a driver), [`CHASSIS`] for the
//! chassis' end (a simulator).
//!
//! ```
//! use kmc_proto::description::{CHASSIS, HOST};
//! use robowire_core::Direction;
//! use robowire_core::json::LinkDescription;
//!
//! let speed = [0xb3, 0x00, 0x00, 0xa0, 0x3f];
//! let frame = HOST.decode(Direction::Received, &speed).unwrap();
//! assert_eq!((frame.schema, frame.value["speed_mps"].as_f64()), ("kmc.VehicleSpeed", Some(1.25)));
//! assert_eq!(CHASSIS.decode(Direction::Sent, &speed).unwrap().schema, "kmc.VehicleSpeed");
//! assert!(HOST.decode(Direction::Sent, &speed).is_err(), "a host sends 0xB3 alone");
//! ```

use robowire_core::Direction;
use robowire_core::json::{
    ANY_VALUE, FrameError, JsonFrame, LinkDescription, LinkPlots, LinkProtocol, PanelSpec, SeriesSpec,
};

use crate::{ChassisFrame, HostFrame};

/// The layout both ends follow.
const LAYOUT: &str = "kmc-uart, one whole frame per record";

/// A chassis link recorded at the host (`kmc.host`): it sends host frames and receives chassis
/// frames.
pub static HOST: LinkProtocol = LinkProtocol {
    name: "kmc.host",
    layout: LAYOUT,
    decode: |p, direction, f| frame(p, direction == Direction::Sent, f),
    wire_schema: None,
};

/// A chassis link recorded at the chassis (`kmc.chassis`, a simulator): it sends chassis frames
/// and receives host frames.
pub static CHASSIS: LinkProtocol = LinkProtocol {
    name: "kmc.chassis",
    layout: LAYOUT,
    decode: |p, direction, f| frame(p, direction == Direction::Received, f),
    wire_schema: None,
};

/// What `robowire plot` draws of a chassis link recorded at the host: commanded against observed
/// velocity, the commanded curvature, the battery.
pub static PLOTS: [LinkPlots; 1] = [LinkPlots {
    protocol: "kmc.host",
    panels: &[
        PanelSpec {
            title: "velocity: commanded (0xA5) and reported (0xB3)",
            y_label: "velocity (m/s)",
            series: &[
                sent("commanded", "kmc.PcControl", "/velocity_mps", true),
                received("reported", "kmc.VehicleSpeed", "/speed_mps"),
            ],
        },
        PanelSpec {
            title: "curvature: commanded (0xA5)",
            y_label: "curvature (1/m)",
            series: &[sent("commanded", "kmc.PcControl", "/curvature_per_m", true)],
        },
        PanelSpec {
            title: "battery (AF 0x07)",
            y_label: "voltage (V)",
            series: &[received("battery", "kmc.BatteryVoltage", "/volts")],
        },
    ],
}];

/// A series of frames the host sent.
const fn sent(name: &'static str, schema: &'static str, pointer: &'static str, held: bool) -> SeriesSpec {
    SeriesSpec { name, direction: Direction::Sent, schema, pointer, held, range: ANY_VALUE }
}

/// A series of frames the host received.
const fn received(name: &'static str, schema: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec { name, direction: Direction::Received, schema, pointer, held: false, range: ANY_VALUE }
}

/// Both ends of a KMC link.
pub static DESCRIPTIONS: [&dyn LinkDescription; 2] = [&HOST, &CHASSIS];

/// A host → chassis frame (`kmc.PcControl`, `kmc.VehicleSpeedRequest`, `kmc.AfRequest`) or a
/// chassis → host one (`kmc.VehicleSpeed`, `kmc.BatteryVoltage`, `kmc.AllState`,
/// `kmc.AfResponse`) as JSON.
fn frame(protocol: &'static str, from_host: bool, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    if from_host {
        JsonFrame::parse(protocol, frame, HostFrame::parse, |parsed| match parsed {
            HostFrame::PcControl(_) => "kmc.PcControl",
            HostFrame::VehicleSpeedRequest => "kmc.VehicleSpeedRequest",
            HostFrame::Af(_) => "kmc.AfRequest",
        })
    } else {
        JsonFrame::parse(protocol, frame, ChassisFrame::parse, |parsed| match parsed {
            ChassisFrame::VehicleSpeed(_) => "kmc.VehicleSpeed",
            ChassisFrame::BatteryVoltage(_) => "kmc.BatteryVoltage",
            ChassisFrame::AllState(_) => "kmc.AllState",
            ChassisFrame::Af(_) => "kmc.AfResponse",
        })
    }
}
