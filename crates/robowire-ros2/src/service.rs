//! `std_srvs/Trigger` services that answer clients of both ROS 2 middlewares, the mapping chosen
//! per request.
//!
//! What decides is the request itself: a body longer than rmw_cyclonedds' 16-byte header is
//! rmw_cyclonedds' mapping (the header is echoed in the reply's body); a bare request (1 byte,
//! padded up to 8) is rmw_fastrtps' (the reply carries the request's identity as its related
//! sample identity: the reader the client named in the request's related sample identity, else
//! the request's writer, with the request's sequence number; a reply to a named reader waits up
//! to 100 ms for that reader to be matched, as rmw_fastrtps does). rmw_cyclonedds' clients also
//! announce `clientid=` in their writers' USER_DATA; the request's own shape is enough, so it is
//! not used. A request of neither shape is counted by the request reader as a decode error and
//! not answered.

use std::time::Duration;

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Reader, Sample, SampleIdentity, StatsHandle, Writer};
use ros2_proto::srv::{AnyTriggerRequest, AnyTriggerResponse, RequestId, TriggerResponse, TriggerResponseBody};

use crate::node::Node;

/// Who asked, in which mapping: what names the request in the reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Caller {
    /// rmw_cyclonedds: the request's header, echoed in the reply's body.
    Cyclone(RequestId),
    /// rmw_fastrtps: the reply's related sample identity.
    FastRtps(SampleIdentity),
}

impl Caller {
    /// The caller of `request` and what its reply must name.
    pub(crate) fn of(request: &Sample<AnyTriggerRequest>) -> Self {
        match &request.value {
            AnyTriggerRequest::WithHeader(r) => Self::Cyclone(r.id),
            AnyTriggerRequest::Bare(_) => {
                // rmw_fastrtps' client names its reply reader (with an unknown sequence number);
                // without a known writer GUID there, the request's own writer.
                let writer = request.related.filter(SampleIdentity::writer_known).map_or(request.writer, |r| r.writer);
                Self::FastRtps(SampleIdentity { writer, sequence: request.sequence })
            }
        }
    }
}

/// How long a reply waits for the reader an rmw_fastrtps client named to be matched (as
/// rmw_fastrtps and rmw_cyclonedds wait, 100 ms): a volatile reply written before is lost.
const REPLY_READER_WAIT: Duration = Duration::from_millis(100);

/// How often the reply writer's matches are looked at meanwhile.
const REPLY_READER_POLL: Duration = Duration::from_millis(10);

/// One Trigger service: requests on `rq/NS/NAMERequest`, replies on `rr/NS/NAMEReply`.
pub(crate) struct TriggerService {
    pub(crate) name: &'static str,
    pub(crate) requests: Reader<AnyTriggerRequest>,
    replies: Writer<AnyTriggerResponse>,
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

    /// The request reader's counters (requests of neither shape are its decode errors).
    pub(crate) fn requests_stats(&self) -> StatsHandle {
        self.requests.stats_handle()
    }

    /// The answer already given to `caller` if it is the last one answered, sent again: a
    /// client that did not see the reply yet asks again with the same id, and the robot must not
    /// act twice. `None`: a new request, for the device.
    pub(crate) fn answer_again(&self, caller: Caller) -> Option<impl Future<Output = Result<(), DdsError>> + '_> {
        let (success, message) = self.last.to(caller)?;
        Some(send(&self.replies, caller, success, message.to_owned()))
    }

    /// Answers `caller`.
    pub(crate) fn reply(
        &mut self,
        caller: Caller,
        success: bool,
        message: String,
    ) -> impl Future<Output = Result<(), DdsError>> + '_ {
        self.last = LastAnswer(Some((caller, success, message.clone())));
        send(&self.replies, caller, success, message)
    }
}

/// The reply in `caller`'s mapping on `replies`; to a reader an rmw_fastrtps client named, once
/// that reader is matched or after [`REPLY_READER_WAIT`] (then sent anyway).
async fn send(
    replies: &Writer<AnyTriggerResponse>,
    caller: Caller,
    success: bool,
    message: String,
) -> Result<(), DdsError> {
    match caller {
        Caller::Cyclone(id) => replies.write(AnyTriggerResponse::WithHeader(TriggerResponse { id, success, message })),
        Caller::FastRtps(request) => {
            // A GUID whose entity kind has the reader bit (0x04): the client's reply reader.
            if request.writer[15] & 0x04 != 0 {
                let matched = async {
                    while !replies.reader_matched(request.writer) {
                        tokio::time::sleep(REPLY_READER_POLL).await;
                    }
                };
                let _ = tokio::time::timeout(REPLY_READER_WAIT, matched).await;
            }
            let reply = AnyTriggerResponse::Bare(TriggerResponseBody { success, message });
            replies.write_related(reply, request).map(drop)
        }
    }
}

/// The last request a service answered, and its answer.
#[derive(Debug, Default)]
struct LastAnswer(Option<(Caller, bool, String)>);

impl LastAnswer {
    /// The answer to `caller`, if it was the last one answered.
    fn to(&self, caller: Caller) -> Option<(bool, &str)> {
        self.0.as_ref().filter(|(last, ..)| *last == caller).map(|(_, success, message)| (*success, message.as_str()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ros2_proto::srv::{TriggerRequest, TriggerRequestBody};

    #[test]
    fn only_the_last_request_answered_is_answered_again() {
        let first = Caller::Cyclone(RequestId { guid: 7, seq: 1 });
        let mut last = LastAnswer::default();
        assert_eq!(last.to(first), None);
        last = LastAnswer(Some((first, true, "standing".into())));
        assert_eq!(last.to(first), Some((true, "standing")));
        assert_eq!(last.to(Caller::Cyclone(RequestId { guid: 7, seq: 2 })), None, "the client's next request is new");
        assert_eq!(last.to(Caller::Cyclone(RequestId { guid: 8, seq: 1 })), None, "another client's is new");
        let fast = Caller::FastRtps(SampleIdentity { writer: [7; 16], sequence: 1 });
        assert_eq!(last.to(fast), None, "the other mapping's is new");
    }

    const WRITER: [u8; 16] = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0, 0, 1, 3];
    const REPLY_READER: [u8; 16] = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 0, 0, 2, 4];

    fn sample(value: AnyTriggerRequest, related: Option<SampleIdentity>) -> Sample<AnyTriggerRequest> {
        Sample { value, writer: WRITER, sequence: 5, related }
    }

    #[test]
    fn the_request_tells_the_mapping_and_what_the_reply_names() {
        let id = RequestId { guid: 0x0110_3f5a_0000_0107, seq: 3 };
        let cyclone = AnyTriggerRequest::WithHeader(TriggerRequest { id, structure_needs_at_least_one_member: 0 });
        assert_eq!(Caller::of(&sample(cyclone.clone(), None)), Caller::Cyclone(id));
        // ros2-client's Cyclone mapping sends a related identity too: the header decides.
        let named = Some(SampleIdentity { writer: REPLY_READER, sequence: 9 });
        assert_eq!(Caller::of(&sample(cyclone, named)), Caller::Cyclone(id));

        let bare = AnyTriggerRequest::Bare(TriggerRequestBody::default());
        let fast_dds = Some(SampleIdentity { writer: REPLY_READER, sequence: SampleIdentity::SEQUENCE_UNKNOWN });
        assert_eq!(
            Caller::of(&sample(bare.clone(), fast_dds)),
            Caller::FastRtps(SampleIdentity { writer: REPLY_READER, sequence: 5 }),
            "Fast DDS: its reply reader, the request's sequence number"
        );
        let unknown_writer = Some(SampleIdentity { writer: [0; 16], sequence: SampleIdentity::SEQUENCE_UNKNOWN });
        let own = Caller::FastRtps(SampleIdentity { writer: WRITER, sequence: 5 });
        assert_eq!(Caller::of(&sample(bare.clone(), unknown_writer)), own, "an unknown GUID: the request's writer");
        assert_eq!(Caller::of(&sample(bare, None)), own, "no related identity: the request's own identity");
    }
}
