//! The LowLevel client: twelve motors, position/velocity/PD/torque commands.

use robowire_rt::device::Device;
use zsl_proto::rules::check_motor_command;
use zsl_proto::stream::{Connection, LowLevelInterface};
use zsl_proto::udp::{self as wire, LowLevelCommand};
use zsl_proto::zerocopy::little_endian::F32;

use super::session::{ClientStats, Session, client_accessors};
use super::snapshot::{Imu, LowLevelState, MotorCommand, MotorState};
use super::{CallError, ClientOptions, ConnectError};

/// The ZSL-1 LowLevel client (the vendor's `LowLevel`): a stream thread sends the latched
/// command every 2 ms, a receive thread keeps the latest state (decoded strictly by default) and
/// the watchdog. No runtime needed. Closing (or dropping) sends the stop burst (velocity targets
/// zeroed: the PD terms hold the last position).
///
/// Streams the all-zero idle command (kp = kd = 0: nothing driven) until the first
/// [`send_motor_command`](Self::send_motor_command), then the latched command every 2 ms.
pub struct LowLevel {
    session: Session<LowLevelInterface>,
}

impl std::fmt::Debug for LowLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LowLevel")
            .field("local", &self.session.local_addr())
            .field("dog", &self.session.options.dog)
            .field("connection", &self.connection())
            .finish_non_exhaustive()
    }
}

fn floats<const N: usize>(v: &[F32; N]) -> [f32; N] {
    v.map(F32::get)
}

impl LowLevel {
    /// Binds `options.local` and starts streaming the idle command to `options.dog`
    /// (use [`ClientOptions::low_level`]).
    pub fn open(options: ClientOptions) -> Result<Self, ConnectError> {
        Ok(Self { session: Session::open(options, "zsl-low")? })
    }

    /// `sendMotorCmd`: all 60 floats must be finite and the positions within the vendor's
    /// bounds (abad −0.7…0.7, hip −1.15…3.0, knee −2.9…−0.65 rad, compared as f64). On error
    /// nothing changes and the previous command keeps streaming (the vendor's −1).
    pub fn send_motor_command(&self, command: &MotorCommand) -> Result<(), CallError> {
        let motor = command.wire_command();
        check_motor_command(&motor)?;
        self.session.submit(LowLevelCommand::new(motor))
    }

    /// `getMotorState()`: positions, velocities, torques (`None` before the first state and
    /// after a timeout).
    pub fn motor_state(&self) -> Option<MotorState> {
        self.session.read(|s| (&s.motor).into())
    }

    /// `haveMotorData()`: the last state carried the magic `0x5AA5`.
    pub fn has_motor_data(&self) -> bool {
        self.session.read(wire::LowLevelState::has_motor_data).unwrap_or(false)
    }

    /// `getQuaternion()`: w, x, y, z.
    pub fn quaternion(&self) -> Option<[f32; 4]> {
        self.session.read(|s| floats(&s.quaternion))
    }

    /// `getRPY()`: rad.
    pub fn rpy(&self) -> Option<[f32; 3]> {
        self.session.read(|s| floats(&s.rpy))
    }

    /// `getBodyAcc()`: m/s².
    pub fn body_acc(&self) -> Option<[f32; 3]> {
        self.session.read(|s| floats(&s.acc))
    }

    /// `getBodyGyro()`: rad/s.
    pub fn body_gyro(&self) -> Option<[f32; 3]> {
        self.session.read(|s| floats(&s.gyro))
    }

    /// The IMU, typed.
    pub fn imu(&self) -> Option<Imu> {
        self.session.read(|s| s.into())
    }
}

client_accessors!(LowLevel, LowLevelInterface, wire::LowLevelState, LowLevelState, LowLevelCommand);
