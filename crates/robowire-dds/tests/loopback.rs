//! Two participants where loopback carries multicast (`netns`): LowCmd and LowState on the wire
//! with Unitree's type names and QoS, counters, and a request/answer round trip.

use std::time::Duration;

use lowcmd_proto::api::{motion_switcher, status};
use lowcmd_proto::{LowCmd, LowState, Message};
use robowire_dds::netns::with_loopback_multicast;
use robowire_dds::qos::Qos;
use robowire_dds::rpc::{RpcClient, RpcServer};
use robowire_dds::{Participant, ParticipantOptions};

const WAIT: Duration = Duration::from_secs(20);

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().unwrap()
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
                        break sample.value;
                    }
                }
            })
            .await
            .expect("a LowCmd crossed");
            assert_eq!(received, cmd.sealed(), "decoded, CRC verified, as sent (sealed)");
            assert!(writer.matched_readers() >= 1);
            assert!(commands.stats().samples >= 1 && commands.stats().checksum_errors == 0);

            // A service call.
            let mut server = RpcServer::new(&robot, motion_switcher::SERVICE).unwrap();
            // A server answers every request: a client writes its request again until an answer
            // gets through (the first may be lost while discovery completes).
            let serve = tokio::spawn(async move {
                while let Ok(request) = server.next_request().await {
                    assert_eq!(request.header.api_id, motion_switcher::CHECK_MODE);
                    server.answer(&request.header, status::OK, r#"{"form":"0","name":"normal"}"#).unwrap();
                }
            });
            let switcher = RpcClient::new(&client, motion_switcher::SERVICE).unwrap();
            let answer = switcher.call(motion_switcher::CHECK_MODE, "{}", WAIT).await.unwrap();
            assert_eq!((answer.code, answer.data.as_str()), (status::OK, r#"{"form":"0","name":"normal"}"#));
            serve.abort();

            let _ = LowState::default();
        })
    });
}
