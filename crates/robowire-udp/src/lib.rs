#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

use std::fmt;
use std::io;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use robowire_core::DatagramCodec;
use tokio::net::UdpSocket;

/// What went wrong on a link. `E` is the codec's error.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum UdpError<E> {
    /// The socket could not be bound.
    #[error("cannot bind UDP {addr}: {source}; this host's IPv4 addresses: {}", HostAddresses(.host_ipv4))]
    Bind {
        /// The address asked for.
        addr: SocketAddr,
        /// Why.
        source: io::Error,
        /// The host's IPv4 addresses, to pick a `local_ip` from.
        host_ipv4: Vec<Ipv4Addr>,
    },
    /// A socket error while sending or receiving.
    #[error("UDP I/O: {0}")]
    Io(#[from] io::Error),
    /// The message could not be encoded.
    #[error("cannot encode: {0}")]
    Encode(E),
    /// A datagram from the peer could not be decoded (it is counted and dropped).
    #[error("datagram from the peer does not decode: {0}")]
    Decode(E),
}

struct HostAddresses<'a>(&'a [Ipv4Addr]);

impl fmt::Display for HostAddresses<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str("none found");
        }
        for (i, ip) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{ip}")?;
        }
        Ok(())
    }
}

/// The host's IPv4 addresses (loopback included), or none if the interfaces cannot be listed.
pub fn host_ipv4_addresses() -> Vec<Ipv4Addr> {
    let mut ips: Vec<Ipv4Addr> = if_addrs::get_if_addrs()
        .map(|ifs| {
            ifs.into_iter()
                .filter_map(|i| match i.ip() {
                    IpAddr::V4(v4) => Some(v4),
                    IpAddr::V6(_) => None,
                })
                .collect()
        })
        .unwrap_or_default();
    ips.sort();
    ips.dedup();
    ips
}

/// Counters of one link, since it was bound.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Datagrams sent.
    pub sent: u64,
    /// Sends that failed (the message was not sent).
    pub send_errors: u64,
    /// Datagrams received from the peer's IP (decode errors included).
    pub received: u64,
    /// Datagrams from the peer that did not decode.
    pub decode_errors: u64,
    /// Datagrams from any other IP: dropped, never decoded.
    pub foreign_dropped: u64,
}

#[derive(Debug, Default)]
struct Counters {
    sent: AtomicU64,
    send_errors: AtomicU64,
    received: AtomicU64,
    decode_errors: AtomicU64,
    foreign_dropped: AtomicU64,
}

impl Counters {
    fn bump(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    fn snapshot(&self) -> LinkStats {
        LinkStats {
            sent: self.sent.load(Ordering::Relaxed),
            send_errors: self.send_errors.load(Ordering::Relaxed),
            received: self.received.load(Ordering::Relaxed),
            decode_errors: self.decode_errors.load(Ordering::Relaxed),
            foreign_dropped: self.foreign_dropped.load(Ordering::Relaxed),
        }
    }
}

/// A read-only view of a link's counters, cheap to clone and to read from any thread.
#[derive(Debug, Clone)]
pub struct StatsHandle(Arc<Counters>);

impl StatsHandle {
    /// The counters now.
    pub fn get(&self) -> LinkStats {
        self.0.snapshot()
    }
}

/// A UDP socket bound to a local address, talking to one peer through codec `C`.
pub struct UdpLink<C> {
    sender: UdpSender<C>,
    receiver: UdpReceiver<C>,
}

impl<C> fmt::Debug for UdpLink<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UdpLink")
            .field("local", &self.receiver.socket.local_addr().ok())
            .field("peer", &self.sender.peer)
            .field("stats", &self.sender.counters.snapshot())
            .finish()
    }
}

impl<C: DatagramCodec + Clone> UdpLink<C> {
    /// Binds `local` (no `SO_REUSEADDR`: a second client on the same port fails, as with the
    /// vendor SDKs) and sends to `peer`; only datagrams from `peer`'s IP are accepted.
    pub async fn bind(local: SocketAddr, peer: SocketAddr, codec: C) -> Result<Self, UdpError<C::Error>> {
        let socket = UdpSocket::bind(local).await.map_err(|source| UdpError::Bind {
            addr: local,
            source,
            host_ipv4: host_ipv4_addresses(),
        })?;
        let socket = Arc::new(socket);
        let counters = Arc::new(Counters::default());
        let sender = UdpSender {
            socket: socket.clone(),
            peer,
            codec: codec.clone(),
            buf: vec![0; C::MAX_DATAGRAM_LEN].into_boxed_slice(),
            counters: counters.clone(),
        };
        // One byte more than the longest datagram, so that an over-long one is seen as such
        // by the codec instead of being silently truncated by the kernel.
        let receiver = UdpReceiver {
            socket,
            peer_ip: peer.ip(),
            codec,
            buf: vec![0; C::MAX_DATAGRAM_LEN + 1].into_boxed_slice(),
            counters,
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

    /// Where messages go.
    pub fn peer(&self) -> SocketAddr {
        self.sender.peer
    }

    /// The counters now.
    pub fn stats(&self) -> LinkStats {
        self.sender.counters.snapshot()
    }

    /// A handle to the counters that outlives the link's halves.
    pub fn stats_handle(&self) -> StatsHandle {
        StatsHandle(self.sender.counters.clone())
    }

    /// A sender and a receiver that can live in different tasks (same socket, same counters).
    pub fn into_split(self) -> (UdpSender<C>, UdpReceiver<C>) {
        (self.sender, self.receiver)
    }
}

/// The sending half: encodes into its own buffer, no allocation per message.
pub struct UdpSender<C> {
    socket: Arc<UdpSocket>,
    peer: SocketAddr,
    codec: C,
    buf: Box<[u8]>,
    counters: Arc<Counters>,
}

impl<C> fmt::Debug for UdpSender<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UdpSender").field("peer", &self.peer).finish_non_exhaustive()
    }
}

impl<C: DatagramCodec> UdpSender<C> {
    /// Encodes `message` and sends it to the peer.
    pub async fn send(&mut self, message: &C::Outgoing) -> Result<(), UdpError<C::Error>> {
        let len = self.codec.encode(message, &mut self.buf).map_err(UdpError::Encode)?;
        match self.socket.send_to(&self.buf[..len], self.peer).await {
            Ok(_) => {
                Counters::bump(&self.counters.sent);
                Ok(())
            }
            Err(e) => {
                Counters::bump(&self.counters.send_errors);
                Err(e.into())
            }
        }
    }

    /// Where messages go.
    pub fn peer(&self) -> SocketAddr {
        self.peer
    }
}

/// The receiving half.
pub struct UdpReceiver<C> {
    socket: Arc<UdpSocket>,
    peer_ip: IpAddr,
    codec: C,
    buf: Box<[u8]>,
    counters: Arc<Counters>,
}

impl<C> fmt::Debug for UdpReceiver<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UdpReceiver").field("peer_ip", &self.peer_ip).finish_non_exhaustive()
    }
}

impl<C: DatagramCodec> UdpReceiver<C> {
    /// The next datagram from the peer's IP, decoded. Datagrams from other IPs are dropped and
    /// counted; a datagram that does not decode is counted and returned as
    /// [`UdpError::Decode`] (the link stays usable).
    ///
    /// Cancel-safe: if the future is dropped before it completes, no datagram is lost.
    pub async fn recv(&mut self) -> Result<C::Incoming, UdpError<C::Error>> {
        loop {
            let (len, from) = self.socket.recv_from(&mut self.buf).await?;
            if from.ip() != self.peer_ip {
                Counters::bump(&self.counters.foreign_dropped);
                continue;
            }
            Counters::bump(&self.counters.received);
            return self.codec.decode(&self.buf[..len]).map_err(|e| {
                Counters::bump(&self.counters.decode_errors);
                UdpError::Decode(e)
            });
        }
    }

    /// The address the socket is bound to.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// The counters now.
    pub fn stats(&self) -> LinkStats {
        self.counters.snapshot()
    }

    /// The codec, for codecs that keep state (to reset it after a timeout, say).
    pub fn codec_mut(&mut self) -> &mut C {
        &mut self.codec
    }
}
