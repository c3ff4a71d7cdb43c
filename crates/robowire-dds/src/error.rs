//! Why a DDS operation failed. The protocol core's or the socket's error is kept as the source.

/// Why a participant, a writer, a reader or a call failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DdsError {
    /// No interface of this name, or it has no IPv4 address.
    #[error("no network interface {name:?} with an IPv4 address (this host has: {available})")]
    NoInterface {
        /// The name asked for.
        name: String,
        /// The host's interfaces with IPv4 addresses.
        available: String,
    },
    /// The participant could not be created (sockets, ports, its thread).
    #[error("cannot create a DDS participant in domain {domain}")]
    Participant {
        /// The domain.
        domain: u16,
        /// What the system said.
        #[source]
        source: std::io::Error,
    },
    /// A writer or reader could not be created.
    #[error("cannot create the {what} of topic {topic}")]
    Create {
        /// Writer or reader.
        what: &'static str,
        /// The topic name.
        topic: String,
        /// What the participant said.
        #[source]
        source: rtps_proto::participant::CreateError,
    },
    /// A sample could not be written.
    #[error("writing to {topic} failed")]
    Write {
        /// The topic.
        topic: String,
        /// What the participant said.
        #[source]
        source: rtps_proto::endpoint::WriteError,
    },
    /// A request got no answer in time.
    #[error("no answer on {topic} within {timeout:?}")]
    NoAnswer {
        /// The answers' topic.
        topic: String,
        /// How long the call waited.
        timeout: std::time::Duration,
    },
    /// A reader's stream ended, or the participant is gone.
    #[error("the reader of {topic} was closed")]
    Closed {
        /// The topic.
        topic: String,
    },
}
