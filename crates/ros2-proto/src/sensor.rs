//! `sensor_msgs`: Imu, JointState, BatteryState.

use alloc::string::String;
use alloc::vec::Vec;

use crate::builtin::Header;
use crate::geometry::{Quaternion, Vector3};

ros_struct! {
    /// `sensor_msgs/Imu`. A covariance's first element -1 means "not provided".
    #[derive(Default)]
    pub struct Imu {
        /// Time and `imu_link`.
        pub header: Header,
        /// Orientation.
        pub orientation: Quaternion,
        /// 3×3, row-major about x, y, z.
        pub orientation_covariance: [f64; 9],
        /// rad/s.
        pub angular_velocity: Vector3,
        /// 3×3, row-major.
        pub angular_velocity_covariance: [f64; 9],
        /// m/s².
        pub linear_acceleration: Vector3,
        /// 3×3, row-major.
        pub linear_acceleration_covariance: [f64; 9],
    }
}

ros_struct! {
    /// `sensor_msgs/JointState`: one entry per joint in each non-empty array.
    #[derive(Default)]
    pub struct JointState {
        /// Time (of the state's receipt).
        pub header: Header,
        /// Joint names.
        pub name: Vec<String>,
        /// rad.
        pub position: Vec<f64>,
        /// rad/s.
        pub velocity: Vec<f64>,
        /// N·m.
        pub effort: Vec<f64>,
    }
}

ros_struct! {
    /// `sensor_msgs/BatteryState`. Unmeasured quantities are NaN, as ROS specifies.
    #[derive(Default)]
    pub struct BatteryState {
        /// Time.
        pub header: Header,
        /// V.
        pub voltage: f32,
        /// °C.
        pub temperature: f32,
        /// A, negative while discharging.
        pub current: f32,
        /// Ah.
        pub charge: f32,
        /// Ah.
        pub capacity: f32,
        /// Ah.
        pub design_capacity: f32,
        /// 0…1.
        pub percentage: f32,
        /// `POWER_SUPPLY_STATUS_*`.
        pub power_supply_status: u8,
        /// `POWER_SUPPLY_HEALTH_*`.
        pub power_supply_health: u8,
        /// `POWER_SUPPLY_TECHNOLOGY_*`.
        pub power_supply_technology: u8,
        /// Whether a battery is present.
        pub present: bool,
        /// V per cell.
        pub cell_voltage: Vec<f32>,
        /// °C per cell.
        pub cell_temperature: Vec<f32>,
        /// Where the battery is.
        pub location: String,
        /// Its serial number.
        pub serial_number: String,
    }
}

impl BatteryState {
    /// `power_supply_status`: unknown.
    pub const STATUS_UNKNOWN: u8 = 0;
    /// `power_supply_status`: discharging.
    pub const STATUS_DISCHARGING: u8 = 2;
    /// `power_supply_health`: unknown.
    pub const HEALTH_UNKNOWN: u8 = 0;
    /// `power_supply_technology`: lithium-ion.
    pub const TECHNOLOGY_LION: u8 = 2;
}

ros_message! {
    Imu => "sensor_msgs::msg::dds_::Imu_";
    JointState => "sensor_msgs::msg::dds_::JointState_";
    BatteryState => "sensor_msgs::msg::dds_::BatteryState_";
}
