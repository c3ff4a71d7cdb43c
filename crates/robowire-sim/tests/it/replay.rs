//! The replay device from a client socket on 127.0.0.1, with the ZSL-1 dog's codec: the
//! recorded frames arrive exactly, in order, after the client's first command.

use std::net::{SocketAddr, UdpSocket};
use std::time::Duration;

use robowire_fixtures::wait::runtime;
use robowire_sim::replay::{DatagramReplay, Pace, ReplayError};
use zsl_proto::codec::HighLevelDogCodec;
use zsl_proto::udp::{HighLevelCommand, Model};

/// Every wait is bounded, so a broken player fails the test instead of hanging it.
const WATCHDOG: Duration = Duration::from_secs(10);

/// Frames of different lengths and contents, `step` apart.
fn frames(count: u8, step: Duration) -> Vec<(Duration, Vec<u8>)> {
    (0..count).map(|i| (step * u32::from(i), vec![i; 8 + usize::from(i)])).collect()
}

fn client() -> UdpSocket {
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    socket.set_read_timeout(Some(WATCHDOG)).unwrap();
    socket
}

/// What `socket` receives: `count` datagrams.
fn receive(socket: &UdpSocket, count: usize, from: SocketAddr) -> Vec<Vec<u8>> {
    let mut buf = [0u8; 1024];
    (0..count)
        .map(|_| {
            let (n, sender) = socket.recv_from(&mut buf).expect("a frame in time");
            assert_eq!(sender, from, "from the device's port");
            buf[..n].to_vec()
        })
        .collect()
}

fn command() -> [u8; HighLevelCommand::LEN] {
    HighLevelCommand::default().encode(Model::Zsl1)
}

#[test]
fn the_client_receives_exactly_the_frames_in_order_at_the_recorded_pace() {
    runtime().block_on(async {
        let recorded = frames(50, Duration::from_millis(2));
        let mut device =
            DatagramReplay::bind("127.0.0.1:0".parse().unwrap(), HighLevelDogCodec::default(), recorded.clone())
                .await
                .unwrap();
        let addr = device.local_addr().unwrap();
        assert_eq!(device.frames(), 50);
        let client = client();
        // Not a command: said, counted, and the device goes on waiting.
        client.send_to(b"hello", addr).unwrap();
        client.send_to(&command(), addr).unwrap();
        let first = tokio::time::timeout(WATCHDOG, async {
            loop {
                if let Ok(from) = device.first_command().await {
                    return from;
                }
            }
        })
        .await
        .expect("the first command in time");
        assert_eq!(first, client.local_addr().unwrap());
        // Commands during the playback are counted.
        client.send_to(&command(), addr).unwrap();
        let summary = tokio::time::timeout(WATCHDOG, device.play(Pace::Recorded { speed: 1.0 }))
            .await
            .expect("played in time")
            .unwrap();
        assert_eq!((summary.frames, summary.sent, summary.client), (50, 50, Some(first)));
        assert_eq!((summary.commands, summary.invalid), (2, 1));
        let received = receive(&client, 50, addr);
        assert_eq!(received, recorded.into_iter().map(|(_, bytes)| bytes).collect::<Vec<_>>());
    });
}

#[test]
fn fast_plays_every_frame_at_once_and_a_bad_speed_is_refused() {
    runtime().block_on(async {
        let bind = || async {
            DatagramReplay::bind(
                "127.0.0.1:0".parse().unwrap(),
                HighLevelDogCodec::default(),
                frames(20, Duration::from_secs(3600)),
            )
            .await
            .unwrap()
        };
        let client = client();
        let mut device = bind().await;
        let addr = device.local_addr().unwrap();
        client.send_to(&command(), addr).unwrap();
        tokio::time::timeout(WATCHDOG, device.first_command()).await.unwrap().unwrap();
        // An hour between frames, recorded: fast ignores it.
        let summary = tokio::time::timeout(WATCHDOG, device.play(Pace::Fast)).await.expect("at once").unwrap();
        assert_eq!((summary.sent, summary.commands), (20, 1));
        let received = receive(&client, 20, addr);
        assert!(received.iter().enumerate().all(|(i, frame)| frame[0] as usize == i && frame.len() == 8 + i));

        for speed in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let refused = bind().await.play(Pace::Recorded { speed }).await;
            assert!(matches!(refused, Err(ReplayError::Speed(_))), "{speed}: {refused:?}");
        }
    });
}
