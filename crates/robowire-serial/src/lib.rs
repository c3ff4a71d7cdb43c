#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod pty;

use std::io;
use std::path::{Path, PathBuf};
use std::time::Duration;

use robowire_core::{Consumed, DecoderCounters, FrameBuffer, StreamDecoder};
use robowire_tap::{Direction, Tap};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio_serial::{DataBits, FlowControl, Parity, SerialPort, SerialStream, StopBits};

/// Serial line settings. Character format is always 8N1 (8 data bits, no parity, 1 stop bit).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SerialPortOptions {
    /// Baud rate, bit/s. Default 115200.
    pub baud_rate: u32,
    /// RTS/CTS hardware flow control. Default on.
    pub rts_cts_flow_control: bool,
    /// Assert RTS after opening and keep it asserted. Default on.
    ///
    /// Ports without modem-control lines (pseudo-terminals) refuse the request; that is
    /// reported in [`SerialLink::rts_asserted`], not as an error, because there is no line to
    /// drive.
    pub keep_rts_asserted: bool,
}

impl Default for SerialPortOptions {
    fn default() -> Self {
        Self { baud_rate: 115_200, rts_cts_flow_control: true, keep_rts_asserted: true }
    }
}

/// Reopen schedule after a disconnect: `initial`, doubling up to `max` between attempts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Backoff {
    /// Wait before the second attempt (the first is immediate).
    pub initial: Duration,
    /// Longest wait between attempts.
    pub max: Duration,
    /// Give up after this many attempts; `None` retries forever.
    pub max_attempts: Option<u32>,
}

impl Default for Backoff {
    fn default() -> Self {
        Self { initial: Duration::from_millis(50), max: Duration::from_secs(2), max_attempts: None }
    }
}

pub use pty::{Pty, PtyDevice};

/// Transport errors. "The bytes were bad" is not one: decoders skip and count those.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SerialError {
    /// The port could not be opened or configured.
    #[error("cannot open serial port {path}")]
    Open {
        /// Device path.
        path: PathBuf,
        /// Why.
        #[source]
        source: tokio_serial::Error,
    },
    /// The device went away: a read returned end-of-file or failed, or a write failed.
    /// The link stays unusable until [`SerialLink::reopen`] succeeds.
    #[error("serial port {path} disconnected")]
    Disconnected {
        /// Device path.
        path: PathBuf,
        /// The I/O error, if there was one (none for end-of-file).
        #[source]
        source: Option<io::Error>,
    },
    /// Reopening gave up after the backoff's `max_attempts`.
    #[error("gave up reopening serial port {path} after {attempts} attempts")]
    ReopenFailed {
        /// Device path.
        path: PathBuf,
        /// Attempts made.
        attempts: u32,
        /// The last attempt's error.
        #[source]
        last: tokio_serial::Error,
    },
}

/// What went over the link.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkCounters {
    /// The stream decoder's counters (frames, skipped bytes, rejected candidates).
    pub decoder: DecoderCounters,
    /// Bytes read from the port.
    pub bytes_read: u64,
    /// Bytes written to the port.
    pub bytes_written: u64,
    /// Frames written.
    pub frames_written: u64,
    /// Times the link was reopened after a disconnect.
    pub reopens: u64,
}

/// Where a link's traffic goes for a recorder: each frame written and read as it was on the
/// line, and the bytes the decoder skipped between frames (line noise, broken frames) as records
/// of their own.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SerialTaps {
    /// Frames written (sent) and decoded (received).
    pub frames: Option<Tap>,
    /// Bytes skipped by the decoder (received), one record per decoding step that skipped any.
    pub skipped: Option<Tap>,
}

impl SerialTaps {
    /// No tap at all.
    pub fn is_empty(&self) -> bool {
        self.frames.is_none() && self.skipped.is_none()
    }

    /// Records what one decoding step consumed: the bytes it skipped, then its frame.
    pub(crate) fn received(&self, consumed: Consumed<'_>) {
        if let (Some(tap), false) = (&self.skipped, consumed.skipped.is_empty()) {
            tap.record(Direction::Received, consumed.skipped);
        }
        if let (Some(tap), false) = (&self.frames, consumed.frame.is_empty()) {
            tap.record(Direction::Received, consumed.frame);
        }
    }

    /// Records a frame written.
    pub fn sent(&self, frame: &[u8]) {
        if let Some(tap) = &self.frames {
            tap.record(Direction::Sent, frame);
        }
    }
}

/// Receive buffer size: at least one frame of any robowire stream codec, plus room to read
/// ahead.
pub const RX_BUFFER_LEN: usize = 1024;

/// A serial port carrying frames of one stream protocol: whole-frame writes, decoded reads.
///
/// Generic over any [`StreamDecoder`] of `robowire-core`; it knows nothing about the device.
pub struct SerialLink<D: StreamDecoder> {
    port: Option<SerialStream>,
    /// A second handle on the open port, for [`SyncWriter`]s.
    native: Option<Box<dyn SerialPort>>,
    path: PathBuf,
    options: SerialPortOptions,
    rx: FrameBuffer<D, RX_BUFFER_LEN>,
    counters: LinkCounters,
    rts_asserted: bool,
    taps: SerialTaps,
}

impl<D: StreamDecoder> std::fmt::Debug for SerialLink<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SerialLink")
            .field("path", &self.path)
            .field("open", &self.port.is_some())
            .field("counters", &self.counters)
            .finish_non_exhaustive()
    }
}

impl<D: StreamDecoder> SerialLink<D> {
    /// Opens `path` with `options` and puts `decoder` on its receive side.
    /// Must be called inside a tokio runtime.
    pub fn open(path: impl AsRef<Path>, options: &SerialPortOptions, decoder: D) -> Result<Self, SerialError> {
        let path = path.as_ref().to_path_buf();
        let (port, native, rts_asserted) = open_port(&path, options)?;
        Ok(Self {
            port: Some(port),
            native: Some(native),
            path,
            options: options.clone(),
            rx: FrameBuffer::new(decoder),
            counters: LinkCounters::default(),
            rts_asserted,
            taps: SerialTaps::default(),
        })
    }

    /// Hands the link's traffic to `taps` from now on (its [`SyncWriter`]s made after this too).
    pub fn set_taps(&mut self, taps: SerialTaps) {
        self.taps = taps;
    }

    /// The device path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Is the port open (not disconnected)?
    pub fn is_open(&self) -> bool {
        self.port.is_some()
    }

    /// Was RTS asserted on the last open? `false` when not requested or when the port has no
    /// modem-control lines (a pseudo-terminal).
    pub fn rts_asserted(&self) -> bool {
        self.rts_asserted
    }

    /// Counters since the link was made (they survive reopening).
    pub fn counters(&self) -> LinkCounters {
        LinkCounters { decoder: self.rx.counters(), ..self.counters }
    }

    /// The decoder, to change its configuration.
    pub fn decoder_mut(&mut self) -> &mut D {
        self.rx.decoder_mut()
    }

    /// A handle for whole-frame writes from another thread, without a runtime (a stream
    /// thread that must never wait on an executor). It writes to the port as it is now: after a
    /// disconnect its writes fail, and a new one is needed after [`reopen`](Self::reopen).
    pub fn sync_writer(&self) -> Result<SyncWriter, SerialError> {
        let native =
            self.native.as_ref().ok_or_else(|| SerialError::Disconnected { path: self.path.clone(), source: None })?;
        let mut port = native.try_clone().map_err(|source| SerialError::Open { path: self.path.clone(), source })?;
        port.set_timeout(SYNC_WRITE_TIMEOUT).map_err(|source| SerialError::Open { path: self.path.clone(), source })?;
        Ok(SyncWriter {
            port,
            path: self.path.clone(),
            bytes_written: 0,
            frames_written: 0,
            tap: self.taps.frames.clone(),
        })
    }

    fn disconnected(&mut self, source: Option<io::Error>) -> SerialError {
        self.port = None;
        self.native = None;
        self.rx.clear();
        SerialError::Disconnected { path: self.path.clone(), source }
    }

    /// The next frame. Cancel-safe: dropping the future loses no bytes, so it can sit in a
    /// `select!` beside timers. A vanished device is [`SerialError::Disconnected`] at once
    /// (end-of-file and read errors both mean that on a serial port), never a busy loop.
    pub async fn recv(&mut self) -> Result<D::Frame, SerialError> {
        loop {
            let taps = &self.taps;
            let frame =
                if taps.is_empty() { self.rx.next_frame() } else { self.rx.next_frame_seen(|c| taps.received(c)) };
            if let Some(frame) = frame {
                return Ok(frame);
            }
            let Some(port) = self.port.as_mut() else { return Err(self.disconnected(None)) };
            match port.read(self.rx.spare_mut()).await {
                Ok(0) => return Err(self.disconnected(None)),
                Ok(n) => {
                    self.rx.commit(n);
                    self.counters.bytes_read += n as u64;
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(self.disconnected(Some(e))),
            }
        }
    }

    /// Writes one whole frame. Not cancel-safe (a cancelled write may leave half a frame on the
    /// line): await it to completion, outside `select!`.
    pub async fn send(&mut self, frame: &[u8]) -> Result<(), SerialError> {
        let Some(port) = self.port.as_mut() else { return Err(self.disconnected(None)) };
        let result = async {
            port.write_all(frame).await?;
            port.flush().await
        }
        .await;
        match result {
            Ok(()) => {
                self.counters.bytes_written += frame.len() as u64;
                self.counters.frames_written += 1;
                self.taps.sent(frame);
                Ok(())
            }
            Err(e) => Err(self.disconnected(Some(e))),
        }
    }

    /// Closes the port (if open) and opens the same path again, retrying on `backoff`.
    /// Bytes pending from before are dropped.
    pub async fn reopen(&mut self, backoff: &Backoff) -> Result<(), SerialError> {
        self.port = None;
        self.native = None;
        self.rx.clear();
        let mut delay = backoff.initial;
        let mut attempts = 0;
        loop {
            attempts += 1;
            match open_port(&self.path, &self.options) {
                Ok((port, native, rts)) => {
                    self.port = Some(port);
                    self.native = Some(native);
                    self.rts_asserted = rts;
                    self.counters.reopens += 1;
                    return Ok(());
                }
                Err(SerialError::Open { source, .. }) => {
                    if backoff.max_attempts.is_some_and(|max| attempts >= max) {
                        return Err(SerialError::ReopenFailed { path: self.path.clone(), attempts, last: source });
                    }
                }
                Err(other) => return Err(other),
            }
            tokio::time::sleep(delay).await;
            delay = (delay * 2).min(backoff.max);
        }
    }
}

/// How long a [`SyncWriter`] waits for room in the port's output buffer (a chassis holding CTS
/// down, say) before a write fails.
pub const SYNC_WRITE_TIMEOUT: Duration = Duration::from_millis(50);

/// Whole-frame writes to an open serial port from any thread, without a runtime; see
/// [`SerialLink::sync_writer`].
pub struct SyncWriter {
    port: Box<dyn SerialPort>,
    path: PathBuf,
    bytes_written: u64,
    frames_written: u64,
    tap: Option<Tap>,
}

impl std::fmt::Debug for SyncWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SyncWriter").field("path", &self.path).finish_non_exhaustive()
    }
}

impl SyncWriter {
    /// Writes one whole frame, waiting at most [`SYNC_WRITE_TIMEOUT`] for room. A failure means
    /// the port is gone (or blocked for good): [`SerialError::Disconnected`].
    pub fn send(&mut self, frame: &[u8]) -> Result<(), SerialError> {
        use std::io::Write;
        match self.port.write_all(frame) {
            Ok(()) => {
                self.bytes_written += frame.len() as u64;
                self.frames_written += 1;
                if let Some(tap) = &self.tap {
                    tap.record(Direction::Sent, frame);
                }
                Ok(())
            }
            Err(e) => Err(SerialError::Disconnected { path: self.path.clone(), source: Some(e) }),
        }
    }

    /// Bytes and frames this writer wrote.
    pub fn written(&self) -> (u64, u64) {
        (self.bytes_written, self.frames_written)
    }
}

/// Opens the port, 8N1, with the options' flow control; returns the async stream, a second
/// handle for synchronous writes, and whether RTS was asserted.
fn open_port(
    path: &Path,
    options: &SerialPortOptions,
) -> Result<(SerialStream, Box<dyn SerialPort>, bool), SerialError> {
    let open_error = |source| SerialError::Open { path: path.to_path_buf(), source };
    let flow = if options.rts_cts_flow_control { FlowControl::Hardware } else { FlowControl::None };
    let native = tokio_serial::new(path.to_string_lossy(), options.baud_rate)
        .data_bits(DataBits::Eight)
        .parity(Parity::None)
        .stop_bits(StopBits::One)
        .flow_control(flow)
        .open_native()
        .map_err(open_error)?;
    let writer = native.try_clone_native().map_err(open_error)?;
    let mut port = SerialStream::try_from(native).map_err(open_error)?;
    let rts_asserted = options.keep_rts_asserted && port.write_request_to_send(true).is_ok();
    Ok((port, Box::new(writer), rts_asserted))
}
