//! What a device reports, in the robot's terms and SI units, the same for every kind: what a
//! bridge (ROS 2), a logger or a dashboard needs without knowing the device. Each part is present
//! when the state it came from carries it.

/// One state of a device, device-neutral.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Observation {
    /// Where the body is and how it moves, in the device's odometry frame.
    pub odometry: Option<Odometry>,
    /// The inertial measurement unit.
    pub imu: Option<ImuReading>,
    /// The joints, in the device's order.
    pub joints: Option<JointReadings>,
    /// The battery.
    pub battery: Option<BatteryReading>,
    /// Motor controllers' health reports.
    pub motors: Vec<MotorReport>,
    /// The device's own state message as its vendor's middleware carries it, for subscribers
    /// that want exactly that.
    pub passthrough: Option<Passthrough>,
}

/// Pose and velocity in the odometry frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Odometry {
    /// x, y, z, m.
    pub position_m: [f64; 3],
    /// Orientation quaternion x, y, z, w.
    pub orientation_xyzw: [f64; 4],
    /// Body-frame linear velocity x, y, z, m/s.
    pub linear_mps: [f64; 3],
    /// Body-frame angular velocity x, y, z, rad/s.
    pub angular_radps: [f64; 3],
}

/// An IMU sample.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ImuReading {
    /// Orientation quaternion x, y, z, w.
    pub orientation_xyzw: [f64; 4],
    /// Angular rate x, y, z, rad/s.
    pub gyro_radps: [f64; 3],
    /// Linear acceleration x, y, z, m/s².
    pub acc_mps2: [f64; 3],
}

/// The joints: names and three equally long columns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointReadings {
    /// Joint names (`FR_hip_joint`, `FR_abad`, …).
    pub names: Vec<String>,
    /// Positions, rad.
    pub position_rad: Vec<f64>,
    /// Velocities, rad/s.
    pub velocity_radps: Vec<f64>,
    /// Torques, N·m.
    pub effort_nm: Vec<f64>,
}

/// The battery; what the device does not measure is `None`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BatteryReading {
    /// Voltage, V.
    pub voltage_v: Option<f32>,
    /// Current, A.
    pub current_a: Option<f32>,
    /// Charge, 0..=1.
    pub charge_fraction: Option<f32>,
    /// Cell voltages, V.
    pub cells_v: Vec<f32>,
}

/// A motor controller's health.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MotorReport {
    /// Which motor (`motor 0`).
    pub name: String,
    /// The controller's hardware id.
    pub hardware_id: String,
    /// No error reported.
    pub ok: bool,
    /// `ok`, or the error.
    pub message: String,
    /// Named readings, as text.
    pub values: Vec<(String, String)>,
}

/// A state message as the vendor's middleware carries it: its topic (in the device's namespace),
/// its DDS type name and its XCDR1 body.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Passthrough {
    /// Topic name, relative to the device's namespace (`lowstate`).
    pub topic: &'static str,
    /// DDS type name (`unitree_go::msg::dds_::LowState_`).
    pub type_name: &'static str,
    /// The XCDR1 body (after the encapsulation header).
    pub body: Vec<u8>,
}

/// The quaternion (x, y, z, w) of a heading about z, rad.
#[cfg(feature = "kmc")]
pub(crate) fn yaw_quaternion(heading_rad: f64) -> [f64; 4] {
    let half = heading_rad / 2.0;
    [0.0, 0.0, half.sin(), half.cos()]
}

/// A quaternion w, x, y, z (the vendors' order) as x, y, z, w.
#[cfg(any(feature = "zsl1", feature = "unitree"))]
pub(crate) fn xyzw(wxyz: [f32; 4]) -> [f64; 4] {
    [wxyz[1].into(), wxyz[2].into(), wxyz[3].into(), wxyz[0].into()]
}

/// Three floats widened.
#[cfg(any(feature = "zsl1", feature = "unitree"))]
pub(crate) fn wide(v: [f32; 3]) -> [f64; 3] {
    v.map(f64::from)
}
