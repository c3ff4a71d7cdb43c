//! Typed state and commands: units in the names, legs FR, FL, RR, RL, quaternion w, x, y, z.
//! The facade hands these out; the datagrams as the vendor lays them out stay in `zsl_proto`.

use zsl_proto::Leg;
use zsl_proto::udp::{self as wire, ControlMode, ReturnCode};
use zsl_proto::zerocopy::little_endian::F32;

fn floats<const N: usize>(v: &[F32; N]) -> [f32; N] {
    v.map(F32::get)
}

fn joint_major(v: &[[F32; 4]; 3]) -> [[f32; 4]; 3] {
    v.map(|legs| floats(&legs))
}

fn to_wire(v: &[[f32; 4]; 3]) -> [[F32; 4]; 3] {
    v.map(|legs| legs.map(F32::new))
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

impl From<&wire::HighLevelState> for Imu {
    fn from(s: &wire::HighLevelState) -> Self {
        Self {
            quaternion_wxyz: floats(&s.quaternion),
            gyro_radps: floats(&s.gyro),
            acc_mps2: floats(&s.acc),
            rpy_rad: floats(&s.rpy),
        }
    }
}

impl From<&wire::LowLevelState> for Imu {
    fn from(s: &wire::LowLevelState) -> Self {
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
    /// The robot's error word: `None` when it reports none (self-check passed).
    pub error: Option<ReturnCode>,
}

impl From<&wire::HighLevelState> for BodyState {
    fn from(s: &wire::HighLevelState) -> Self {
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

impl From<&wire::HighLevelState> for LegJoints {
    fn from(s: &wire::HighLevelState) -> Self {
        Self {
            position_rad: JointArrays::from_slots(&s.joint_angle),
            velocity_radps: JointArrays::from_slots(&s.joint_velocity),
            torque_nm: JointArrays::from_slots(&s.joint_torque),
        }
    }
}

/// Everything the HighLevel state reports, typed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotState {
    /// Body, mode, battery, error.
    pub body: BodyState,
    /// Joint angles, velocities, torques.
    pub joints: LegJoints,
    /// The robot raised "SDK mismatch" (the vendor's client stops streaming for good on it).
    pub sdk_mismatch: bool,
}

impl From<&wire::HighLevelState> for RobotState {
    fn from(s: &wire::HighLevelState) -> Self {
        Self { body: s.into(), joints: s.into(), sdk_mismatch: s.has_sdk_mismatch() }
    }
}

/// A LowLevel motor command, `[joint][leg]`: joints abad, hip, knee; legs FR, FL, RR, RL (the
/// vendor's `q_des_abad[4]` … `tau_knee_ff[4]`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MotorCommand {
    /// Position targets, rad.
    pub q_des_rad: [[f32; 4]; 3],
    /// Velocity targets, rad/s.
    pub qd_des_radps: [[f32; 4]; 3],
    /// Position gains, N·m/rad.
    pub kp: [[f32; 4]; 3],
    /// Velocity gains, N·m·s/rad.
    pub kd: [[f32; 4]; 3],
    /// Feed-forward torques, N·m.
    pub tau_ff_nm: [[f32; 4]; 3],
}

impl MotorCommand {
    /// A PD hold: position targets `q_des_rad[joint][leg]` with one `kp` and `kd` per joint;
    /// zero velocity targets and feed-forward torques.
    pub fn pd_hold(q_des_rad: [[f32; 4]; 3], kp: [f32; 3], kd: [f32; 3]) -> Self {
        Self { q_des_rad, kp: kp.map(|k| [k; 4]), kd: kd.map(|k| [k; 4]), ..Self::default() }
    }

    /// The 60 floats as the datagram carries them.
    pub(crate) fn wire_command(&self) -> wire::MotorCommand {
        wire::MotorCommand {
            q_des: to_wire(&self.q_des_rad),
            qd_des: to_wire(&self.qd_des_radps),
            kp: to_wire(&self.kp),
            kd: to_wire(&self.kd),
            tau_ff: to_wire(&self.tau_ff_nm),
        }
    }
}

impl From<&wire::MotorCommand> for MotorCommand {
    fn from(m: &wire::MotorCommand) -> Self {
        Self {
            q_des_rad: joint_major(&m.q_des),
            qd_des_radps: joint_major(&m.qd_des),
            kp: joint_major(&m.kp),
            kd: joint_major(&m.kd),
            tau_ff_nm: joint_major(&m.tau_ff),
        }
    }
}

/// The twelve motors as the LowLevel state reports them, `[joint][leg]`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MotorState {
    /// Positions, rad.
    pub q_rad: [[f32; 4]; 3],
    /// Velocities, rad/s.
    pub qd_radps: [[f32; 4]; 3],
    /// Torque feedback, N·m.
    pub tau_nm: [[f32; 4]; 3],
}

impl From<&wire::MotorState> for MotorState {
    fn from(m: &wire::MotorState) -> Self {
        Self { q_rad: joint_major(&m.q), qd_radps: joint_major(&m.qd), tau_nm: joint_major(&m.tau_fb) }
    }
}

/// Everything the LowLevel state reports, typed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LowLevelState {
    /// The motors.
    pub motor: MotorState,
    /// The IMU.
    pub imu: Imu,
    /// The state carried the magic `0x5AA5` (`haveMotorData()`).
    pub has_motor_data: bool,
}

impl From<&wire::LowLevelState> for LowLevelState {
    fn from(s: &wire::LowLevelState) -> Self {
        Self { motor: (&s.motor).into(), imu: s.into(), has_motor_data: s.has_motor_data() }
    }
}
