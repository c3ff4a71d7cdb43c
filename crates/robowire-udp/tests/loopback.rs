//! The link on loopback: typed send and receive, foreign sources, decode errors, bind errors.
//! 127.0.0.2 (also loopback on Linux) plays the foreign host.

use std::net::{SocketAddr, UdpSocket};
use std::time::Duration;

use robowire_core::DatagramCodec;
use robowire_udp::{LinkStats, Peer, UdpError, UdpLink};

/// Messages are a little-endian u32; anything else is a decode error.
#[derive(Clone, Default)]
struct Word;

#[derive(Debug, PartialEq, thiserror::Error)]
#[error("{0} bytes, 4 expected")]
struct BadLength(usize);

impl DatagramCodec for Word {
    type Outgoing = u32;
    type Incoming = u32;
    type Error = BadLength;
    const MAX_DATAGRAM_LEN: usize = 4;
    fn encode(&mut self, m: &u32, buf: &mut [u8]) -> Result<usize, BadLength> {
        let available = buf.len();
        buf.get_mut(..4).ok_or(BadLength(available))?.copy_from_slice(&m.to_le_bytes());
        Ok(4)
    }
    fn decode(&mut self, d: &[u8]) -> Result<u32, BadLength> {
        Ok(u32::from_le_bytes(d.try_into().map_err(|_| BadLength(d.len()))?))
    }
}

fn peer() -> UdpSocket {
    let s = UdpSocket::bind("127.0.0.1:0").unwrap();
    s.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
    s
}

async fn link_to(peer: &UdpSocket) -> UdpLink<Word> {
    UdpLink::bind("127.0.0.1:0".parse().unwrap(), Peer::AnyPortOf(peer.local_addr().unwrap()), Word).await.unwrap()
}

async fn recv(link: &mut UdpLink<Word>) -> Result<u32, UdpError<BadLength>> {
    tokio::time::timeout(Duration::from_secs(2), link.recv()).await.expect("a datagram within 2 s")
}

#[tokio::test]
async fn typed_messages_both_ways() {
    let robot = peer();
    let mut link = link_to(&robot).await;
    link.send(&0xA55A_0102).await.unwrap();
    let mut buf = [0u8; 16];
    let (n, from) = robot.recv_from(&mut buf).unwrap();
    assert_eq!(&buf[..n], &0xA55A_0102u32.to_le_bytes());
    assert_eq!(from, link.local_addr().unwrap(), "sent from the bound socket");

    robot.send_to(&7u32.to_le_bytes(), from).unwrap();
    assert_eq!(recv(&mut link).await.unwrap(), 7);
    assert_eq!(link.stats(), LinkStats { sent: 1, received: 1, ..LinkStats::default() });
}

#[tokio::test]
async fn foreign_sources_are_dropped_and_counted_decode_errors_reported() {
    let robot = peer();
    let mut link = link_to(&robot).await;
    let to = link.local_addr().unwrap();
    let spoofer = UdpSocket::bind("127.0.0.2:0").expect("127.0.0.2 is loopback on Linux");
    spoofer.send_to(&1u32.to_le_bytes(), to).unwrap();
    // Another port on the robot's IP is the robot: the source port is not compared.
    let robot_other_port = peer();
    robot_other_port.send_to(&[1, 2, 3], to).unwrap();
    robot.send_to(&2u32.to_le_bytes(), to).unwrap();

    assert!(matches!(recv(&mut link).await, Err(UdpError::Decode(BadLength(3)))));
    assert_eq!(recv(&mut link).await.unwrap(), 2, "the spoofed 1 never arrives");
    let stats = link.stats();
    assert_eq!((stats.received, stats.decode_errors, stats.foreign_dropped), (2, 1, 1));
}

#[tokio::test]
async fn an_exact_peer_drops_other_ports_of_its_ip() {
    let robot = peer();
    let mut link =
        UdpLink::bind("127.0.0.1:0".parse().unwrap(), Peer::Exact(robot.local_addr().unwrap()), Word).await.unwrap();
    let to = link.local_addr().unwrap();
    peer().send_to(&1u32.to_le_bytes(), to).unwrap(); // the robot's IP, another port
    robot.send_to(&2u32.to_le_bytes(), to).unwrap();
    assert_eq!(recv(&mut link).await.unwrap(), 2);
    assert_eq!((link.stats().received, link.stats().foreign_dropped), (1, 1));
}

#[tokio::test]
async fn the_device_side_answers_whoever_spoke_last() {
    let mut device = UdpLink::bind("127.0.0.1:0".parse().unwrap(), Peer::Any { reply_to: None }, Word).await.unwrap();
    assert!(matches!(device.send(&1).await, Err(UdpError::NoPeer)), "nobody to answer yet");
    assert_eq!(device.stats().send_errors, 1);
    let (first, second) = (peer(), peer());
    let to = device.local_addr().unwrap();
    first.send_to(&[1, 2, 3], to).unwrap(); // does not decode: not learned
    first.send_to(&10u32.to_le_bytes(), to).unwrap();
    assert!(matches!(recv(&mut device).await, Err(UdpError::Decode(BadLength(3)))));
    assert_eq!(recv(&mut device).await.unwrap(), 10);
    assert_eq!(device.destination(), first.local_addr().ok());
    second.send_to(&11u32.to_le_bytes(), to).unwrap();
    assert_eq!(recv(&mut device).await.unwrap(), 11);
    let (mut tx, _rx) = device.into_split();
    // From a plain thread, without the runtime.
    std::thread::spawn(move || tx.send_now(&12).unwrap()).join().unwrap();
    let mut buf = [0u8; 8];
    let (n, _) = second.recv_from(&mut buf).unwrap();
    assert_eq!(&buf[..n], &12u32.to_le_bytes(), "the reply goes to whoever spoke last");
}

#[tokio::test]
async fn an_over_long_datagram_is_a_decode_error_not_a_truncation() {
    let robot = peer();
    let mut link = link_to(&robot).await;
    robot.send_to(&[0; 5], link.local_addr().unwrap()).unwrap();
    assert!(matches!(recv(&mut link).await, Err(UdpError::Decode(BadLength(5)))));
}

#[tokio::test]
async fn split_halves_work_from_two_tasks() {
    let robot = peer();
    let link = link_to(&robot).await;
    let local = link.local_addr().unwrap();
    let stats = link.stats_handle();
    let (mut tx, mut rx) = link.into_split();
    let receiving = tokio::spawn(async move { rx.recv().await.unwrap() });
    tx.send(&9).await.unwrap();
    let mut buf = [0u8; 8];
    let (_, from) = robot.recv_from(&mut buf).unwrap();
    assert_eq!(from, local);
    robot.send_to(&10u32.to_le_bytes(), local).unwrap();
    assert_eq!(tokio::time::timeout(Duration::from_secs(2), receiving).await.unwrap().unwrap(), 10);
    assert_eq!((stats.get().sent, stats.get().received), (1, 1));
}

#[tokio::test]
async fn a_bind_failure_names_the_address_and_lists_the_hosts_ipv4_addresses() {
    let taken = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap();
    let err = UdpLink::bind(addr, Peer::Exact(addr), Word).await.unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, UdpError::Bind { addr: a, .. } if a == addr), "{text}");
    assert!(text.contains(&addr.to_string()), "{text}");
    assert!(text.contains("127.0.0.1"), "loopback is among the host's addresses: {text}");

    // An address this host does not have: the classic wrong `local_ip`.
    let foreign: SocketAddr = "192.0.2.1:43988".parse().unwrap();
    let err = UdpLink::bind(foreign, Peer::Exact(addr), Word).await.unwrap_err();
    assert!(err.to_string().starts_with("cannot bind UDP 192.0.2.1:43988"), "{err}");
}

#[tokio::test]
async fn arrival_stamps_are_the_network_stacks_times() {
    let peer = peer();
    let (_sender, mut receiver) = link_to(&peer).await.into_split();
    receiver.enable_arrival_stamps().unwrap();
    let to = receiver.local_addr().unwrap();
    // Linux turns stamping on for the whole stack a moment after the first socket asks
    // (a deferred static key); until then a datagram is stamped when it is read. Wait for
    // that: a datagram left unread for 5 ms must carry a stamp at least 4 ms old.
    let began = std::time::Instant::now();
    loop {
        peer.send_to(&0u32.to_le_bytes(), to).unwrap();
        std::thread::sleep(Duration::from_millis(5));
        let (_, _, stamp) = receiver.recv_stamped().await.unwrap();
        let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap();
        if now.saturating_sub(stamp.unwrap()) >= Duration::from_millis(4) {
            break;
        }
        assert!(began.elapsed() < Duration::from_secs(20), "the kernel never stamped a datagram at its arrival");
    }
    let before = receiver.stats().received;
    peer.send_to(&7u32.to_le_bytes(), to).unwrap();
    std::thread::sleep(Duration::from_millis(20));
    peer.send_to(&8u32.to_le_bytes(), to).unwrap();
    // Both are queued before the first is read: their stamps are still 20 ms apart.
    let (a, from, first) = receiver.recv_stamped().await.unwrap();
    let (b, _, second) = receiver.recv_stamped().await.unwrap();
    assert_eq!((a, b, from), (7, 8, peer.local_addr().unwrap()));
    let gap = second.unwrap().saturating_sub(first.unwrap());
    assert!(gap >= Duration::from_millis(19), "stamped when they arrived, not when read: {gap:?}");
    assert_eq!(receiver.stats().received, before + 2);
}

/// Waits (at most 2 s per look) on the receiver's socket, as a stream thread does, and returns
/// the next datagram the peer filter lets through.
fn next_now(receiver: &mut robowire_udp::UdpReceiver<Word>) -> Result<u32, UdpError<BadLength>> {
    use rustix::event::{PollFd, PollFlags, Timespec, poll};
    loop {
        let mut fds = [PollFd::new(receiver, PollFlags::IN)];
        let timeout = Timespec { tv_sec: 2, tv_nsec: 0 };
        assert_eq!(poll(&mut fds, Some(&timeout)).unwrap(), 1, "a datagram within 2 s");
        if let Some(received) = receiver.recv_stamped_now().transpose() {
            return received.map(|(message, _, _)| message);
        }
    }
}

#[test]
fn a_thread_outside_the_runtime_waits_on_the_socket_and_receives_now() {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_io().build().unwrap();
    let robot = peer();
    let peer_filter = Peer::AnyPortOf(robot.local_addr().unwrap());
    let link = UdpLink::bind_in(runtime.handle(), "127.0.0.1:0".parse().unwrap(), peer_filter, Word).unwrap();
    let (mut sender, mut receiver) = link.into_split();
    let to = receiver.local_addr().unwrap();
    assert!(matches!(receiver.recv_stamped_now(), Ok(None)), "nothing waiting: no wait, no error");

    robot.send_to(&[1, 2, 3], to).unwrap();
    assert!(matches!(next_now(&mut receiver), Err(UdpError::Decode(BadLength(3)))));
    let spoofer = UdpSocket::bind("127.0.0.2:0").expect("127.0.0.2 is loopback on Linux");
    spoofer.send_to(&1u32.to_le_bytes(), to).unwrap();
    robot.send_to(&2u32.to_le_bytes(), to).unwrap();
    assert_eq!(next_now(&mut receiver).unwrap(), 2, "the spoofed 1 is dropped");
    assert!(matches!(receiver.recv_stamped_now(), Ok(None)));

    sender.send_now(&3).unwrap();
    let mut buf = [0u8; 8];
    let (n, from) = robot.recv_from(&mut buf).unwrap();
    assert_eq!((&buf[..n], from), (&3u32.to_le_bytes()[..], to));
    let stats = receiver.stats();
    assert_eq!((stats.received, stats.decode_errors, stats.foreign_dropped, stats.sent), (2, 1, 1, 1));
}
