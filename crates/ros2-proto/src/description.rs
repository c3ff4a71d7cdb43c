//! ROS 2 topics described to a recorder (feature `json`): each message type of this crate as a
//! link whose frames are its DDS payloads (encapsulation header, XCDR1 body). A payload that
//! decodes is written as `cdr` under its `ros2msg` definition ([`crate::definitions`]), on the
//! ROS topic itself, which `ros2 bag`, `rosbags` and Foxglove read; its JSON form here says only
//! what it is (ROS 2 tools decode the message).
//!
//! ```
//! use robowire_core::Direction;
//! use robowire_core::json::LinkDescription;
//! use ros2_proto::description::of;
//!
//! // A Twist (linear x 0.5 m/s, angular z 0.2 rad/s): the XCDR1 header, six float64.
//! let mut payload = vec![0u8, 1, 0, 0];
//! payload.extend([0.5f64, 0.0, 0.0, 0.0, 0.0, 0.2].iter().flat_map(|v| v.to_le_bytes()));
//! let link = of("geometry_msgs::msg::dds_::Twist_").unwrap();
//! let wire = link.wire_schema(Direction::Received, &payload).unwrap();
//! assert_eq!((wire.encoding, wire.name, wire.schema_encoding), ("cdr", "geometry_msgs/msg/Twist", "ros2msg"));
//! assert!(link.wire_schema(Direction::Received, &payload[..20]).is_none(), "a cut payload is not cdr");
//! assert!(link.decode(Direction::Received, &payload[..20]).is_err());
//! ```

use robowire_core::cdr::{CdrEncoding, CdrType};
use robowire_core::json::serde_json::json;
use robowire_core::json::{FrameError, JsonFrame, LinkDescription, LinkProtocol, WireSchema};

use crate::definitions;
use crate::diagnostic::DiagnosticArray;
use crate::geometry::Twist;
use crate::nav::Odometry;
use crate::sensor::{BatteryState, Imu, JointState};
use crate::tf::TfMessage;

/// The layout every ROS 2 link follows.
const LAYOUT: &str = "ROS 2 over DDS (rmw_cyclonedds, rmw_fastrtps): XCDR1 payload with its encapsulation header";

/// The body of `frame`, a payload in XCDR1, decoded as `T`.
fn decoded<T: CdrType>(frame: &[u8]) -> Option<Result<T, T::Error>> {
    let header: [u8; 4] = frame.get(..4)?.try_into().ok()?;
    (CdrEncoding::from_header(header)? == CdrEncoding::Xcdr1).then(|| T::decode_body(CdrEncoding::Xcdr1, &frame[4..]))
}

/// The frame as JSON: what it is and its size, or why it is not one.
fn decode<T: CdrType>(protocol: &'static str, frame: &[u8]) -> Result<JsonFrame, FrameError>
where
    T::Error: core::error::Error + Send + Sync + 'static,
{
    match decoded::<T>(frame) {
        Some(Ok(_)) => {
            Ok(JsonFrame { schema: T::TYPE_NAME, value: json!({ "type": T::TYPE_NAME, "bytes": frame.len() }) })
        }
        Some(Err(e)) => Err(FrameError::decode(protocol, frame, e)),
        None => Err(FrameError::decode(protocol, frame, NotXcdr1)),
    }
}

/// A frame that is not an XCDR1 payload.
#[derive(Debug, Clone, Copy, thiserror::Error)]
#[error("not an XCDR1 payload (ROS 2 messages are XCDR1)")]
pub struct NotXcdr1;

/// Its `ros2msg` schema, if the frame decodes.
fn wire<T: CdrType>(frame: &[u8]) -> Option<WireSchema> {
    let definition = definitions::definition(T::TYPE_NAME)?;
    decoded::<T>(frame)?.ok()?;
    Some(WireSchema { encoding: "cdr", name: definition.name, schema_encoding: "ros2msg", text: definition.text })
}

macro_rules! ros2_links {
    ($($(#[$meta:meta])* $name:ident: $ty:ty = $protocol:literal;)*) => {
        $(
            $(#[$meta])*
            pub static $name: LinkProtocol = LinkProtocol {
                name: $protocol,
                layout: LAYOUT,
                decode: |p, _, f| decode::<$ty>(p, f),
                wire_schema: Some(|_, f| wire::<$ty>(f)),
            };
        )*

        /// Every ROS 2 link.
        pub static DESCRIPTIONS: [&dyn LinkDescription; [$($protocol),*].len()] = [$(&$name),*];

        /// The link of the message whose DDS type name is `dds_type_name`.
        pub fn of(dds_type_name: &str) -> Option<&'static LinkProtocol> {
            $(if dds_type_name == <$ty as CdrType>::TYPE_NAME { return Some(&$name); })*
            None
        }
    };
}

ros2_links! {
    /// `geometry_msgs/msg/Twist` (`cmd_vel`).
    TWIST: Twist = "ros2.geometry_msgs/msg/Twist";
    /// `nav_msgs/msg/Odometry` (`odom`).
    ODOMETRY: Odometry = "ros2.nav_msgs/msg/Odometry";
    /// `sensor_msgs/msg/Imu` (`imu`).
    IMU: Imu = "ros2.sensor_msgs/msg/Imu";
    /// `sensor_msgs/msg/JointState` (`joint_states`).
    JOINT_STATE: JointState = "ros2.sensor_msgs/msg/JointState";
    /// `sensor_msgs/msg/BatteryState` (`battery`).
    BATTERY_STATE: BatteryState = "ros2.sensor_msgs/msg/BatteryState";
    /// `tf2_msgs/msg/TFMessage` (`/tf`).
    TF_MESSAGE: TfMessage = "ros2.tf2_msgs/msg/TFMessage";
    /// `diagnostic_msgs/msg/DiagnosticArray` (`/diagnostics`).
    DIAGNOSTIC_ARRAY: DiagnosticArray = "ros2.diagnostic_msgs/msg/DiagnosticArray";
}
