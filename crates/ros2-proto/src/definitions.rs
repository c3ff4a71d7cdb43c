//! The message definitions of this crate's top-level messages, as a recorder writes them for
//! ROS 2 tools: MCAP's `ros2msg` schema encoding, named `package/msg/Type`, the message's own
//! `.msg` fields followed by each type it uses, separated as rosbag2 writes them
//! (a line of 80 `=`, then `MSG: package/Type`). Fields, order and types are those the codecs
//! of this crate write (and ROS 2 Humble and Jazzy define); comments and constants are left out
//! but `DiagnosticStatus`'s levels and `BatteryState`'s enumerations, which readers may show.
//!
//! ```
//! use robowire_core::cdr::CdrType;
//! use ros2_proto::definitions::definition;
//! use ros2_proto::geometry::Twist;
//!
//! let twist = definition(Twist::TYPE_NAME).unwrap();
//! assert_eq!(twist.name, "geometry_msgs/msg/Twist");
//! assert!(twist.text.starts_with("Vector3 linear\nVector3 angular\n"));
//! assert!(twist.text.contains("\nMSG: geometry_msgs/Vector3\nfloat64 x\n"));
//! ```

/// A message's definition for ROS 2 tools.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MessageDefinition {
    /// `package/msg/Type`.
    pub name: &'static str,
    /// The `.msg` text with its dependencies.
    pub text: &'static str,
}

/// The separator rosbag2 writes between a definition and each dependency.
macro_rules! dependency {
    ($name:literal, $text:expr) => {
        concat!(
            "================================================================================\nMSG: ",
            $name,
            "\n",
            $text
        )
    };
}

macro_rules! header_deps {
    () => {
        concat!(
            dependency!("std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"),
            dependency!("builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"),
        )
    };
}

macro_rules! vector3_dep {
    () => {
        dependency!("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n")
    };
}

macro_rules! quaternion_dep {
    () => {
        dependency!("geometry_msgs/Quaternion", "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n")
    };
}

/// `geometry_msgs/msg/Twist`.
pub const TWIST: MessageDefinition = MessageDefinition {
    name: "geometry_msgs/msg/Twist",
    text: concat!("Vector3 linear\nVector3 angular\n", vector3_dep!(),),
};

/// `nav_msgs/msg/Odometry`.
pub const ODOMETRY: MessageDefinition = MessageDefinition {
    name: "nav_msgs/msg/Odometry",
    text: concat!(
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n",
        "geometry_msgs/TwistWithCovariance twist\n",
        header_deps!(),
        dependency!("geometry_msgs/PoseWithCovariance", "Pose pose\nfloat64[36] covariance\n"),
        dependency!("geometry_msgs/Pose", "Point position\nQuaternion orientation\n"),
        dependency!("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"),
        quaternion_dep!(),
        dependency!("geometry_msgs/TwistWithCovariance", "Twist twist\nfloat64[36] covariance\n"),
        dependency!("geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"),
        vector3_dep!(),
    ),
};

/// `sensor_msgs/msg/Imu`.
pub const IMU: MessageDefinition = MessageDefinition {
    name: "sensor_msgs/msg/Imu",
    text: concat!(
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n",
        "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n",
        "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
        header_deps!(),
        quaternion_dep!(),
        vector3_dep!(),
    ),
};

/// `sensor_msgs/msg/JointState`.
pub const JOINT_STATE: MessageDefinition = MessageDefinition {
    name: "sensor_msgs/msg/JointState",
    text: concat!(
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
        header_deps!(),
    ),
};

/// `sensor_msgs/msg/BatteryState`.
pub const BATTERY_STATE: MessageDefinition = MessageDefinition {
    name: "sensor_msgs/msg/BatteryState",
    text: concat!(
        "uint8 POWER_SUPPLY_STATUS_UNKNOWN = 0\nuint8 POWER_SUPPLY_STATUS_CHARGING = 1\n",
        "uint8 POWER_SUPPLY_STATUS_DISCHARGING = 2\nuint8 POWER_SUPPLY_STATUS_NOT_CHARGING = 3\n",
        "uint8 POWER_SUPPLY_STATUS_FULL = 4\n",
        "std_msgs/Header header\nfloat32 voltage\nfloat32 temperature\nfloat32 current\nfloat32 charge\n",
        "float32 capacity\nfloat32 design_capacity\nfloat32 percentage\nuint8 power_supply_status\n",
        "uint8 power_supply_health\nuint8 power_supply_technology\nbool present\nfloat32[] cell_voltage\n",
        "float32[] cell_temperature\nstring location\nstring serial_number\n",
        header_deps!(),
    ),
};

/// `tf2_msgs/msg/TFMessage`.
pub const TF_MESSAGE: MessageDefinition = MessageDefinition {
    name: "tf2_msgs/msg/TFMessage",
    text: concat!(
        "geometry_msgs/TransformStamped[] transforms\n",
        dependency!(
            "geometry_msgs/TransformStamped",
            "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"
        ),
        header_deps!(),
        dependency!("geometry_msgs/Transform", "Vector3 translation\nQuaternion rotation\n"),
        vector3_dep!(),
        quaternion_dep!(),
    ),
};

/// `diagnostic_msgs/msg/DiagnosticArray`.
pub const DIAGNOSTIC_ARRAY: MessageDefinition = MessageDefinition {
    name: "diagnostic_msgs/msg/DiagnosticArray",
    text: concat!(
        "std_msgs/Header header\nDiagnosticStatus[] status\n",
        header_deps!(),
        dependency!(
            "diagnostic_msgs/DiagnosticStatus",
            "byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\nbyte level\nstring name\nstring message\n\
             string hardware_id\nKeyValue[] values\n"
        ),
        dependency!("diagnostic_msgs/KeyValue", "string key\nstring value\n"),
    ),
};

/// Every definition, by the DDS type name of its message in this crate.
pub static DEFINITIONS: [(&str, MessageDefinition); 7] = [
    ("geometry_msgs::msg::dds_::Twist_", TWIST),
    ("nav_msgs::msg::dds_::Odometry_", ODOMETRY),
    ("sensor_msgs::msg::dds_::Imu_", IMU),
    ("sensor_msgs::msg::dds_::JointState_", JOINT_STATE),
    ("sensor_msgs::msg::dds_::BatteryState_", BATTERY_STATE),
    ("tf2_msgs::msg::dds_::TFMessage_", TF_MESSAGE),
    ("diagnostic_msgs::msg::dds_::DiagnosticArray_", DIAGNOSTIC_ARRAY),
];

/// The definition of the message whose DDS type name is `dds_type_name`
/// (`geometry_msgs::msg::dds_::Twist_`).
pub fn definition(dds_type_name: &str) -> Option<MessageDefinition> {
    DEFINITIONS.iter().find(|(name, _)| *name == dds_type_name).map(|(_, d)| *d)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TIME: &str = "int32 sec\nuint32 nanosec\n";
    const HEADER: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
    const VECTOR3: &str = "float64 x\nfloat64 y\nfloat64 z\n";
    const QUATERNION: &str = "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n";

    #[test]
    fn shared_pieces_are_the_ones_spelled_out() {
        // The macros spell the shared definitions out (concat! takes literals only).
        assert!(ODOMETRY.text.contains(&["MSG: std_msgs/Header\n", HEADER].concat()));
        assert!(ODOMETRY.text.contains(&["MSG: builtin_interfaces/Time\n", TIME].concat()));
        assert!(IMU.text.contains(&["MSG: geometry_msgs/Vector3\n", VECTOR3].concat()));
        assert!(TF_MESSAGE.text.contains(&["MSG: geometry_msgs/Quaternion\n", QUATERNION].concat()));
    }
}
