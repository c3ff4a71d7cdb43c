//! Why a call was refused or a client could not start; each call error maps to the vendor's
//! return code.

use robowire_rt::RtError;
use robowire_udp::UdpError;
use zsl_proto::gate::Refusal;
use zsl_proto::rules::ArgumentError;
use zsl_proto::udp::{ControlMode, DatagramError, ReturnCode};

/// Why a client could not start (or, on close, could not send its stop).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConnectError {
    /// The socket could not be bound (the message names the address and lists this host's
    /// IPv4 addresses).
    #[error(transparent)]
    Link(#[from] UdpError<DatagramError>),
    /// A thread could not be placed (priority, CPU, memory lock) or started.
    #[error("the client's threads")]
    Thread(#[from] RtError),
    /// An option is out of range.
    #[error("option {name}: {reason}")]
    Option {
        /// The option.
        name: &'static str,
        /// Why it is refused.
        reason: String,
    },
}

/// Why a call did not go out. Each maps to the vendor's return code
/// ([`CallError::return_code`]). A call that went out is `Ok` ([`Latched`]), whatever the robot
/// has acknowledged so far.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CallError {
    /// The vendor client's checks refused the call (`zsl_proto::gate`): nothing was latched or
    /// sent.
    #[error("{0}; nothing was sent")]
    Refused(#[from] Refusal),
    /// The robot raised its "SDK mismatch" flag (state 0x1F8 = 1): the client has stopped
    /// streaming for good, like the vendor's. Check the model (ZSL-1 vs ZSL-1W).
    #[error("the robot reported an SDK mismatch; this client stopped streaming (check --model)")]
    SdkMismatch,
}

impl From<ArgumentError> for CallError {
    fn from(e: ArgumentError) -> Self {
        Self::Refused(Refusal::Argument(e))
    }
}

impl CallError {
    /// The vendor's return code for this outcome.
    pub fn return_code(&self) -> ReturnCode {
        match self {
            Self::Refused(refusal) => refusal.return_code(),
            Self::SdkMismatch => ReturnCode::SwitchFailed,
        }
    }
}

/// A call that went out: its command is latched and streamed every 2 ms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Latched {
    /// The mode the call asks for.
    pub target: ControlMode,
    /// The mode the robot reported when the call was made.
    pub reported: ControlMode,
    /// The vendor's return code for the call: 0 (queued), or 0x3007 when the robot has not
    /// reported the target mode for 11 such calls in a row (the command was sent all the same).
    pub return_code: ReturnCode,
}

impl Latched {
    /// Whether the robot already reports the mode the call asks for.
    pub fn acknowledged(&self) -> bool {
        self.target == self.reported
    }
}
