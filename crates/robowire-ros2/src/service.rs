//! `std_srvs/Trigger` services in rmw_cyclonedds' request/reply format.

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Participant, Reader, Writer};
use ros2_proto::srv::{TriggerRequest, TriggerResponse};

/// One Trigger service: requests on `rq/NS/NAMERequest`, replies on `rr/NS/NAMEReply`.
pub(crate) struct TriggerService {
    pub(crate) name: &'static str,
    pub(crate) requests: Reader<TriggerRequest>,
    replies: Writer<TriggerResponse>,
}

impl TriggerService {
    pub(crate) fn new(participant: &Participant, namespace: &str, name: &'static str) -> Result<Self, DdsError> {
        Ok(Self {
            name,
            requests: participant.reader(&ros2_proto::request_topic(namespace, name), Qos::ROS_DEFAULT)?,
            replies: participant.writer(&ros2_proto::reply_topic(namespace, name), Qos::ROS_DEFAULT)?,
        })
    }

    /// Answers `request`.
    pub(crate) fn reply(&self, request: &TriggerRequest, success: bool, message: String) -> Result<(), DdsError> {
        self.replies.write(TriggerResponse { id: request.id, success, message })
    }
}
