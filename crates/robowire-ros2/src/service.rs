//! `std_srvs/Trigger` services in rmw_cyclonedds' request/reply format.

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Reader, Writer};
use ros2_proto::srv::{RequestId, TriggerRequest, TriggerResponse};

use crate::node::Node;

/// One Trigger service: requests on `rq/NS/NAMERequest`, replies on `rr/NS/NAMEReply`.
pub(crate) struct TriggerService {
    pub(crate) name: &'static str,
    pub(crate) requests: Reader<TriggerRequest>,
    replies: Writer<TriggerResponse>,
    last: LastAnswer,
}

impl TriggerService {
    /// The service `name` of `node`, its request reader and reply writer listed under the node.
    pub(crate) fn new(node: &Node<'_>, name: &'static str) -> Result<Self, DdsError> {
        let (participant, namespace) = (node.participant, &node.options.namespace);
        Ok(Self {
            name,
            requests: node
                .listed_reader(participant.reader(&ros2_proto::request_topic(namespace, name), Qos::ROS_DEFAULT)?)?,
            replies: node
                .listed_writer(participant.writer(&ros2_proto::reply_topic(namespace, name), Qos::ROS_DEFAULT)?)?,
            last: LastAnswer::default(),
        })
    }

    /// The answer already given to `request` if it is the last one answered, sent again: a
    /// client that did not see the reply yet asks again with the same id, and the robot must not
    /// act twice. `None`: a new request, for the device.
    pub(crate) fn answer_again(&self, request: &TriggerRequest) -> Option<Result<(), DdsError>> {
        let (success, message) = self.last.to(request.id)?;
        Some(self.replies.write(TriggerResponse { id: request.id, success, message: message.to_owned() }))
    }

    /// Answers `request`.
    pub(crate) fn reply(&mut self, request: &TriggerRequest, success: bool, message: String) -> Result<(), DdsError> {
        self.last = LastAnswer(Some((request.id, success, message.clone())));
        self.replies.write(TriggerResponse { id: request.id, success, message })
    }
}

/// The last request a service answered, and its answer.
#[derive(Debug, Default)]
struct LastAnswer(Option<(RequestId, bool, String)>);

impl LastAnswer {
    /// The answer to `id`, if it was the last one answered.
    fn to(&self, id: RequestId) -> Option<(bool, &str)> {
        self.0.as_ref().filter(|(last, ..)| *last == id).map(|(_, success, message)| (*success, message.as_str()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_last_request_answered_is_answered_again() {
        let first = RequestId { guid: 7, seq: 1 };
        let mut last = LastAnswer::default();
        assert_eq!(last.to(first), None);
        last = LastAnswer(Some((first, true, "standing".into())));
        assert_eq!(last.to(first), Some((true, "standing")));
        assert_eq!(last.to(RequestId { seq: 2, ..first }), None, "the client's next request is new");
        assert_eq!(last.to(RequestId { guid: 8, ..first }), None, "another client's is new");
    }
}
