//! Unitree DDS links described to a recorder (feature `serde`). A frame is a DDS serialized
//! payload as it travels: the 4-byte encapsulation header (XCDR1 or XCDR2), then the CDR body.
//!
//! - [`GO2_LOW_LEVEL`] (`unitree_go.low_level`) and [`HG_LOW_LEVEL`] (`unitree_hg.low_level`):
//!   `rt/lowcmd` and `rt/lowstate`; `LowCmd_` and `LowState_` differ in length in either
//!   encoding, so a frame is whichever its length says, decoded strictly (CRC checked) and named
//!   by its DDS type (`unitree_go::msg::dds_::LowState_`), with the IDL field names.
//! - [`API_CLIENT`] (`unitree_api.client`) and [`API_SERVER`] (`unitree_api.server`): a service's
//!   `rt/api/<service>/request` and `/response`, recorded at the caller or at the service; which
//!   of `Request_` and `Response_` a frame is follows from the end and the direction.
//!
//! ```
//! use unitree_proto::description::GO2_LOW_LEVEL;
//! use unitree_proto::{CdrEncoding, LowState, Message};
//! use robowire_core::Direction;
//! use robowire_core::json::LinkDescription;
//!
//! let mut payload = [0u8; 1188];
//! let n = LowState::default().encode_cdr(CdrEncoding::Xcdr2, &mut payload).unwrap();
//! let frame = GO2_LOW_LEVEL.decode(Direction::Received, &payload[..n]).unwrap();
//! assert_eq!(frame.schema, "unitree_go::msg::dds_::LowState_");
//! assert_eq!(frame.value["motor_state"].as_array().map(Vec::len), Some(20));
//! assert!(GO2_LOW_LEVEL.decode(Direction::Received, &payload[..n - 1]).is_err());
//! ```

use robowire_core::Direction;
use robowire_core::cdr::CdrEncoding;
use robowire_core::json::serde_json::json;
use robowire_core::json::{
    ANY_VALUE, FrameError, JsonFrame, LinkDescription, LinkPlots, LinkProtocol, PanelSpec, SeriesSpec, WireSchema,
};

use crate::api::{REQUEST_TYPE_NAME, RESPONSE_TYPE_NAME, Request, Response};
use crate::idl::{self, IdlSchema};
use crate::{DecodeError, HgLowCmd, HgLowState, LowCmd, LowState, Message};

/// The layout of the low-level links.
const LOW_LEVEL_LAYOUT: &str = "unitree-lowlevel over unitree-dds, CDR payload with its encapsulation header";
/// The layout of the service links.
const API_LAYOUT: &str = "unitree-dds services, CDR payload with its encapsulation header";

/// A Go2's low-level link (`unitree_go.low_level`): `unitree_go` `LowCmd_` and `LowState_`.
pub static GO2_LOW_LEVEL: LinkProtocol = LinkProtocol {
    name: "unitree_go.low_level",
    layout: LOW_LEVEL_LAYOUT,
    decode: low_level::<LowCmd, LowState>,
    wire_schema: Some(|_, frame| low_level_wire::<LowCmd, LowState>(frame, &idl::GO2_LOW_CMD, &idl::GO2_LOW_STATE)),
};

/// An HG robot's (G1's) low-level link (`unitree_hg.low_level`): `unitree_hg` `LowCmd_` and
/// `LowState_`.
pub static HG_LOW_LEVEL: LinkProtocol = LinkProtocol {
    name: "unitree_hg.low_level",
    layout: LOW_LEVEL_LAYOUT,
    decode: low_level::<HgLowCmd, HgLowState>,
    wire_schema: Some(|_, frame| low_level_wire::<HgLowCmd, HgLowState>(frame, &idl::HG_LOW_CMD, &idl::HG_LOW_STATE)),
};

/// A service link recorded at the caller (`unitree_api.client`): it sends `Request_` and
/// receives `Response_`.
pub static API_CLIENT: LinkProtocol = LinkProtocol {
    name: "unitree_api.client",
    layout: API_LAYOUT,
    decode: |p, direction, f| call(p, direction == Direction::Sent, f),
    wire_schema: Some(|direction, f| call_wire(direction == Direction::Sent, f)),
};

/// A service link recorded at the service (`unitree_api.server`): it receives `Request_` and
/// sends `Response_`.
pub static API_SERVER: LinkProtocol = LinkProtocol {
    name: "unitree_api.server",
    layout: API_LAYOUT,
    decode: |p, direction, f| call(p, direction == Direction::Received, f),
    wire_schema: Some(|direction, f| call_wire(direction == Direction::Received, f)),
};

/// What `robowire plot` draws of a Unitree low-level link recorded at the client. Go2: each leg's
/// joint angles against the commanded targets (a target outside ±20 rad, Unitree's "no position"
/// marker, is not drawn), the body's attitude. HG (G1): the legs' pitch joints and ankles, the
/// waist, the arms, each against its target, and the pelvis attitude.
pub static PLOTS: [LinkPlots; 2] = [GO2_PLOTS, HG_PLOTS];

const GO2_PLOTS: LinkPlots = LinkPlots {
    protocol: "unitree_go.low_level",
    panels: &[
        PanelSpec {
            title: "front right leg: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                target("hip target", "/motor_cmd/0/q"),
                joint("hip", "/motor_state/0/q"),
                target("thigh target", "/motor_cmd/1/q"),
                joint("thigh", "/motor_state/1/q"),
                target("calf target", "/motor_cmd/2/q"),
                joint("calf", "/motor_state/2/q"),
            ],
        },
        PanelSpec {
            title: "front left leg: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                target("hip target", "/motor_cmd/3/q"),
                joint("hip", "/motor_state/3/q"),
                target("thigh target", "/motor_cmd/4/q"),
                joint("thigh", "/motor_state/4/q"),
                target("calf target", "/motor_cmd/5/q"),
                joint("calf", "/motor_state/5/q"),
            ],
        },
        PanelSpec {
            title: "rear right leg: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                target("hip target", "/motor_cmd/6/q"),
                joint("hip", "/motor_state/6/q"),
                target("thigh target", "/motor_cmd/7/q"),
                joint("thigh", "/motor_state/7/q"),
                target("calf target", "/motor_cmd/8/q"),
                joint("calf", "/motor_state/8/q"),
            ],
        },
        PanelSpec {
            title: "rear left leg: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                target("hip target", "/motor_cmd/9/q"),
                joint("hip", "/motor_state/9/q"),
                target("thigh target", "/motor_cmd/10/q"),
                joint("thigh", "/motor_state/10/q"),
                target("calf target", "/motor_cmd/11/q"),
                joint("calf", "/motor_state/11/q"),
            ],
        },
        PanelSpec {
            title: "body attitude (IMU)",
            y_label: "angle (rad)",
            series: &[
                joint("roll", "/imu_state/rpy/0"),
                joint("pitch", "/imu_state/rpy/1"),
                joint("yaw", "/imu_state/rpy/2"),
            ],
        },
    ],
};

const HG_PLOTS: LinkPlots = LinkPlots {
    protocol: "unitree_hg.low_level",
    panels: &[
        PanelSpec {
            title: "left leg: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                hg_target("hip pitch target", "/motor_cmd/0/q"),
                hg_joint("hip pitch", "/motor_state/0/q"),
                hg_target("knee target", "/motor_cmd/3/q"),
                hg_joint("knee", "/motor_state/3/q"),
                hg_target("ankle pitch (B) target", "/motor_cmd/4/q"),
                hg_joint("ankle pitch (B)", "/motor_state/4/q"),
                hg_target("ankle roll (A) target", "/motor_cmd/5/q"),
                hg_joint("ankle roll (A)", "/motor_state/5/q"),
            ],
        },
        PanelSpec {
            title: "right leg: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                hg_target("hip pitch target", "/motor_cmd/6/q"),
                hg_joint("hip pitch", "/motor_state/6/q"),
                hg_target("knee target", "/motor_cmd/9/q"),
                hg_joint("knee", "/motor_state/9/q"),
                hg_target("ankle pitch (B) target", "/motor_cmd/10/q"),
                hg_joint("ankle pitch (B)", "/motor_state/10/q"),
                hg_target("ankle roll (A) target", "/motor_cmd/11/q"),
                hg_joint("ankle roll (A)", "/motor_state/11/q"),
            ],
        },
        PanelSpec {
            title: "waist: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                hg_target("yaw target", "/motor_cmd/12/q"),
                hg_joint("yaw", "/motor_state/12/q"),
                hg_target("roll (A) target", "/motor_cmd/13/q"),
                hg_joint("roll (A)", "/motor_state/13/q"),
                hg_target("pitch (B) target", "/motor_cmd/14/q"),
                hg_joint("pitch (B)", "/motor_state/14/q"),
            ],
        },
        PanelSpec {
            title: "left arm: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                hg_target("shoulder pitch target", "/motor_cmd/15/q"),
                hg_joint("shoulder pitch", "/motor_state/15/q"),
                hg_target("shoulder roll target", "/motor_cmd/16/q"),
                hg_joint("shoulder roll", "/motor_state/16/q"),
                hg_target("elbow target", "/motor_cmd/18/q"),
                hg_joint("elbow", "/motor_state/18/q"),
            ],
        },
        PanelSpec {
            title: "right arm: joint angles and their targets",
            y_label: "angle (rad)",
            series: &[
                hg_target("shoulder pitch target", "/motor_cmd/22/q"),
                hg_joint("shoulder pitch", "/motor_state/22/q"),
                hg_target("shoulder roll target", "/motor_cmd/23/q"),
                hg_joint("shoulder roll", "/motor_state/23/q"),
                hg_target("elbow target", "/motor_cmd/25/q"),
                hg_joint("elbow", "/motor_state/25/q"),
            ],
        },
        PanelSpec {
            title: "pelvis attitude (IMU)",
            y_label: "angle (rad)",
            series: &[
                hg_joint("roll", "/imu_state/rpy/0"),
                hg_joint("pitch", "/imu_state/rpy/1"),
                hg_joint("yaw", "/imu_state/rpy/2"),
            ],
        },
    ],
};

/// A commanded joint target (a `LowCmd_` of type `schema`, sent): held until the next command.
const fn commanded(schema: &'static str, name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec { name, direction: Direction::Sent, schema, pointer, held: true, range: (-20.0, 20.0) }
}

/// A reported value (a `LowState_` of type `schema`, received).
const fn reported(schema: &'static str, name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec { name, direction: Direction::Received, schema, pointer, held: false, range: ANY_VALUE }
}

const fn target(name: &'static str, pointer: &'static str) -> SeriesSpec {
    commanded(LowCmd::DDS_TYPE_NAME, name, pointer)
}

const fn joint(name: &'static str, pointer: &'static str) -> SeriesSpec {
    reported(LowState::DDS_TYPE_NAME, name, pointer)
}

const fn hg_target(name: &'static str, pointer: &'static str) -> SeriesSpec {
    commanded(HgLowCmd::DDS_TYPE_NAME, name, pointer)
}

const fn hg_joint(name: &'static str, pointer: &'static str) -> SeriesSpec {
    reported(HgLowState::DDS_TYPE_NAME, name, pointer)
}

/// Every Unitree DDS link.
pub static DESCRIPTIONS: [&dyn LinkDescription; 4] = [&GO2_LOW_LEVEL, &HG_LOW_LEVEL, &API_CLIENT, &API_SERVER];

/// A payload whose length is neither the command's nor the state's in its encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("a {encoding:?} payload of {found} bytes: LowCmd_ is {command}, LowState_ {state} with the header")]
pub struct LowLevelLength {
    /// The payload's encoding, from its header.
    pub encoding: CdrEncoding,
    /// `LowCmd_`'s payload length in it.
    pub command: usize,
    /// `LowState_`'s payload length in it.
    pub state: usize,
    /// The frame's length.
    pub found: usize,
}

/// `frame` as the message `M`, CRC checked.
fn message<M: Message + serde::Serialize>(protocol: &'static str, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    let decode = |f: &[u8]| M::decode_cdr(f).map(|(m, _)| m).map_err(DecodeError::without_message);
    JsonFrame::parse(protocol, frame, decode, |_| M::DDS_TYPE_NAME)
}

/// `frame` as the command `C` or the state `S`, whichever its length is (either way).
fn low_level<C, S>(protocol: &'static str, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError>
where
    C: Message + serde::Serialize,
    S: Message + serde::Serialize,
{
    match encoding(frame) {
        Some(encoding) if frame.len() == S::cdr_len(encoding) => message::<S>(protocol, frame),
        Some(encoding) if frame.len() != C::cdr_len(encoding) => {
            let (command, state, found) = (C::cdr_len(encoding), S::cdr_len(encoding), frame.len());
            Err(FrameError::decode(protocol, frame, LowLevelLength { encoding, command, state, found }))
        }
        // The command's length, or no encapsulation header: the command's decoder says which.
        _ => message::<C>(protocol, frame),
    }
}

/// `schema` as the wire schema of a `cdr` channel.
fn cdr(schema: &IdlSchema) -> WireSchema {
    WireSchema { encoding: "cdr", name: schema.name, schema_encoding: "omgidl", text: schema.text }
}

/// A low-level frame's wire schema: an XCDR1 payload of the command's or the state's exact
/// length. Not an XCDR2 one: Foxglove's CDR reader (`@foxglove/cdr` 3.5) reads no DHEADER in
/// PLAIN_CDR2, which CycloneDDS and these codecs put before an array of structs (the motors), so
/// it would show wrong values; nor a frame of another length, which no CDR reader can read. Those
/// are recorded raw, beside their JSON.
fn low_level_wire<C: Message, S: Message>(frame: &[u8], command: &IdlSchema, state: &IdlSchema) -> Option<WireSchema> {
    let xcdr1 = CdrEncoding::Xcdr1;
    match encoding(frame)? {
        CdrEncoding::Xcdr1 if frame.len() == C::cdr_len(xcdr1) => Some(cdr(command)),
        CdrEncoding::Xcdr1 if frame.len() == S::cdr_len(xcdr1) => Some(cdr(state)),
        _ => None,
    }
}

/// A service frame's wire schema: a `Request_` or `Response_` payload that decodes (either
/// encoding: their structs hold no array of structs), so that a CDR reader can read it whole.
fn call_wire(is_request: bool, frame: &[u8]) -> Option<WireSchema> {
    let body = frame.get(4..).filter(|_| encoding(frame).is_some())?;
    if is_request {
        Request::decode_body(body).ok().map(|_| cdr(&idl::API_REQUEST))
    } else {
        Response::decode_body(body).ok().map(|_| cdr(&idl::API_RESPONSE))
    }
}

/// The encoding the payload's header announces.
fn encoding(frame: &[u8]) -> Option<CdrEncoding> {
    CdrEncoding::from_header(frame.get(..4)?.try_into().ok()?)
}

/// The CDR body after the encapsulation header.
fn body<'a>(protocol: &'static str, frame: &'a [u8]) -> Result<&'a [u8], FrameError> {
    match (encoding(frame), frame.get(..4)) {
        (Some(_), _) => Ok(&frame[4..]),
        (None, Some(header)) => {
            let found = header.try_into().unwrap_or_default();
            Err(FrameError::decode(protocol, frame, DecodeError::<()>::Encapsulation { found }))
        }
        (None, None) => {
            Err(FrameError::decode(protocol, frame, DecodeError::<()>::NoEncapsulation { found: frame.len() }))
        }
    }
}

/// A `Request_` payload (`is_request`) or a `Response_` one, with the IDL's nesting.
fn call(protocol: &'static str, is_request: bool, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    if is_request { request(protocol, frame) } else { response(protocol, frame) }
}

/// A `Request_` payload, with the IDL's nesting.
fn request(protocol: &'static str, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    let r = Request::decode_body(body(protocol, frame)?).map_err(|e| FrameError::decode(protocol, frame, e))?;
    let h = r.header;
    let value = json!({
        "header": {
            "identity": { "id": h.id, "api_id": h.api_id },
            "lease": { "id": h.lease_id },
            "policy": { "priority": h.priority, "noreply": h.noreply },
        },
        "parameter": r.parameter,
        "binary": r.binary,
    });
    Ok(JsonFrame { schema: REQUEST_TYPE_NAME, value })
}

/// A `Response_` payload, with the IDL's nesting.
fn response(protocol: &'static str, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    let r = Response::decode_body(body(protocol, frame)?).map_err(|e| FrameError::decode(protocol, frame, e))?;
    let value = json!({
        "header": { "identity": { "id": r.id, "api_id": r.api_id }, "status": { "code": r.code } },
        "data": r.data,
        "binary": r.binary,
    });
    Ok(JsonFrame { schema: RESPONSE_TYPE_NAME, value })
}
