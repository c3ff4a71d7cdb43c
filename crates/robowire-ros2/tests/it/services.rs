//! A device's services (`std_srvs/Trigger`) called by ros2-client (an independent ROS 2 client
//! library on rustdds) in rmw_fastrtps' and rmw_cyclonedds' mappings, and by robowire's own DDS
//! with a request of neither shape (counted, not answered) and as Fast DDS sends one.

use robowire_dds::netns::with_loopback_multicast;
use robowire_ros2::BridgeOptions;

use crate::{Bridge, WAIT, options};

/// A simulated dog at the root namespace, on `lo`.
fn one_dog() -> BridgeOptions {
    BridgeOptions { interface: Some("lo".into()), ..options(&["sim:zsl1"]) }
}

/// `std_srvs/Trigger` as ros2-client (an independent ROS 2 client library on rustdds) declares it.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct TriggerRequest {
    structure_needs_at_least_one_member: u8,
}
impl ros2_client::Message for TriggerRequest {}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct TriggerResponse {
    success: bool,
    message: String,
}
impl ros2_client::Message for TriggerResponse {}

/// ros2-client calls a simulated dog's `stand_up` (one device: the root namespace) in rmw_fastrtps'
/// mapping (its `Enhanced`: the bare request, the reply named by its related sample identity) and
/// in rmw_cyclonedds' (the 16-byte header before the request, echoed): the bridge answers both.
/// A bridge per mapping: rustdds hands a new reply reader the replies written before it, and
/// ros2-client fails a call on a reply of the other mapping's shape instead of skipping it.
#[test]
fn a_ros2_client_calls_stand_up_in_both_middlewares_mappings() {
    use ros2_client::{Context, Name, NodeName, NodeOptions, QosProfile, ServiceMapping, ServiceTypeName};
    use std::net::{IpAddr, Ipv4Addr};

    with_loopback_multicast(|| {
        for (middleware, mapping) in
            [("rmw_fastrtps", ServiceMapping::Enhanced), ("rmw_cyclonedds", ServiceMapping::Cyclone)]
        {
            let bridge = Bridge::start(one_dog());
            // Kept until the bridge stopped: ros2-client's node spins on it.
            let runtime = robowire_fixtures::wait::runtime_two_workers();
            let reply = runtime.block_on(async {
                let participant = ros2_client::dds::rustdds::DomainParticipantBuilder::new(0)
                    .with_only_networks([IpAddr::V4(Ipv4Addr::LOCALHOST)])
                    .build()
                    .unwrap();
                let context = Context::from_domain_participant(participant).unwrap();
                let mut node =
                    context.new_node(NodeName::new("/", "trigger_caller").unwrap(), NodeOptions::new()).unwrap();
                // Reliable, as the bridge's request reader (ros2-client's default QoS is best effort).
                let qos = QosProfile::publisher_default();
                let (name, type_name) =
                    (Name::new("/", "stand_up").unwrap(), ServiceTypeName::new("std_srvs", "Trigger"));
                let client = node
                    .create_client::<TriggerRequest, TriggerResponse>(mapping, &name, &type_name, qos.clone(), qos)
                    .unwrap();
                tokio::spawn(node.spinner().unwrap().spin());
                let found = tokio::time::timeout(WAIT, client.wait_for_service(&node)).await;
                assert!(found.is_ok(), "{middleware}: the service's reader and writer matched");
                let call = client.async_call_service(TriggerRequest { structure_needs_at_least_one_member: 0 });
                tokio::time::timeout(WAIT, call)
                    .await
                    .unwrap_or_else(|_| panic!("{middleware}: no answer"))
                    .unwrap_or_else(|e| panic!("{middleware}: {e:?}"))
            });
            assert!(reply.success, "{middleware}: {reply:?}");
            assert!(reply.message.starts_with("stand_up sent"), "{middleware}: {reply:?}");
            let counters = bridge.stop()[0].counters();
            assert_eq!(counters.service_calls, 1, "{middleware}: {counters:?}");
            assert_eq!(counters.malformed_requests, 0, "{middleware}");
        }
    });
}

/// A Trigger request of neither mapping's shape (too long for the bare request, too short for
/// rmw_cyclonedds' header and request) is counted and not answered; then a request as Fast DDS
/// sends it (bare, its related sample identity naming the client's reply reader with an unknown
/// sequence number) is answered with a reply naming that reader and the request's sequence number.
#[test]
fn a_request_of_neither_shape_is_counted_and_a_fast_dds_request_answered() {
    use robowire_core::cdr::{CdrEncoding, CdrType};
    use robowire_dds::{Participant, ParticipantOptions, RawSample, SampleIdentity};
    use ros2_proto::srv::{TriggerRequest, TriggerRequestBody, TriggerResponseBody};

    with_loopback_multicast(|| {
        let bridge = Bridge::start(one_dog());
        robowire_fixtures::wait::runtime().block_on(async {
            let participant = Participant::new(ParticipantOptions::new(0, Some("lo"))).unwrap();
            let qos = robowire_dds::qos::Qos::ROS_DEFAULT;
            let bad = participant.raw_writer("rq/stand_upRequest", TriggerRequest::TYPE_NAME, qos).unwrap();
            let requests = participant.writer::<TriggerRequestBody>("rq/stand_upRequest", qos).unwrap();
            let mut replies = participant.reader::<TriggerResponseBody>("rr/stand_upReply", qos).unwrap();
            let matched = tokio::time::timeout(WAIT, async {
                while bad.matched_readers() == 0 || requests.matched_readers() == 0 {
                    tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                }
            })
            .await;
            assert!(matched.is_ok(), "the bridge's request reader matched");
            for len in [12, 0] {
                bad.write(RawSample { encoding: CdrEncoding::Xcdr1, body: vec![0; len] }).unwrap();
            }
            let acknowledged = tokio::time::timeout(WAIT, bad.acknowledged()).await;
            assert!(matches!(acknowledged, Ok(Ok(true))), "the bridge has both bad requests");
            // Asked again (a new request each time) if no reply comes (the bridge waits at most
            // 100 ms for its reply writer to match the reader named).
            let reply_to = SampleIdentity { writer: replies.guid(), sequence: SampleIdentity::SEQUENCE_UNKNOWN };
            let mut sent = Vec::new();
            let reply = tokio::time::timeout(WAIT, async {
                loop {
                    sent.push(requests.write_related(TriggerRequestBody::default(), reply_to).unwrap());
                    let reply = tokio::time::timeout(std::time::Duration::from_millis(200), replies.recv()).await;
                    if let Ok(reply) = reply {
                        break reply.unwrap();
                    }
                }
            })
            .await
            .expect("the Fast DDS request is answered");
            assert!(reply.value.success && reply.value.message.starts_with("stand_up sent"), "{reply:?}");
            let named = reply.related.expect("the reply names its request");
            assert_eq!(named.writer, replies.guid(), "the client's reply reader");
            assert!(
                sent.iter().any(|s| s.sequence == named.sequence),
                "a request's sequence number: {named:?} {sent:?}"
            );
        });
        let counters = bridge.stop()[0].counters();
        assert_eq!(counters.malformed_requests, 2, "{counters:?}");
        assert!(counters.service_calls >= 1);
    });
}
