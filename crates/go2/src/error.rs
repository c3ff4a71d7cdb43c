//! Why the client could not start, release the sport mode, or take a command.

use lowcmd_proto::robot::CommandError;
use robowire_dds::DdsError;
use robowire_rt::RtError;

/// Why something failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Go2Error {
    /// DDS: a participant, a topic, a write, a call without answer.
    #[error(transparent)]
    Dds(#[from] DdsError),
    /// The stream thread could not be placed or started.
    #[error("the LowCmd stream thread: {0}")]
    StreamThread(#[from] RtError),
    /// An option is out of range.
    #[error("option {name}: {reason}")]
    Option {
        /// The option.
        name: &'static str,
        /// Why.
        reason: String,
    },
    /// A command the robot's rules refuse; nothing was sent, the previous command stays.
    #[error(transparent)]
    Command(#[from] CommandError),
    /// A service answered with an error code.
    #[error("{service} api {api_id} answered code {code}")]
    Refused {
        /// The service.
        service: &'static str,
        /// The API id.
        api_id: i64,
        /// The status code.
        code: i32,
    },
    /// The sport mode still owned the motors after the release sequence's time.
    #[error("sport mode {mode:?} still owns the motors after {attempts} release attempts")]
    NotReleased {
        /// The mode that owns them.
        mode: String,
        /// ReleaseMode calls made.
        attempts: u32,
    },
    /// An answer the client cannot read (CheckMode without a name).
    #[error("{service} answered {data:?}, which is not what its API promises")]
    Unexpected {
        /// The service.
        service: &'static str,
        /// The data.
        data: String,
    },
    /// The stream halted (the client was closed).
    #[error("the client is closed")]
    Closed,
}
