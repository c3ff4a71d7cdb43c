//! [`DatagramReplay`]: recorded datagrams played back to a live client over UDP. The device side
//! of `robowire-udp` ([`Peer::Any`]: it answers whoever spoke last) waits for the client's first
//! command, then the runner sends each frame on time.

use std::io;
use std::net::SocketAddr;
use std::time::Duration;

use robowire_core::DatagramCodec;
use robowire_udp::{Peer, UdpError, UdpLink, UdpReceiver, UdpSender};

use super::{Pace, ReplayError, ReplaySummary};

/// Recorded datagrams played back to a live client as the device, over UDP, with the device
/// side's codec (which decodes what the client sends, to count its commands).
///
/// ```
/// use std::net::UdpSocket;
/// use std::time::Duration;
/// use robowire_sim::replay::{DatagramReplay, Pace};
///
/// /// The device side of a protocol whose commands are any datagram (their length).
/// #[derive(Clone)]
/// struct AnyCommand;
/// impl robowire_core::DatagramCodec for AnyCommand {
///     type Outgoing = ();
///     type Incoming = usize;
///     type Error = std::convert::Infallible;
///     const MAX_DATAGRAM_LEN: usize = 64;
///     fn encode(&mut self, _: &(), _: &mut [u8]) -> Result<usize, Self::Error> {
///         Ok(0)
///     }
///     fn decode(&mut self, datagram: &[u8]) -> Result<usize, Self::Error> {
///         Ok(datagram.len())
///     }
/// }
///
/// # tokio::runtime::Builder::new_current_thread().enable_all().build()?.block_on(async {
/// let frames = [(Duration::ZERO, b"first".to_vec()), (Duration::from_millis(2), b"second".to_vec())];
/// let mut device = DatagramReplay::bind("127.0.0.1:0".parse()?, AnyCommand, frames).await?;
/// let client = UdpSocket::bind("127.0.0.1:0")?;
/// client.send_to(b"hello", device.local_addr()?)?;
/// assert_eq!(device.first_command().await?, client.local_addr()?);
/// let summary = device.play(Pace::Recorded { speed: 1.0 }).await?;
/// assert_eq!((summary.frames, summary.sent, summary.commands), (2, 2, 1));
/// let mut buf = [0u8; 16];
/// let n = client.recv(&mut buf)?;
/// assert_eq!(&buf[..n], b"first");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// # })?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct DatagramReplay<C> {
    sender: UdpSender<C>,
    receiver: UdpReceiver<C>,
    /// Offset from the first frame, bytes.
    frames: Vec<(Duration, Vec<u8>)>,
    commands: u64,
    invalid: u64,
}

impl<C> DatagramReplay<C>
where
    C: DatagramCodec + Clone + Send + 'static,
{
    /// Binds `addr` with the device side's `codec`, to play `frames` (each: its offset from the
    /// first frame, its bytes, in the order to send them).
    pub async fn bind(
        addr: SocketAddr,
        codec: C,
        frames: impl IntoIterator<Item = (Duration, Vec<u8>)>,
    ) -> Result<Self, UdpError<C::Error>> {
        let (sender, receiver) = UdpLink::bind(addr, Peer::Any { reply_to: None }, codec).await?.into_split();
        Ok(Self { sender, receiver, frames: frames.into_iter().collect(), commands: 0, invalid: 0 })
    }

    /// The address the device is bound to.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.sender.local_addr()
    }

    /// Frames to play.
    pub fn frames(&self) -> usize {
        self.frames.len()
    }

    /// Waits for the client's first command: where it came from (the frames go there). A
    /// datagram that is no command is an error (counted): call again to go on waiting.
    pub async fn first_command(&mut self) -> Result<SocketAddr, UdpError<C::Error>> {
        match self.receiver.recv_from().await {
            Ok((_, from)) => {
                self.commands += 1;
                Ok(from)
            }
            Err(e) => {
                self.invalid += u64::from(matches!(e, UdpError::Decode(_)));
                Err(e)
            }
        }
    }

    /// Plays every frame to the client on robowire's runner at `pace`, counting the client's
    /// commands meanwhile; returns once the last frame is sent.
    pub async fn play(self, pace: Pace) -> Result<ReplaySummary, ReplayError> {
        let Self { mut sender, mut receiver, frames, mut commands, mut invalid } = self;
        let client = sender.destination();
        let count = frames.len();
        let runner = super::spawn_playback(frames, pace, move |bytes| sender.send_bytes_now(bytes).is_ok())?;
        let mut done = tokio::task::spawn_blocking(move || runner.join());
        let mut listening = true;
        let played = loop {
            tokio::select! {
                played = &mut done => break played.ok().flatten().ok_or(ReplayError::Lost)?,
                received = receiver.recv(), if listening => match received {
                    Ok(_) => commands += 1,
                    Err(UdpError::Decode(_)) => invalid += 1,
                    // The socket failed: the frames still go out; nothing more is counted.
                    Err(_) => listening = false,
                },
            }
        };
        Ok(ReplaySummary { frames: count, sent: played.sent, commands, invalid, client })
    }
}
