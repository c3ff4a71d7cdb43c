//! Typed snapshots of the state: units in the names, legs FR, FL, RR, RL, quaternion w, x, y, z.

use zsl_proto::Leg;
use zsl_proto::udp::{ControlMode, HighLevelState, LowLevelState, ReturnCode};
use zsl_proto::zerocopy::little_endian::F32;

fn floats<const N: usize>(v: &[F32; N]) -> [f32; N] {
    v.map(F32::get)
}

/// The IMU as both interfaces report it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Imu {
    /// Orientation quaternion w, x, y, z.
    pub quaternion_wxyz: [f32; 4],
    /// Angular rate x, y, z, rad/s.
    pub gyro_radps: [f32; 3],
    /// Acceleration x, y, z, m/s².
    pub acc_mps2: [f32; 3],
    /// Roll, pitch, yaw, rad.
    pub rpy_rad: [f32; 3],
}

impl From<&HighLevelState> for Imu {
    fn from(s: &HighLevelState) -> Self {
        Self {
            quaternion_wxyz: floats(&s.quaternion),
            gyro_radps: floats(&s.gyro),
            acc_mps2: floats(&s.acc),
            rpy_rad: floats(&s.rpy),
        }
    }
}

impl From<&LowLevelState> for Imu {
    fn from(s: &LowLevelState) -> Self {
        Self {
            quaternion_wxyz: floats(&s.quaternion),
            gyro_radps: floats(&s.gyro),
            acc_mps2: floats(&s.acc),
            rpy_rad: floats(&s.rpy),
        }
    }
}

/// The body as the HighLevel state reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// The IMU.
    pub imu: Imu,
    /// Body-frame velocity x, y, z, m/s.
    pub body_velocity_mps: [f32; 3],
    /// World-frame velocity x, y, z, m/s.
    pub world_velocity_mps: [f32; 3],
    /// Position x, y, z, m.
    pub position_m: [f32; 3],
    /// Current control mode.
    pub mode: ControlMode,
    /// Battery level, % (0–100 per the vendor docs).
    pub battery_percent: u32,
    /// Error word (`Queued` = 0 = no error).
    pub error: ReturnCode,
}

impl From<&HighLevelState> for BodyState {
    fn from(s: &HighLevelState) -> Self {
        Self {
            imu: s.into(),
            body_velocity_mps: floats(&s.body_velocity),
            world_velocity_mps: floats(&s.world_velocity),
            position_m: floats(&s.position),
            mode: s.mode(),
            battery_percent: s.battery_percent.get(),
            error: s.error(),
        }
    }
}

/// One quantity for every joint: `[leg]` arrays per joint, legs FR, FL, RR, RL.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointArrays {
    /// Abduction joints.
    pub abad: [f32; 4],
    /// Hip joints.
    pub hip: [f32; 4],
    /// Knee joints.
    pub knee: [f32; 4],
    /// Foot/wheel joints (ZSL-1W; zero on the ZSL-1).
    pub foot: [f32; 4],
}

impl JointArrays {
    fn from_slots(slots: &[[F32; 4]; 4]) -> Self {
        Self { abad: floats(&slots[0]), hip: floats(&slots[1]), knee: floats(&slots[2]), foot: floats(&slots[3]) }
    }

    /// Abad, hip, knee, foot of one leg.
    pub fn leg(&self, leg: Leg) -> [f32; 4] {
        let i = leg.index();
        [self.abad[i], self.hip[i], self.knee[i], self.foot[i]]
    }
}

/// The joints as the HighLevel state reports them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LegJoints {
    /// Angles, rad.
    pub position_rad: JointArrays,
    /// Velocities, rad/s.
    pub velocity_radps: JointArrays,
    /// Torques, N·m.
    pub torque_nm: JointArrays,
}

impl From<&HighLevelState> for LegJoints {
    fn from(s: &HighLevelState) -> Self {
        Self {
            position_rad: JointArrays::from_slots(&s.joint_angle),
            velocity_radps: JointArrays::from_slots(&s.joint_velocity),
            torque_nm: JointArrays::from_slots(&s.joint_torque),
        }
    }
}
