//! Why a DDS operation failed.

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
    /// The participant could not be created (sockets, ports).
    #[error("cannot create a DDS participant in domain {domain}: {reason}")]
    Participant {
        /// The domain.
        domain: u16,
        /// The library's reason.
        reason: String,
    },
    /// A topic, writer or reader could not be created.
    #[error("cannot create the {what} of topic {topic}: {reason}")]
    Create {
        /// Writer, reader or topic.
        what: &'static str,
        /// The topic name.
        topic: String,
        /// The library's reason.
        reason: String,
    },
    /// A sample could not be written.
    #[error("writing to {topic} failed: {reason}")]
    Write {
        /// The topic.
        topic: String,
        /// The reason.
        reason: String,
    },
    /// A request got no answer in time.
    #[error("no answer from service {service} (api {api_id}) within {timeout:?}")]
    NoAnswer {
        /// The service.
        service: String,
        /// The API id.
        api_id: i64,
        /// How long the call waited.
        timeout: std::time::Duration,
    },
    /// A reader's stream ended (the participant is gone).
    #[error("the reader of {topic} was closed")]
    Closed {
        /// The topic.
        topic: String,
    },
}
