//! Why a call was refused or a client could not start; each call error maps to the vendor's
//! return code.

use robowire_rt::RtError;
use robowire_udp::UdpError;
use zsl_proto::rules::ArgumentError;
use zsl_proto::udp::{ControlMode, DatagramError, Model, ReturnCode};

/// Why a client could not start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConnectError {
    /// The socket could not be bound (the message names the address and lists this host's
    /// IPv4 addresses).
    #[error(transparent)]
    Link(#[from] UdpError<DatagramError>),
    /// The stream thread could not be placed (priority, CPU, memory lock) or started.
    #[error("the stream thread: {0}")]
    StreamThread(#[from] RtError),
    /// An option is out of range.
    #[error("option {name}: {reason}")]
    Option {
        /// The option.
        name: &'static str,
        /// Why it is refused.
        reason: String,
    },
}

/// Why a call was refused, or what went wrong after it was accepted. Each maps to the vendor's
/// return code ([`CallError::return_code`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CallError {
    /// The robot reports a non-zero error word (self-check failed); nothing was changed.
    #[error("the robot reports error {0:?} (self-check failed); nothing was sent")]
    SelfCheck(ReturnCode),
    /// The robot is lying down (mode 0, 10 or 51); it must stand first. Nothing was changed.
    #[error("refused in mode {0:?}: the robot must stand first; nothing was sent")]
    LyingDown(ControlMode),
    /// `move` while a two-leg stand is active; cancel it first. Nothing was changed.
    #[error("move refused during a two-leg stand (cancel it first); nothing was sent")]
    TwoLegStandActive,
    /// The robot is moving (|vx|, |vy| or |yaw rate| above 0.2); nothing was changed.
    #[error("refused while the robot is moving (|vx|, |vy| or |yaw rate| > 0.2) in mode {0:?}; nothing was sent")]
    Running(ControlMode),
    /// `attitudeControl` with |roll| above 1.0 rad; nothing was changed.
    #[error("attitude refused: |roll| = {0} rad is above 1.0 rad; nothing was sent")]
    Unbalanced(f32),
    /// An argument is NaN, infinite or out of range; nothing was changed.
    #[error("{0}; nothing was sent")]
    Argument(#[from] ArgumentError),
    /// The call is not in this model's API (ZSL-1W `crawl`/`climb` on a ZSL-1).
    #[error("{call} is a {needs:?} call; this client is configured for {model:?}")]
    WrongModel {
        /// The call.
        call: &'static str,
        /// The model that has it.
        needs: Model,
        /// The client's model.
        model: Model,
    },
    /// The command **was** latched and sent, but the robot has not reported the target mode
    /// for 11 calls in a row (the vendor's 0x3007 on the 11th miss).
    #[error(
        "the robot has not reported mode {target:?} for 11 calls in a row (it reports {reported:?}); the command was sent"
    )]
    NotAcknowledged {
        /// The mode the call asks for.
        target: ControlMode,
        /// The mode the robot reports.
        reported: ControlMode,
    },
    /// The robot raised its "SDK mismatch" flag (state 0x1F8 = 1): the client has stopped
    /// streaming for good, like the vendor's. Check the model (ZSL-1 vs ZSL-1W).
    #[error("the robot reported an SDK mismatch; this client stopped streaming (check --model)")]
    SdkMismatch,
}

impl CallError {
    /// The vendor's return code for this outcome.
    pub fn return_code(&self) -> ReturnCode {
        match self {
            Self::SelfCheck(word) => *word,
            Self::Argument(e) => e.return_code(),
            Self::LyingDown(_)
            | Self::TwoLegStandActive
            | Self::Running(_)
            | Self::Unbalanced(_)
            | Self::NotAcknowledged { .. }
            | Self::WrongModel { .. }
            | Self::SdkMismatch => ReturnCode::SwitchFailed,
        }
    }
}
