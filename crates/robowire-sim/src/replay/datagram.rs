//! [`DatagramReplay`]: a device that plays recorded datagrams back, byte for byte, to a live
//! client over UDP (`robowire replay --as-device`), so that a session seen once on a robot can be
//! replayed on a desk. It knows no recorder and no device: it takes the frames as offsets from
//! the first and bytes, a bind address and the device side's codec (which decodes what the client
//! sends, to count its commands).
//!
//! The device side of `robowire-udp` ([`Peer::Any`]: it answers whoever spoke last) waits for the
//! client's first command, then robowire's runner sends each frame on time, at the recorded pace
//! scaled by a speed, or as fast as it can ([`Pace`]).
//!
//! ```
//! use std::net::UdpSocket;
//! use std::time::Duration;
//! use robowire_sim::replay::{DatagramReplay, Pace};
//!
//! /// The device side of a protocol whose commands are any datagram (their length).
//! #[derive(Clone)]
//! struct AnyCommand;
//! impl robowire_core::DatagramCodec for AnyCommand {
//!     type Outgoing = ();
//!     type Incoming = usize;
//!     type Error = std::convert::Infallible;
//!     const MAX_DATAGRAM_LEN: usize = 64;
//!     fn encode(&mut self, _: &(), _: &mut [u8]) -> Result<usize, Self::Error> {
//!         Ok(0)
//!     }
//!     fn decode(&mut self, datagram: &[u8]) -> Result<usize, Self::Error> {
//!         Ok(datagram.len())
//!     }
//! }
//!
//! # tokio::runtime::Builder::new_current_thread().enable_all().build()?.block_on(async {
//! let frames = [(Duration::ZERO, b"first".to_vec()), (Duration::from_millis(2), b"second".to_vec())];
//! let mut device = DatagramReplay::bind("127.0.0.1:0".parse()?, AnyCommand, frames).await?;
//! let client = UdpSocket::bind("127.0.0.1:0")?;
//! client.send_to(b"hello", device.local_addr()?)?;
//! assert_eq!(device.first_command().await?, client.local_addr()?);
//! let summary = device.play(Pace::Recorded { speed: 1.0 }).await?;
//! assert_eq!((summary.frames, summary.sent, summary.commands), (2, 2, 1));
//! let mut buf = [0u8; 16];
//! let n = client.recv(&mut buf)?;
//! assert_eq!(&buf[..n], b"first");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::io;
use std::net::SocketAddr;
use std::time::Duration;

use robowire_core::DatagramCodec;
use robowire_core::schedule::Time;
use robowire_rt::runner::{Job, Runner, RunnerOptions};
use robowire_udp::{Peer, UdpError, UdpLink, UdpReceiver, UdpSender};

/// How fast to play.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pace {
    /// At the recorded offsets divided by `speed` (2: twice as fast as recorded).
    Recorded {
        /// Finite, above 0.
        speed: f64,
    },
    /// Every frame at once, one after the other.
    Fast,
}

/// What a playback did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReplaySummary {
    /// Frames to play.
    pub frames: usize,
    /// Frames sent (the others failed at the socket, or had no client to go to).
    pub sent: u64,
    /// The client's valid commands, the first one included.
    pub commands: u64,
    /// Datagrams from the client that did not decode as commands.
    pub invalid: u64,
    /// Where the frames went when the playback began.
    pub client: Option<SocketAddr>,
}

/// Why a playback could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// [`Pace::Recorded`] with a speed that is not finite and above 0.
    #[error("the speed must be finite and above 0, got {0}")]
    Speed(f64),
    /// The player's thread could not start.
    #[error("cannot start the player's thread")]
    Thread(#[from] robowire_rt::RtError),
    /// The player's thread ended without a result (it panicked).
    #[error("the player's thread ended without a result")]
    Lost,
}

/// Recorded datagrams played back to a live client as the device; see the [module](self).
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
        let Self { sender, mut receiver, frames, mut commands, mut invalid } = self;
        let speed = match pace {
            Pace::Recorded { speed } if speed.is_finite() && speed > 0.0 => Some(speed),
            Pace::Recorded { speed } => return Err(ReplayError::Speed(speed)),
            Pace::Fast => None,
        };
        let client = sender.destination();
        let count = frames.len();
        let start = robowire_rt::now();
        let due = |offset: Duration| match speed {
            Some(speed) => start + Duration::try_from_secs_f64(offset.as_secs_f64() / speed).unwrap_or(Duration::MAX),
            // In the past: at once.
            None => Time::ZERO,
        };
        let frames = frames.into_iter().map(|(offset, bytes)| (due(offset), bytes)).collect();
        let runner = Runner::spawn(RunnerOptions::named("replay"), Playback { sender, frames, next: 0, sent: 0 })?;
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

/// The frames on the runner: each sent at its due time.
struct Playback<C> {
    sender: UdpSender<C>,
    /// When each is due, its bytes.
    frames: Vec<(Time, Vec<u8>)>,
    next: usize,
    sent: u64,
}

impl<C: DatagramCodec + Send + 'static> Job for Playback<C> {
    fn next_run(&mut self) -> Option<Time> {
        self.frames.get(self.next).map(|(due, _)| *due)
    }

    fn run(&mut self, now: Time) {
        while let Some((due, bytes)) = self.frames.get(self.next)
            && *due <= now
        {
            self.sent += u64::from(self.sender.send_bytes_now(bytes).is_ok());
            self.next += 1;
        }
    }
}
