//! Why the client could not start, release the sport mode, or take a command.

use robowire_dds::DdsError;
use robowire_rt::RtError;
use unitree_proto::robot::CommandError;
use unitree_proto::stream::MotionState;

/// Why something failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum UnitreeError {
    /// DDS: a participant, a topic, a write, a call without answer.
    #[error(transparent)]
    Dds(#[from] DdsError),
    /// A thread could not be placed (priority, CPU, memory lock) or started.
    #[error("the client's threads")]
    Thread(#[from] RtError),
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
    /// A service call failed: no answer in time, or the middleware refused the request.
    #[error("{service} api {api_id}")]
    Service {
        /// The service.
        service: &'static str,
        /// The API id.
        api_id: i64,
        /// What failed.
        #[source]
        source: DdsError,
    },
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
    /// An answer the client cannot read (CheckMode without a name, an answer to another API).
    #[error("{service} answered {data:?}, which is not what its API promises")]
    Unexpected {
        /// The service.
        service: &'static str,
        /// The data.
        data: String,
    },
    /// The client's receive thread has ended (the client is being closed): a service call
    /// cannot be made, a motion is not followed any more.
    #[error("the client is closed")]
    Closed,
    /// A followed motion ended before its last step: a newer command or motion replaced it,
    /// damping ended it, or the robot's rules refused a step (damping from then on).
    #[error("the motion ended before its last step: {0}")]
    MotionEnded(MotionState),
}
