//! ZSL-1 links described to a recorder (feature `serde`): the HighLevel and LowLevel UDP links,
//! each frame one datagram decoded strictly by its length (either link's datagrams decode on
//! either description, as they always have in captures), as JSON under `zsl1.<datagram>`; and
//! the shared-memory links (spec `spline-shm.md`), each frame the bytes of one handshake as they
//! were copied in or out of the region: `/spline_shm` seen by a client ([`SPLINE_CLIENT`]) or by
//! the daemon ([`SPLINE_DAEMON`]), and `/imu_shm` ([`IMU`]).
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
use zerocopy::FromBytes;

use crate::serde_impl::Legs;
use crate::shm::{LegControl, LegState, NavImu};
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
/// observed motion, the mode, the body's height. Of the spline link recorded at the client: each
/// leg's joint angles against their targets; of the IMU: its rates.
pub static PLOTS: [LinkPlots; 3] = [
    LinkPlots { protocol: "zsl1.high_level", panels: &HIGH_LEVEL_PANELS },
    LinkPlots {
        protocol: "zsl1.spline.client",
        panels: &[
            PanelSpec {
                title: "front right leg (FR): joint angles and their targets",
                y_label: "angle (rad)",
                series: &[
                    spline_target("abad target", "/FR/abad/p_des_rad"),
                    spline_joint("abad", "/FR/abad/p_rad"),
                    spline_target("hip target", "/FR/hip/p_des_rad"),
                    spline_joint("hip", "/FR/hip/p_rad"),
                    spline_target("knee target", "/FR/knee/p_des_rad"),
                    spline_joint("knee", "/FR/knee/p_rad"),
                ],
            },
            PanelSpec {
                title: "front left leg (FL): joint angles and their targets",
                y_label: "angle (rad)",
                series: &[
                    spline_target("abad target", "/FL/abad/p_des_rad"),
                    spline_joint("abad", "/FL/abad/p_rad"),
                    spline_target("hip target", "/FL/hip/p_des_rad"),
                    spline_joint("hip", "/FL/hip/p_rad"),
                    spline_target("knee target", "/FL/knee/p_des_rad"),
                    spline_joint("knee", "/FL/knee/p_rad"),
                ],
            },
            PanelSpec {
                title: "rear right leg (RR): joint angles and their targets",
                y_label: "angle (rad)",
                series: &[
                    spline_target("abad target", "/RR/abad/p_des_rad"),
                    spline_joint("abad", "/RR/abad/p_rad"),
                    spline_target("hip target", "/RR/hip/p_des_rad"),
                    spline_joint("hip", "/RR/hip/p_rad"),
                    spline_target("knee target", "/RR/knee/p_des_rad"),
                    spline_joint("knee", "/RR/knee/p_rad"),
                ],
            },
            PanelSpec {
                title: "rear left leg (RL): joint angles and their targets",
                y_label: "angle (rad)",
                series: &[
                    spline_target("abad target", "/RL/abad/p_des_rad"),
                    spline_joint("abad", "/RL/abad/p_rad"),
                    spline_target("hip target", "/RL/hip/p_des_rad"),
                    spline_joint("hip", "/RL/hip/p_rad"),
                    spline_target("knee target", "/RL/knee/p_des_rad"),
                    spline_joint("knee", "/RL/knee/p_rad"),
                ],
            },
        ],
    },
    LinkPlots {
        protocol: "zsl1.imu",
        panels: &[PanelSpec {
            title: "angular rate (IMU)",
            y_label: "rate (rad/s)",
            series: &[imu("x", "/gyro_radps/0"), imu("y", "/gyro_radps/1"), imu("z", "/gyro_radps/2")],
        }],
    },
];

/// A spline command's target.
const fn spline_target(name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec { name, direction: Direction::Sent, schema: "zsl1.SplineCommand", pointer, held: true, range: ANY_VALUE }
}

/// A spline state's value.
const fn spline_joint(name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec {
        name,
        direction: Direction::Received,
        schema: "zsl1.SplineState",
        pointer,
        held: false,
        range: ANY_VALUE,
    }
}

/// An IMU sample's value.
const fn imu(name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec {
        name,
        direction: Direction::Received,
        schema: "zsl1.ImuSample",
        pointer,
        held: false,
        range: ANY_VALUE,
    }
}

/// The HighLevel link's panels.
const HIGH_LEVEL_PANELS: [PanelSpec; 4] = [
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
];

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

/// The layout the shared-memory links follow.
const SHM_LAYOUT: &str = "zsl1-spline-shm, vendor SDK v0.2.7 lowlevel.h";

/// `/spline_shm` recorded by the motion controller or a monitor (`zsl1.spline.client`): it
/// sends the 336 bytes of leg commands it publishes (`zsl1.SplineCommand`, the command block
/// without its consumer flags) and receives the 256 bytes of leg states it takes
/// (`zsl1.SplineState`, the state block without its flags).
pub static SPLINE_CLIENT: LinkProtocol = LinkProtocol {
    name: "zsl1.spline.client",
    layout: SHM_LAYOUT,
    decode: |p, direction, f| spline(p, direction == Direction::Sent, f),
    wire_schema: None,
};

/// `/spline_shm` recorded by the daemon (`zsl1.spline.daemon`): the same frames as
/// [`SPLINE_CLIENT`], the other way round: it receives leg commands and sends leg states.
pub static SPLINE_DAEMON: LinkProtocol = LinkProtocol {
    name: "zsl1.spline.daemon",
    layout: SHM_LAYOUT,
    decode: |p, direction, f| spline(p, direction == Direction::Received, f),
    wire_schema: None,
};

/// `/imu_shm` (`zsl1.imu`): each frame one 48-byte `nav_imu` record as read or written, the
/// timestamp (its version) then the sample (`zsl1.ImuSample`), either way.
pub static IMU: LinkProtocol = LinkProtocol {
    name: "zsl1.imu",
    layout: SHM_LAYOUT,
    decode: |p, _, f| exact::<NavImu>(p, "zsl1.ImuSample", f),
    wire_schema: None,
};

/// Every ZSL-1 link.
pub static DESCRIPTIONS: [&dyn LinkDescription; 5] = [&HIGH_LEVEL, &LOW_LEVEL, &SPLINE_CLIENT, &SPLINE_DAEMON, &IMU];

/// A frame of a shared-memory link that is not the length of the block it must be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("a {message} frame is {expected} bytes, not {found}")]
pub struct WrongLength {
    /// The message the frame should be (`zsl1.SplineState`).
    pub message: &'static str,
    /// Its length, bytes.
    pub expected: usize,
    /// The frame's length, bytes.
    pub found: usize,
}

/// A spline frame as JSON: leg commands if `command`, else leg states.
fn spline(protocol: &'static str, command: bool, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    if command {
        exact::<[LegControl; 4]>(protocol, "zsl1.SplineCommand", frame)
    } else {
        exact::<[LegState; 4]>(protocol, "zsl1.SplineState", frame)
    }
}

/// `frame` read as exactly one `T`, as JSON under `schema`; any other length is a
/// [`WrongLength`].
fn exact<T: FromBytes + ToJson>(
    protocol: &'static str,
    schema: &'static str,
    frame: &[u8],
) -> Result<JsonFrame, FrameError> {
    let wrong = WrongLength { message: schema, expected: size_of::<T>(), found: frame.len() };
    let block = T::read_from_bytes(frame).map_err(|_| FrameError::decode(protocol, frame, wrong))?;
    block.to_json(protocol, schema)
}

/// A shared-memory block's JSON form.
trait ToJson {
    fn to_json(&self, protocol: &'static str, schema: &'static str) -> Result<JsonFrame, FrameError>;
}

impl<T: serde::Serialize> ToJson for [T; 4] {
    fn to_json(&self, protocol: &'static str, schema: &'static str) -> Result<JsonFrame, FrameError> {
        JsonFrame::serialize(protocol, schema, &Legs(self))
    }
}

impl ToJson for NavImu {
    fn to_json(&self, protocol: &'static str, schema: &'static str) -> Result<JsonFrame, FrameError> {
        JsonFrame::serialize(protocol, schema, self)
    }
}

/// A datagram of either link as JSON: `zsl1.HighLevelState`, ….
fn datagram(protocol: &'static str, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    JsonFrame::parse(protocol, frame, AnyDatagram::decode, |datagram| match datagram {
        AnyDatagram::HighLevelCommand(_) => "zsl1.HighLevelCommand",
        AnyDatagram::HighLevelState(_) => "zsl1.HighLevelState",
        AnyDatagram::LowLevelCommand(_) => "zsl1.LowLevelCommand",
        AnyDatagram::LowLevelState(_) => "zsl1.LowLevelState",
    })
}
