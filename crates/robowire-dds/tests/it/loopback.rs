//! Two participants where loopback carries multicast (`netns`): LowCmd and LowState on the wire
//! with Unitree's type names and QoS, counters, and a request/answer round trip.

use std::time::Duration;

use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::rpc::{RpcClient, RpcServer, Service};
use robowire_dds::{Participant, ParticipantOptions, Reader};
use robowire_fixtures::wait::runtime;
use unitree_proto::api::{self, ApiRequest, ApiResponse, RequestHeader, Response, motion_switcher, status};
use unitree_proto::{LowCmd, LowState, Message};

const WAIT: Duration = Duration::from_secs(20);

/// A request/answer protocol for the test: Unitree's service messages, paired by id.
struct Api;

impl Service for Api {
    type Request = ApiRequest;
    type Answer = ApiResponse;
    fn request_id(request: &ApiRequest) -> i64 {
        request.header.id
    }
    fn answer_id(answer: &ApiResponse) -> i64 {
        answer.id
    }
}

#[test]
fn lowcmd_and_lowstate_between_two_participants_and_a_call() {
    with_loopback_multicast(|| {
        runtime().block_on(async {
            let options = ParticipantOptions::new(0, Some("lo"));
            let robot = Participant::new(options.clone()).unwrap();
            let client = Participant::new(options).unwrap();

            let mut commands = robot.reader::<LowCmd>(LowCmd::TOPIC, Qos::READER).unwrap();
            let writer = client.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
            let mut cmd = LowCmd::default();
            cmd.motor_cmd[2].q = (-1.3).into();
            // Keep writing until the reader has one (discovery takes a moment).
            let received = tokio::time::timeout(WAIT, async {
                loop {
                    writer.write(cmd).unwrap();
                    if let Ok(Ok(sample)) = tokio::time::timeout(Duration::from_millis(50), commands.recv()).await {
                        break sample;
                    }
                }
            })
            .await
            .expect("a LowCmd crossed");
            assert_eq!(received.value, cmd.sealed(), "decoded, CRC verified, as sent (sealed)");

            // GUIDs: the writer's on its samples and in the other side's discovery, under its
            // participant's prefix.
            assert_eq!(received.writer, writer.guid());
            assert_eq!(client.guid()[12..], [0, 0, 1, 0xc1], "the participant entity");
            assert_eq!(writer.guid()[..12], client.guid()[..12]);
            assert_eq!(commands.guid()[..12], robot.guid()[..12]);
            assert_ne!(writer.guid(), client.guid());
            let seen = |by: &Participant, guid: [u8; 16], is_writer: bool| {
                by.discovered_endpoints().into_iter().any(|e| {
                    e.guid == guid
                        && e.writer == is_writer
                        && e.topic == LowCmd::TOPIC
                        && e.type_name == <LowCmd as robowire_core::cdr::CdrType>::TYPE_NAME
                })
            };
            assert!(seen(&robot, writer.guid(), true), "{:?}", robot.discovered_endpoints());
            tokio::time::timeout(WAIT, async {
                while !seen(&client, commands.guid(), false) {
                    tokio::time::sleep(Duration::from_millis(20)).await;
                }
            })
            .await
            .expect("the client discovers the robot's reader");
            assert!(writer.matched_readers() >= 1);
            assert!(commands.stats().samples >= 1 && commands.stats().checksum_errors == 0);

            // A service call.
            let (requests, answers) = (
                api::request_topic(motion_switcher::SERVICE).to_string(),
                api::response_topic(motion_switcher::SERVICE).to_string(),
            );
            let mut server = RpcServer::<ApiRequest, ApiResponse>::new(&robot, &requests, &answers).unwrap();
            // A server answers every request: a client writes its request again until an answer
            // gets through (the first may be lost while discovery completes).
            let serve = tokio::spawn(async move {
                while let Ok(request) = server.next_request().await {
                    assert_eq!(request.header.api_id, motion_switcher::CHECK_MODE);
                    let answer = Response::to(&request.header, status::OK, r#"{"form":"0","name":"normal"}"#);
                    server.answer(answer.into()).unwrap();
                }
            });
            let switcher = RpcClient::<Api>::new(&client, &requests, &answers).unwrap();
            let request = ApiRequest {
                header: RequestHeader::call(7, motion_switcher::CHECK_MODE),
                parameter: "{}".into(),
                binary: Vec::new(),
            };
            let answer = switcher.call(request, WAIT).await.unwrap();
            assert_eq!(
                (answer.id, answer.code, answer.data.as_str()),
                (7, status::OK, r#"{"form":"0","name":"normal"}"#)
            );
            serve.abort();

            let _ = LowState::default();
        })
    });
}

fn tagged(tag: u32) -> LowCmd {
    let mut cmd = LowCmd::default();
    cmd.reserve = tag.into();
    cmd
}

/// The tag of the reader's next sample.
async fn next(reader: &mut Reader<LowCmd>) -> u32 {
    tokio::time::timeout(WAIT, reader.recv()).await.expect("a sample").unwrap().value.reserve.get()
}

/// Of the samples that arrived since the last `recv`, a reader keeps the newest `depth` (its QoS's
/// keep-last history), oldest first: a keep-last-1 reader gets the newest.
#[test]
fn a_reader_delivers_the_newest_depth_samples_oldest_first() {
    with_loopback_multicast(|| {
        runtime().block_on(async {
            let options = ParticipantOptions::new(0, Some("lo"));
            let robot = Participant::new(options.clone()).unwrap();
            let client = Participant::new(options).unwrap();
            // Reliable, so that none of the burst is lost; all three in one participant, fed by
            // its one event loop in arrival order.
            let reliable = |depth| Qos { reliable: true, depth, ..Qos::READER };
            let mut every = robot.reader::<LowCmd>(LowCmd::TOPIC, reliable(16)).unwrap();
            let mut newest = robot.reader::<LowCmd>(LowCmd::TOPIC, reliable(1)).unwrap();
            let mut four = robot.reader::<LowCmd>(LowCmd::TOPIC, reliable(4)).unwrap();
            let writer = client.writer::<LowCmd>(LowCmd::TOPIC, Qos::WRITER).unwrap();
            // Tag 0 until each reader has one (discovery takes a moment).
            for reader in [&mut every, &mut newest, &mut four] {
                tokio::time::timeout(WAIT, async {
                    loop {
                        writer.write(tagged(0)).unwrap();
                        if let Ok(Ok(_)) = tokio::time::timeout(Duration::from_millis(50), reader.recv()).await {
                            break;
                        }
                    }
                })
                .await
                .expect("each reader matched");
            }
            for tag in 1..=11 {
                writer.write(tagged(tag)).unwrap();
            }
            // Once the depth-16 reader has all eleven, in order, the other two have them too.
            let mut seen = Vec::new();
            while seen.last() != Some(&11) {
                let sample = tokio::time::timeout(WAIT, every.recv()).await.expect("the burst").unwrap();
                let tag = sample.value.reserve.get();
                if tag != 0 {
                    seen.push(tag);
                }
            }
            assert_eq!(seen, (1..=11).collect::<Vec<u32>>());
            assert_eq!(next(&mut newest).await, 11, "keep last 1: the newest");
            let mut last_four = Vec::new();
            for _ in 0..4 {
                last_four.push(next(&mut four).await);
            }
            assert_eq!(last_four, [8, 9, 10, 11], "keep last 4: the newest four, oldest first");
            assert_eq!(newest.stats().decode_errors + four.stats().checksum_errors, 0);
        })
    });
}

/// A sample's RTPS sequence number and its related sample identity cross the wire: a plain write
/// carries none, `write_related` the one given (as an rmw_fastrtps reply names its request),
/// an unknown sequence number included.
#[test]
fn a_related_sample_identity_and_the_sequence_number_cross() {
    use robowire_dds::SampleIdentity;
    with_loopback_multicast(|| {
        runtime().block_on(async {
            let options = ParticipantOptions::new(0, Some("lo"));
            let robot = Participant::new(options.clone()).unwrap();
            let client = Participant::new(options).unwrap();
            let reliable = Qos { reliable: true, depth: 16, ..Qos::READER };
            let mut reader = robot.reader::<LowCmd>(LowCmd::TOPIC, reliable).unwrap();
            let writer = client.writer::<LowCmd>(LowCmd::TOPIC, Qos { reliable: true, ..Qos::WRITER }).unwrap();
            let first = tokio::time::timeout(WAIT, async {
                loop {
                    writer.write(tagged(0)).unwrap();
                    if let Ok(Ok(sample)) = tokio::time::timeout(Duration::from_millis(50), reader.recv()).await {
                        break sample;
                    }
                }
            })
            .await
            .expect("the reader matched");
            assert_eq!(first.related, None, "a plain write names no other sample");
            let matched = tokio::time::timeout(WAIT, async {
                while !writer.reader_matched(reader.guid()) {
                    tokio::time::sleep(Duration::from_millis(10)).await;
                }
            })
            .await;
            assert!(matched.is_ok(), "the writer names its matched reader");
            assert!(!writer.reader_matched(writer.guid()), "not a reader of it");
            assert!(first.sequence >= 1, "{first:?}");
            let related = SampleIdentity { writer: reader.guid(), sequence: 42 };
            let unknown = SampleIdentity { writer: reader.guid(), sequence: SampleIdentity::SEQUENCE_UNKNOWN };
            let one = writer.write_related(tagged(1), related).unwrap();
            let two = writer.write_related(tagged(2), unknown).unwrap();
            assert_eq!(
                (one.writer, two.sequence),
                (writer.guid(), one.sequence + 1),
                "the written samples' identities"
            );
            let mut seen = Vec::new();
            while seen.len() < 2 {
                let sample = tokio::time::timeout(WAIT, reader.recv()).await.expect("the related samples").unwrap();
                if sample.value.reserve.get() != 0 {
                    seen.push(sample);
                }
            }
            assert_eq!((seen[0].related, seen[1].related), (Some(related), Some(unknown)));
            assert_eq!((seen[0].sequence, seen[1].sequence), (one.sequence, two.sequence), "as written");
            assert!(seen[0].sequence > first.sequence);
            assert!(unknown.writer_known() && !SampleIdentity { writer: [0; 16], sequence: 1 }.writer_known());
        })
    });
}

#[test]
fn participant_user_data_is_announced_and_a_leaving_participant_is_forgotten_at_once() {
    with_loopback_multicast(|| {
        let options = ParticipantOptions::new(0, Some("lo"));
        let ros =
            Participant::new(ParticipantOptions { user_data: b"enclave=/;".to_vec(), ..options.clone() }).unwrap();
        let observer = Participant::new(options).unwrap();
        let ros_prefix: [u8; 12] = ros.guid()[..12].try_into().unwrap();
        let began = std::time::Instant::now();
        let seen = loop {
            if let Some(p) = observer.discovered_participants().into_iter().find(|p| p.guid_prefix == ros_prefix) {
                break p;
            }
            assert!(began.elapsed() < WAIT, "never discovered");
            std::thread::sleep(Duration::from_millis(5));
        };
        assert_eq!(seen.user_data, b"enclave=/;");
        assert_eq!(seen.vendor.1, Some("robowire"));
        assert!(!seen.unicast.is_empty());
        // Its dispose arrives when it is dropped: gone long before its 20 s lease.
        drop(ros);
        robowire_fixtures::wait::until(Duration::from_secs(10), "forgotten after its dispose", || {
            !observer.discovered_participants().iter().any(|p| p.guid_prefix == ros_prefix)
        });
    });
}
