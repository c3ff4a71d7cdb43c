//! The receiving half of a link.

use std::fmt;
use std::io;
use std::net::SocketAddr;
use std::os::fd::{AsFd, AsRawFd, BorrowedFd};
use std::sync::Arc;
use std::time::Duration;

use robowire_core::DatagramCodec;
use robowire_tap::{Direction, Tap};
use tokio::net::UdpSocket;

use super::{Destination, Peer, address_words, destination};
use crate::stats::Counters;
use crate::{LinkStats, UdpError};

/// The receiving half.
pub struct UdpReceiver<C> {
    pub(super) socket: Arc<UdpSocket>,
    pub(super) peer: Peer,
    pub(super) destination: Destination,
    pub(super) codec: C,
    pub(super) buf: Box<[u8]>,
    /// Room for the arrival stamp's control message.
    pub(super) control: Box<[u8]>,
    pub(super) counters: Arc<Counters>,
    pub(super) tap: Option<Tap>,
}

impl<C> fmt::Debug for UdpReceiver<C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("UdpReceiver").field("peer", &self.peer).finish_non_exhaustive()
    }
}

impl<C: DatagramCodec> UdpReceiver<C> {
    /// The next datagram from the peer, decoded. Datagrams the [`Peer`] does not accept are
    /// dropped and counted; one that does not decode is counted and returned as
    /// [`UdpError::Decode`], a socket error is counted and returned as [`UdpError::Io`] (the
    /// link stays usable after both).
    ///
    /// Cancel-safe: if the future is dropped before it completes, no datagram is lost.
    pub async fn recv(&mut self) -> Result<C::Incoming, UdpError<C::Error>> {
        self.recv_from().await.map(|(message, _)| message)
    }

    /// [`recv`](Self::recv), with the datagram's source.
    pub async fn recv_from(&mut self) -> Result<(C::Incoming, SocketAddr), UdpError<C::Error>> {
        loop {
            let (len, from) = match self.socket.recv_from(&mut self.buf).await {
                Ok(received) => received,
                Err(e) => {
                    Counters::bump(&self.counters.receive_errors);
                    return Err(e.into());
                }
            };
            if let Some(result) = self.accept(len, from) {
                return result.map(|message| (message, from));
            }
        }
    }

    /// Asks the kernel to stamp each datagram with its arrival time (`SO_TIMESTAMPNS`), for
    /// [`recv_stamped`](Self::recv_stamped): arrival as the network stack saw it, whatever the
    /// receiving thread's scheduling.
    pub fn enable_arrival_stamps(&self) -> io::Result<()> {
        nix::sys::socket::setsockopt(&*self.socket, nix::sys::socket::sockopt::ReceiveTimestampns, &true)
            .map_err(io::Error::from)
    }

    /// [`recv_from`](Self::recv_from) with the kernel's arrival stamp (`CLOCK_REALTIME`, since the
    /// Unix epoch), if [`enable_arrival_stamps`](Self::enable_arrival_stamps) was called.
    pub async fn recv_stamped(&mut self) -> Result<(C::Incoming, SocketAddr, Option<Duration>), UdpError<C::Error>> {
        loop {
            let socket = self.socket.clone();
            let (buf, control) = (&mut self.buf, &mut self.control);
            let received = socket
                .async_io(tokio::io::Interest::READABLE, || receive_stamped(socket.as_raw_fd(), buf, control))
                .await;
            if let Some(result) = self.received(received) {
                return result;
            }
        }
    }

    /// [`recv_stamped`](Self::recv_stamped) now, from any thread, without a runtime: non-blocking
    /// `recvmsg(2)` calls until a datagram the [`Peer`] accepts; `Ok(None)` when none is waiting.
    /// For stream threads that wait on the socket themselves (it is [`AsFd`]).
    #[expect(clippy::type_complexity, reason = "recv_stamped's result, maybe")]
    pub fn recv_stamped_now(
        &mut self,
    ) -> Result<Option<(C::Incoming, SocketAddr, Option<Duration>)>, UdpError<C::Error>> {
        loop {
            let received = receive_stamped(self.socket.as_raw_fd(), &mut self.buf, &mut self.control);
            if matches!(&received, Err(e) if e.kind() == io::ErrorKind::WouldBlock) {
                return Ok(None);
            }
            if let Some(result) = self.received(received) {
                return result.map(Some);
            }
        }
    }

    /// What one `recvmsg(2)` gave: `None` if the datagram is not returned (no source, or
    /// dropped by the peer filter), else the message or the error (counted).
    #[expect(clippy::type_complexity, reason = "the decoded message with its source and stamp, or the error")]
    fn received(
        &mut self,
        received: io::Result<(usize, Option<SocketAddr>, Option<Duration>)>,
    ) -> Option<Result<(C::Incoming, SocketAddr, Option<Duration>), UdpError<C::Error>>> {
        match received {
            Ok((len, Some(from), stamp)) => {
                self.accept(len, from).map(|result| result.map(|message| (message, from, stamp)))
            }
            Ok((_, None, _)) => None,
            Err(e) => {
                Counters::bump(&self.counters.receive_errors);
                Some(Err(e.into()))
            }
        }
    }

    /// A datagram of `len` bytes (in `buf`) from `from`: `None` if the peer filter drops it (counted),
    /// else the decoded message or the decode error (counted).
    fn accept(&mut self, len: usize, from: SocketAddr) -> Option<Result<C::Incoming, UdpError<C::Error>>> {
        if !self.peer.accepts(from) {
            Counters::bump(&self.counters.foreign_dropped);
            return None;
        }
        Counters::bump(&self.counters.received);
        if let Some(tap) = &self.tap {
            tap.record(Direction::Received, &self.buf[..len]);
        }
        Some(match self.codec.decode(&self.buf[..len]) {
            Ok(message) => {
                if self.peer.learns() {
                    // Only when it changed: the sender's read never retries on a steady peer.
                    if destination(&self.destination) != Some(from) {
                        self.destination.write(robowire_rt::now(), &address_words(from));
                    }
                }
                Ok(message)
            }
            Err(e) => {
                Counters::bump(&self.counters.decode_errors);
                Err(UdpError::Decode(e))
            }
        })
    }

    /// The address the socket is bound to.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// Whom this half accepts datagrams from.
    pub fn peer(&self) -> Peer {
        self.peer
    }

    /// The counters now.
    pub fn stats(&self) -> LinkStats {
        self.counters.snapshot()
    }

    /// Hands every datagram accepted from the peer from now on to `tap` (`None`: stop).
    pub fn set_tap(&mut self, tap: Option<Tap>) {
        self.tap = tap;
    }

    /// The codec, for codecs that keep state (to reset it after a timeout, say).
    pub fn codec_mut(&mut self) -> &mut C {
        &mut self.codec
    }
}

impl<C> AsFd for UdpReceiver<C> {
    fn as_fd(&self) -> BorrowedFd<'_> {
        self.socket.as_fd()
    }
}

/// One `recvmsg(2)` on `fd` into `buf` (control messages into `control`): the length, the
/// source, the kernel's arrival stamp if stamps are on.
fn receive_stamped(
    fd: std::os::fd::RawFd,
    buf: &mut [u8],
    control: &mut [u8],
) -> io::Result<(usize, Option<SocketAddr>, Option<Duration>)> {
    use nix::sys::socket::{ControlMessageOwned, MsgFlags, SockaddrStorage, recvmsg};
    let mut iov = [io::IoSliceMut::new(buf)];
    let msg = recvmsg::<SockaddrStorage>(fd, &mut iov, Some(control), MsgFlags::empty()).map_err(io::Error::from)?;
    let stamp = msg.cmsgs().ok().and_then(|mut c| {
        c.find_map(|m| match m {
            ControlMessageOwned::ScmTimestampns(ts) => {
                Some(Duration::new(u64::try_from(ts.tv_sec()).unwrap_or(0), u32::try_from(ts.tv_nsec()).unwrap_or(0)))
            }
            _ => None,
        })
    });
    let from = msg.address.and_then(|a: SockaddrStorage| {
        a.as_sockaddr_in()
            .map(|v4| SocketAddr::from((v4.ip(), v4.port())))
            .or_else(|| a.as_sockaddr_in6().map(|v6| SocketAddr::from((v6.ip(), v6.port()))))
    });
    Ok((msg.bytes, from, stamp))
}
