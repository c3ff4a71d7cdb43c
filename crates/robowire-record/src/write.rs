//! The recorder: a thread that writes the taps' frames into an MCAP file.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use mcap::records::{MessageHeader, Metadata};
use robowire_core::json::LinkDescription;
use robowire_tap::{LinkRegistry, RecordLinks, Tap, TapRing, TappedFrame};

use crate::channels::{Channels, Placed};
use crate::json_thread::{JsonMessage, JsonThread};

/// How long the writer sleeps when the ring is empty: at 1 M frames/s, 1 000 frames arrive
/// meanwhile (a sixteenth of the default ring).
const POLL: Duration = Duration::from_millis(1);

/// How a recorder is set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecorderOptions {
    /// Slots of the taps' ring, each [`robowire_tap::SLOT_BYTES`] (the default 16384: about 38 MB,
    /// 16 ms of 1 M frames/s, or 16 s of a 500 Hz link both ways, for the writer to fall behind by
    /// before frames are dropped: enough for the page cache's stalls of the writer at 1 M frames/s).
    pub ring_slots: usize,
    /// Writes each frame's JSON message beside its raw bytes (default on); off, a capture has the
    /// raw channels only, and `robowire decode --mcap` reads them.
    pub json: bool,
    /// How the file's chunks are compressed (default none: the writer's thread does nothing
    /// more per byte than copy it).
    pub compression: Compression,
    /// The MCAP profile in the file's header: `""` (default), or `"ros2"` for a capture of ROS 2
    /// topics that `ros2 bag` plays.
    pub profile: &'static str,
    /// Writes only frames in a wire encoding (a ROS 2 capture that ROS 2 tools read whole); the
    /// others are counted ([`RecordingSummary::not_wire`]), not written. Default off.
    pub wire_only: bool,
}

impl Default for RecorderOptions {
    fn default() -> Self {
        Self { ring_slots: 16_384, json: true, compression: Compression::None, profile: "", wire_only: false }
    }
}

/// Chunk compression of a capture: every MCAP reader reads all three. On the demo's capture
/// zstd makes it about 12 times smaller.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[non_exhaustive]
pub enum Compression {
    /// Uncompressed chunks.
    #[default]
    None,
    /// Zstandard, level 1 (`mcap`'s default level).
    Zstd,
    /// LZ4 frames.
    Lz4,
}

impl Compression {
    fn mcap(self) -> Option<mcap::Compression> {
        match self {
            Self::None => None,
            Self::Zstd => Some(mcap::Compression::Zstd),
            Self::Lz4 => Some(mcap::Compression::Lz4),
        }
    }
}

/// Why a capture could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RecordError {
    /// The file could not be created.
    #[error("cannot create {path}: {source}")]
    Create {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The MCAP writer failed (disk full, say).
    #[error("writing {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: mcap::McapError,
    },
    /// The writer thread died.
    #[error("the recorder's thread panicked")]
    Thread,
}

/// What a finished capture holds.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RecordingSummary {
    /// Frames written, raw (or in their wire encoding).
    pub frames: u64,
    /// Frames the taps dropped because the ring was full (the writer fell behind).
    pub dropped: u64,
    /// Frames the taps dropped because they were longer than a slot.
    pub oversize: u64,
    /// Frames whose decoding for the JSON channel failed (their raw frame is still written).
    pub decode_errors: u64,
    /// Frames whose JSON message was skipped because the JSON thread fell behind (their raw frame
    /// is written; `robowire decode --mcap` decodes it).
    pub json_skipped: u64,
    /// Frames not written because they were not in a wire encoding, with
    /// [`RecorderOptions::wire_only`].
    pub not_wire: u64,
}

/// Records taps into one MCAP file.
///
/// The taps stamp frames with the monotonic clock; the writer logs them at Unix time, through
/// the offset between the two clocks taken once when the recorder is created (a step of the wall
/// clock while recording does not move the frames' times). The writer thread writes each frame
/// as it was on the wire; a second thread decodes the frames into JSON, so that decoding never
/// holds the raw frames back.
#[derive(Debug)]
pub struct Recorder {
    ring: TapRing,
    links: LinkRegistry,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<RecordingSummary, RecordError>>>,
}

impl Recorder {
    /// Creates `path` and starts the writer thread, with the default options. `command` is what
    /// is recording (for the metadata: `robowire dog … --record`).
    pub fn create(path: impl AsRef<Path>, command: &str) -> Result<Self, RecordError> {
        Self::create_with(path, command, RecorderOptions::default())
    }

    /// As [`create`](Self::create), with `options`.
    pub fn create_with(path: impl AsRef<Path>, command: &str, options: RecorderOptions) -> Result<Self, RecordError> {
        let path = path.as_ref().to_path_buf();
        let file = File::create(&path).map_err(|source| RecordError::Create { path: path.clone(), source })?;
        let writer = mcap::WriteOptions::new()
            .compression(options.compression.mcap())
            .profile(options.profile)
            .library(concat!("robowire ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::with_capacity(1 << 20, file))
            .map_err(|source| RecordError::Write { path: path.clone(), source })?;
        let ring = TapRing::with_slots(options.ring_slots);
        let json = options
            .json
            .then(|| JsonThread::spawn(ring.slots() / 2))
            .transpose()
            .map_err(|source| RecordError::Create { path: path.clone(), source })?;
        let links = LinkRegistry::default();
        let stop = Arc::new(AtomicBool::new(false));
        let mut state = WriterState {
            writer,
            path: path.clone(),
            command: command.into(),
            links: links.clone(),
            unix_offset_ns: unix_minus_monotonic_ns(),
            channels: Channels::default(),
            wire_only: options.wire_only,
            summary: RecordingSummary::default(),
        };
        let thread = std::thread::Builder::new()
            .name("robowire-record".into())
            .spawn({
                let (ring, stop) = (ring.clone(), stop.clone());
                move || {
                    let result = state.run(&ring, &stop, json);
                    ring.close();
                    result
                }
            })
            .map_err(|source| RecordError::Create { path, source })?;
        Ok(Self { ring, links, stop, thread: Some(thread) })
    }

    /// A tap for the link `name` (`zsl1/high_level`), whose frames `description` describes: the
    /// capture names its protocol, and its frames are decoded by it for the JSON channels.
    pub fn link(&self, name: &str, description: &'static dyn LinkDescription) -> Tap {
        self.links().link(name, description)
    }

    /// A handle that registers links with this recorder, for code that opens devices on its
    /// behalf (`robowire_devices::OpenOptions::record`).
    pub fn links(&self) -> RecordLinks {
        RecordLinks::new(self.ring.clone(), self.links.clone())
    }

    /// Frames dropped so far because the ring was full.
    pub fn dropped(&self) -> u64 {
        self.ring.counters().dropped()
    }

    /// Frames dropped so far because they were longer than a slot.
    pub fn oversize(&self) -> u64 {
        self.ring.counters().oversize()
    }

    /// Writes what is in the ring, the metadata and the summary, and closes the file. Frames
    /// tapped after this are dropped (counted by their taps).
    pub fn finish(mut self) -> Result<RecordingSummary, RecordError> {
        let thread = self.stop_thread().ok_or(RecordError::Thread)?;
        let mut summary = thread.join().map_err(|_| RecordError::Thread)??;
        summary.dropped = self.ring.counters().dropped();
        summary.oversize = self.ring.counters().oversize();
        Ok(summary)
    }

    /// Tells the writer to drain the ring and finish, and wakes it.
    fn stop_thread(&mut self) -> Option<JoinHandle<Result<RecordingSummary, RecordError>>> {
        self.stop.store(true, Ordering::Release);
        let thread = self.thread.take()?;
        thread.thread().unpark();
        Some(thread)
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        if let Some(thread) = self.stop_thread() {
            let _ = thread.join();
        }
    }
}

/// Unix time minus monotonic time, ns: what turns a tap's stamp into a log time.
fn unix_minus_monotonic_ns() -> i64 {
    let unix_ns = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos());
    let offset = i128::try_from(unix_ns).unwrap_or(i128::MAX) - i128::from(robowire_rt::monotonic_ns());
    i64::try_from(offset).unwrap_or(0)
}

/// The writer thread's state.
struct WriterState {
    writer: mcap::Writer<BufWriter<File>>,
    path: PathBuf,
    command: String,
    links: LinkRegistry,
    /// Added to a tap's monotonic stamp: Unix time, ns.
    unix_offset_ns: i64,
    channels: Channels,
    /// [`RecorderOptions::wire_only`].
    wire_only: bool,
    summary: RecordingSummary,
}

impl WriterState {
    fn run(
        &mut self,
        ring: &TapRing,
        stop: &AtomicBool,
        json: Option<JsonThread>,
    ) -> Result<RecordingSummary, RecordError> {
        loop {
            let stopping = stop.load(Ordering::Acquire);
            if stopping {
                ring.close();
            }
            let mut queued = false;
            while let Some(frame) = ring.take() {
                let Some(description) = self.write_frame(&frame)? else { continue };
                let Some(json) = &json else { continue };
                if stopping {
                    json.push_waiting((frame, description), |m| self.write_json(&m))?;
                } else if json.offer(frame, description) {
                    queued = true;
                } else {
                    self.summary.json_skipped += 1;
                }
            }
            if let Some(json) = &json {
                if queued {
                    json.wake();
                }
                for message in json.ready() {
                    self.write_json(&message)?;
                }
            }
            if stopping {
                if let Some(json) = json {
                    json.finish(|m| self.write_json(&m))?;
                }
                return self.close();
            }
            std::thread::park_timeout(POLL);
        }
    }

    fn error(&self) -> impl Fn(mcap::McapError) -> RecordError + '_ {
        |source| RecordError::Write { path: self.path.clone(), source }
    }

    /// Writes `frame` on the channel of its own bytes (its wire encoding's, or raw); the
    /// description to decode it to JSON with if it went raw.
    fn write_frame(&mut self, frame: &TappedFrame) -> Result<Option<&'static dyn LinkDescription>, RecordError> {
        let key = (frame.link, frame.direction, frame.origin.writer);
        let links = &self.links;
        let registered = |link: usize| robowire_rt::lock(links).get(link).cloned();
        let placed = self
            .channels
            .frame_channel(&mut self.writer, key, frame.bytes(), self.wire_only, registered)
            .map_err(self.error())?;
        let channel = match placed {
            Placed::On(channel) => channel,
            Placed::UnknownLink => {
                self.summary.decode_errors += 1;
                return Ok(None);
            }
            Placed::NotWire => {
                self.summary.not_wire += 1;
                return Ok(None);
            }
        };
        let header = self.header(channel.id, frame.monotonic_ns, frame.origin.source_unix_ns);
        self.writer.write_to_known_channel(&header, frame.bytes()).map_err(self.error())?;
        self.summary.frames += 1;
        Ok(channel.json_by)
    }

    /// A message's header: logged at the tap's time in Unix ns, published at the source
    /// timestamp if the middleware gave one.
    fn header(&mut self, channel_id: u16, monotonic_ns: u64, source_unix_ns: Option<u64>) -> MessageHeader {
        let log_time = monotonic_ns.saturating_add_signed(self.unix_offset_ns);
        let sequence = self.channels.next_sequence(channel_id);
        MessageHeader { channel_id, sequence, log_time, publish_time: source_unix_ns.unwrap_or(log_time) }
    }

    /// Writes a frame's JSON message (made by the JSON thread) on its message type's channel.
    fn write_json(&mut self, message: &JsonMessage) -> Result<(), RecordError> {
        let Some(json) = &message.json else {
            self.summary.decode_errors += 1;
            return Ok(());
        };
        let key = (message.link, message.direction, message.origin.writer);
        let channel = self
            .channels
            .json_channel(&mut self.writer, key, message.schema, message.schema_text.as_ref())
            .map_err(self.error())?;
        let Some(channel) = channel else { return Ok(()) };
        let header = self.header(channel, message.monotonic_ns, message.origin.source_unix_ns);
        self.writer.write_to_known_channel(&header, json).map_err(self.error())?;
        Ok(())
    }

    fn close(&mut self) -> Result<RecordingSummary, RecordError> {
        let links = robowire_rt::lock(&self.links).clone();
        let mut metadata = BTreeMap::from([
            ("robowire_version".to_string(), env!("CARGO_PKG_VERSION").to_string()),
            ("command".to_string(), self.command.clone()),
        ]);
        for (name, description) in &links {
            metadata.insert(format!("link:{name}"), format!("{} ({})", description.protocol(), description.layout()));
        }
        self.writer.write_metadata(&Metadata { name: "robowire".into(), metadata }).map_err(self.error())?;
        self.writer.finish().map_err(self.error())?;
        Ok(self.summary.clone())
    }
}
