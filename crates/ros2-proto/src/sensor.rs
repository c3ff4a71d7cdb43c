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
    /// A present lithium-ion battery with every quantity unmeasured (NaN, as ROS specifies),
    /// status and health unknown: fill in what the device reports.
    pub fn unmeasured(header: Header) -> Self {
        Self {
            header,
            voltage: f32::NAN,
            temperature: f32::NAN,
            current: f32::NAN,
            charge: f32::NAN,
            capacity: f32::NAN,
            design_capacity: f32::NAN,
            percentage: f32::NAN,
            power_supply_status: Self::STATUS_UNKNOWN,
            power_supply_health: Self::HEALTH_UNKNOWN,
            power_supply_technology: Self::TECHNOLOGY_LION,
            present: true,
            cell_voltage: Vec::new(),
            cell_temperature: Vec::new(),
            location: String::new(),
            serial_number: String::new(),
        }
    }

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
