//! A socket, a peer and a codec: typed datagrams both ways.

mod receiver;

use std::fmt;
use std::io;
use std::net::SocketAddr;
use std::sync::Arc;

use robowire_core::DatagramCodec;
use robowire_rt::Latest;
use robowire_tap::{Direction, Tap};
use tokio::net::UdpSocket;

use crate::stats::{Counters, StatsHandle};
use crate::{LinkStats, UdpError, host_ipv4_addresses};
pub use receiver::UdpReceiver;

/// Whom a link talks to, and whom it accepts datagrams from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Peer {
    /// Send to this address; accept datagrams only from it, IP and port.
    Exact(SocketAddr),
    /// Send to this address; accept datagrams from any port of its IP. For devices whose
    /// sending port is not documented (the ZSL-1 sends state from a port of its own choosing).
    AnyPortOf(SocketAddr),
    /// The device side of a protocol: accept datagrams from anyone; send to `reply_to`, or, if
    /// `None`, to the source of the latest datagram that decoded.
    Any {
        /// A fixed destination, if the device is configured with one.
        reply_to: Option<SocketAddr>,
    },
}

impl Peer {
    /// Whether a datagram from `from` is accepted.
    fn accepts(&self, from: SocketAddr) -> bool {
        match self {
            Self::Exact(addr) => from == *addr,
            Self::AnyPortOf(addr) => from.ip() == addr.ip(),
            Self::Any { .. } => true,
        }
    }

    /// Where messages go before anything was received.
    fn initial_destination(&self) -> Option<SocketAddr> {
        match *self {
            Self::Exact(addr) | Self::AnyPortOf(addr) => Some(addr),
            Self::Any { reply_to } => reply_to,
        }
    }

    /// Whether the destination follows the sources of what arrives.
    fn learns(&self) -> bool {
        matches!(self, Self::Any { reply_to: None })
    }
}

/// The destination, shared by both halves: learned by the receiver on a [`Peer::Any`] link, read
/// by the sender without a lock (a seqlock: the sender may be a stream thread).
type Destination = Arc<Latest<[u32; 7]>>;

/// A socket address as seven words: family and port, the IP (v4 in the first word), v6 flow
/// info and scope.
fn address_words(addr: SocketAddr) -> [u32; 7] {
    match addr {
        SocketAddr::V4(v4) => [4 << 16 | u32::from(v4.port()), u32::from(*v4.ip()), 0, 0, 0, 0, 0],
        SocketAddr::V6(v6) => {
            let ip = v6.ip().to_bits();
            let word = |i: u32| (ip >> (96 - 32 * i)) as u32;
            [6 << 16 | u32::from(v6.port()), word(0), word(1), word(2), word(3), v6.flowinfo(), v6.scope_id()]
        }
    }
}

fn words_address(w: [u32; 7]) -> Option<SocketAddr> {
    let port = (w[0] & 0xffff) as u16;
    match w[0] >> 16 {
        4 => Some(SocketAddr::new(std::net::Ipv4Addr::from(w[1]).into(), port)),
        6 => {
            let ip = w[1..5].iter().fold(0u128, |ip, &word| ip << 32 | u128::from(word));
            Some(SocketAddr::V6(std::net::SocketAddrV6::new(std::net::Ipv6Addr::from_bits(ip), port, w[5], w[6])))
        }
        _ => None,
    }
}

fn new_destination(initial: Option<SocketAddr>) -> Destination {
    let shared = Arc::new(Latest::new());
    if let Some(addr) = initial {
        shared.write(robowire_rt::now(), &address_words(addr));
    }
    shared
}

fn destination(shared: &Destination) -> Option<SocketAddr> {
    shared.read().and_then(|(_, words)| words_address(words))
}

/// A UDP socket bound to a local address, talking to a [`Peer`] through codec `C`.
pub struct UdpLink<C> {
    sender: UdpSender<C>,
    receiver: UdpReceiver<C>,
}

impl<C> fmt::Debug for UdpLink<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UdpLink")
            .field("local", &self.receiver.socket.local_addr().ok())
            .field("peer", &self.receiver.peer)
            .field("stats", &self.sender.counters.snapshot())
            .finish()
    }
}

impl<C: DatagramCodec + Clone> UdpLink<C> {
    /// Binds `local` (no `SO_REUSEADDR`: a second client on the same port fails, as with the
    /// vendor SDKs) and talks to `peer`. Must be called inside a tokio runtime.
    pub async fn bind(local: SocketAddr, peer: Peer, codec: C) -> Result<Self, UdpError<C::Error>> {
        Self::bind_registered(local, peer, codec)
    }

    /// [`bind`](Self::bind) from any thread, inside a runtime or not: the socket is registered
    /// with `runtime`, whose reactor serves the async calls. Links used only through the `_now`
    /// calls need no more of it than that it outlives them.
    pub fn bind_in(
        runtime: &tokio::runtime::Handle,
        local: SocketAddr,
        peer: Peer,
        codec: C,
    ) -> Result<Self, UdpError<C::Error>> {
        let _context = runtime.enter();
        Self::bind_registered(local, peer, codec)
    }

    /// Binds with the socket registered with the runtime of the calling context.
    fn bind_registered(local: SocketAddr, peer: Peer, codec: C) -> Result<Self, UdpError<C::Error>> {
        let bind_error = |source| UdpError::Bind { addr: local, source, host_ipv4: host_ipv4_addresses() };
        let std_socket = std::net::UdpSocket::bind(local).map_err(bind_error)?;
        std_socket.set_nonblocking(true)?;
        // A second handle on the same socket, for sends from threads outside the runtime.
        let sync_socket = std_socket.try_clone()?;
        let socket = Arc::new(UdpSocket::from_std(std_socket)?);
        let counters = Arc::new(Counters::default());
        let destination = new_destination(peer.initial_destination());
        let sender = UdpSender {
            socket: socket.clone(),
            sync_socket,
            destination: destination.clone(),
            codec: codec.clone(),
            buf: vec![0; C::MAX_DATAGRAM_LEN].into_boxed_slice(),
            counters: counters.clone(),
            tap: None,
        };
        // One byte more than the longest datagram, so that an over-long one is seen as such
        // by the codec instead of being silently truncated by the kernel.
        let receiver = UdpReceiver {
            socket,
            peer,
            destination,
            codec,
            buf: vec![0; C::MAX_DATAGRAM_LEN + 1].into_boxed_slice(),
            control: nix::cmsg_space!(nix::sys::time::TimeSpec).into_boxed_slice(),
            counters,
            tap: None,
        };
        Ok(Self { sender, receiver })
    }
}

impl<C: DatagramCodec> UdpLink<C> {
    /// Encodes `message` and sends it to the peer.
    pub async fn send(&mut self, message: &C::Outgoing) -> Result<(), UdpError<C::Error>> {
        self.sender.send(message).await
    }

    /// The next message from the peer (see [`UdpReceiver::recv`]).
    pub async fn recv(&mut self) -> Result<C::Incoming, UdpError<C::Error>> {
        self.receiver.recv().await
    }

    /// The address the socket is bound to.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.receiver.socket.local_addr()
    }

    /// Where messages go now (`None` on a [`Peer::Any`] link that has heard nobody yet).
    pub fn destination(&self) -> Option<SocketAddr> {
        self.sender.destination()
    }

    /// The counters now.
    pub fn stats(&self) -> LinkStats {
        self.sender.counters.snapshot()
    }

    /// Hands every datagram sent and accepted from now on to `tap` (`None`: stop); the frames
    /// carry their direction.
    pub fn set_tap(&mut self, tap: Option<Tap>) {
        self.sender.set_tap(tap.clone());
        self.receiver.set_tap(tap);
    }

    /// A handle to the counters that outlives the link's halves.
    pub fn stats_handle(&self) -> StatsHandle {
        StatsHandle(self.sender.counters.clone())
    }

    /// A sender and a receiver that can live in different tasks (or threads: the sender's
    /// [`send_now`](UdpSender::send_now) needs no runtime). Same socket, same counters.
    pub fn into_split(self) -> (UdpSender<C>, UdpReceiver<C>) {
        (self.sender, self.receiver)
    }
}

/// The sending half: encodes into its own buffer, no allocation per message.
pub struct UdpSender<C> {
    socket: Arc<UdpSocket>,
    sync_socket: std::net::UdpSocket,
    destination: Destination,
    codec: C,
    buf: Box<[u8]>,
    counters: Arc<Counters>,
    tap: Option<Tap>,
}

impl<C> fmt::Debug for UdpSender<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UdpSender").field("destination", &destination(&self.destination)).finish_non_exhaustive()
    }
}

impl<C: DatagramCodec> UdpSender<C> {
    /// A send that failed before reaching the socket: counted, returned.
    fn refused(&self, error: UdpError<C::Error>) -> UdpError<C::Error> {
        Counters::bump(&self.counters.send_errors);
        error
    }

    fn encode(&mut self, message: &C::Outgoing) -> Result<(usize, SocketAddr), UdpError<C::Error>> {
        let to = self.destination().ok_or_else(|| self.refused(UdpError::NoPeer))?;
        match self.codec.encode(message, &mut self.buf) {
            Ok(len) => Ok((len, to)),
            Err(e) => Err(self.refused(UdpError::Encode(e))),
        }
    }

    /// Counts a send of `len` bytes of `buf` (or of `bytes`), and hands them to the tap.
    fn count(&self, result: io::Result<usize>, sent: &[u8]) -> Result<(), UdpError<C::Error>> {
        match result {
            Ok(_) => {
                Counters::bump(&self.counters.sent);
                if let Some(tap) = &self.tap {
                    tap.record(Direction::Sent, sent);
                }
                Ok(())
            }
            Err(e) => {
                Counters::bump(&self.counters.send_errors);
                Err(e.into())
            }
        }
    }

    /// Encodes `message` and sends it to the peer.
    pub async fn send(&mut self, message: &C::Outgoing) -> Result<(), UdpError<C::Error>> {
        let (len, to) = self.encode(message)?;
        let result = self.socket.send_to(&self.buf[..len], to).await;
        self.count(result, &self.buf[..len])
    }

    /// Encodes `message` and sends it now, from any thread, without a runtime: one
    /// non-blocking `sendto(2)`. A full socket buffer is an error ([`io::ErrorKind::WouldBlock`],
    /// counted), never a wait. For stream threads that must not block.
    pub fn send_now(&mut self, message: &C::Outgoing) -> Result<(), UdpError<C::Error>> {
        let (len, to) = self.encode(message)?;
        let result = self.sync_socket.send_to(&self.buf[..len], to);
        self.count(result, &self.buf[..len])
    }

    /// The address the socket is bound to.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// Sends `bytes` as they are, bypassing the codec, now (like [`send_now`](Self::send_now)):
    /// for fault injection (junk on the wire), never for messages.
    pub fn send_bytes_now(&mut self, bytes: &[u8]) -> Result<(), UdpError<C::Error>> {
        let to = self.destination().ok_or_else(|| self.refused(UdpError::NoPeer))?;
        let result = self.sync_socket.send_to(bytes, to);
        self.count(result, bytes)
    }

    /// Where messages go now (`None` on a [`Peer::Any`] link that has heard nobody yet).
    pub fn destination(&self) -> Option<SocketAddr> {
        destination(&self.destination)
    }

    /// Hands every datagram sent from now on to `tap` (`None`: stop).
    pub fn set_tap(&mut self, tap: Option<Tap>) {
        self.tap = tap;
    }

    /// The counters now.
    pub fn stats(&self) -> LinkStats {
        self.counters.snapshot()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_cross_the_seqlock_whole() {
        for text in ["127.0.0.1:43988", "[::1]:7", "[fe80::1%3]:65535", "0.0.0.0:0"] {
            let addr: SocketAddr = text.parse().unwrap();
            assert_eq!(words_address(address_words(addr)), Some(addr), "{text}");
        }
        let shared = new_destination(None);
        assert_eq!(destination(&shared), None);
        shared.write(robowire_rt::now(), &address_words("10.0.0.2:9".parse().unwrap()));
        assert_eq!(destination(&shared), Some("10.0.0.2:9".parse().unwrap()));
    }
}
