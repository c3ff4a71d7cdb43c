//! The recorder: a thread that writes the taps' frames into an MCAP file.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use mcap::records::{MessageHeader, Metadata};
use robowire_core::json::{LinkDescription, WireSchema};
use robowire_tap::{Direction, Tap, TapRing, TappedFrame};

use crate::json_thread::{JsonMessage, JsonThread};
use crate::{LAYOUT_SCHEMA_ENCODING, RAW_ENCODING};

/// How long the writer sleeps when the ring is empty: at 1 M frames/s, 1 000 frames arrive
/// meanwhile (a quarter of the default ring).
const POLL: Duration = Duration::from_millis(1);

/// How a recorder is set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecorderOptions {
    /// Slots of the taps' ring, each [`robowire_tap::SLOT_BYTES`] (the default 4096: about 9.6 MB,
    /// 4 ms of 1 M frames/s, or 4 s of a 500 Hz link both ways, for the writer to fall behind by
    /// before frames are dropped).
    pub ring_slots: usize,
    /// Writes each frame's JSON message beside its raw bytes (default on); off, a capture has the
    /// raw channels only, and `robowire decode --mcap` reads them.
    pub json: bool,
}

impl Default for RecorderOptions {
    fn default() -> Self {
        Self { ring_slots: 4096, json: true }
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
}

/// Every link's name and description, by link number.
type Links = Arc<Mutex<Vec<(String, &'static dyn LinkDescription)>>>;

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
    links: Links,
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
            .compression(None)
            .profile("")
            .library(concat!("robowire ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::with_capacity(1 << 20, file))
            .map_err(|source| RecordError::Write { path: path.clone(), source })?;
        let ring = TapRing::with_slots(options.ring_slots);
        let json = options
            .json
            .then(|| JsonThread::spawn(ring.slots() / 2))
            .transpose()
            .map_err(|source| RecordError::Create { path: path.clone(), source })?;
        let links = Links::default();
        let stop = Arc::new(AtomicBool::new(false));
        let mut state = WriterState {
            writer,
            path: path.clone(),
            command: command.into(),
            links: links.clone(),
            unix_offset_ns: unix_minus_monotonic_ns(),
            channels: HashMap::new(),
            schemas: HashMap::new(),
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

    /// A tap for the link `name` (`dog/high_level`), whose frames `description` describes: the
    /// capture names its protocol, and its frames are decoded by it for the JSON channels.
    pub fn link(&self, name: &str, description: &'static dyn LinkDescription) -> Tap {
        self.links().link(name, description)
    }

    /// A handle that registers links with this recorder, for code that opens devices on its
    /// behalf (`robowire_devices::OpenOptions::record`).
    pub fn links(&self) -> RecordLinks {
        RecordLinks { ring: self.ring.clone(), links: self.links.clone() }
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

/// Registers links with a [`Recorder`] ([`Recorder::links`]); clones register with the same
/// one. Taps handed out after the recorder finished drop their frames and count them.
#[derive(Debug, Clone)]
pub struct RecordLinks {
    ring: TapRing,
    links: Links,
}

impl RecordLinks {
    /// As [`Recorder::link`].
    pub fn link(&self, name: &str, description: &'static dyn LinkDescription) -> Tap {
        let mut links = robowire_rt::lock(&self.links);
        links.push((name.trim_matches('/').into(), description));
        self.ring.tap(u16::try_from(links.len() - 1).unwrap_or(u16::MAX))
    }
}

/// Two handles are equal when they register with the same recorder.
impl PartialEq for RecordLinks {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.links, &other.links)
    }
}

impl Eq for RecordLinks {}

/// Unix time minus monotonic time, ns: what turns a tap's stamp into a log time.
fn unix_minus_monotonic_ns() -> i64 {
    let unix_ns = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos());
    let offset = i128::try_from(unix_ns).unwrap_or(i128::MAX) - i128::from(robowire_rt::monotonic_ns());
    i64::try_from(offset).unwrap_or(0)
}

/// Which channels a frame goes to: its link, direction and writer.
type ChannelKey = (u16, Direction, Option<[u8; 16]>);

/// The channels of one link, direction and writer: the frames' own (raw, or per wire schema),
/// and one JSON channel per schema.
struct LinkChannels {
    name: String,
    description: &'static dyn LinkDescription,
    raw: Option<u16>,
    wire: HashMap<&'static str, u16>,
    json: HashMap<&'static str, u16>,
    /// Messages written per channel id, for their sequence numbers.
    sequence: HashMap<u16, u32>,
}

/// The writer thread's state.
struct WriterState {
    writer: mcap::Writer<BufWriter<File>>,
    path: PathBuf,
    command: String,
    links: Links,
    /// Added to a tap's monotonic stamp: Unix time, ns.
    unix_offset_ns: i64,
    channels: HashMap<ChannelKey, LinkChannels>,
    /// Schema ids by (encoding, name).
    schemas: HashMap<(&'static str, &'static str), u16>,
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

    /// The channels of `key`, made on its link's first frame; `None` for a link number no one
    /// registered (taps are only handed out for registered links).
    fn link_channels(&mut self, key: ChannelKey) -> Option<&mut LinkChannels> {
        if !self.channels.contains_key(&key) {
            let (name, description) = robowire_rt::lock(&self.links).get(usize::from(key.0)).cloned()?;
            let channels = LinkChannels {
                name,
                description,
                raw: None,
                wire: HashMap::new(),
                json: HashMap::new(),
                sequence: HashMap::new(),
            };
            self.channels.insert(key, channels);
        }
        self.channels.get_mut(&key)
    }

    fn schema_id(&mut self, encoding: &'static str, name: &'static str, text: &[u8]) -> Result<u16, RecordError> {
        if let Some(&id) = self.schemas.get(&(encoding, name)) {
            return Ok(id);
        }
        let id = self.writer.add_schema(name, encoding, text).map_err(self.error())?;
        self.schemas.insert((encoding, name), id);
        Ok(id)
    }

    /// The metadata of a channel of `key`'s link.
    fn metadata(key: ChannelKey, name: &str, description: &dyn LinkDescription) -> BTreeMap<String, String> {
        let mut metadata = BTreeMap::from([
            ("link".to_string(), name.to_string()),
            ("direction".to_string(), key.1.name().to_string()),
            ("protocol".to_string(), description.protocol().to_string()),
        ]);
        if let Some(writer) = key.2 {
            metadata.insert("writer_guid".into(), writer.iter().map(|b| format!("{b:02x}")).collect());
        }
        metadata
    }

    /// Writes `frame` on the channel of its own bytes: its wire encoding's, if its description
    /// names one, else the raw channel. The description to decode it to JSON with if it went
    /// raw (a wire encoding readers decode themselves).
    fn write_frame(&mut self, frame: &TappedFrame) -> Result<Option<&'static dyn LinkDescription>, RecordError> {
        let key = (frame.link, frame.direction, frame.origin.writer);
        let Some(channels) = self.link_channels(key) else {
            self.summary.decode_errors += 1;
            return Ok(None);
        };
        let description = channels.description;
        let (channel, json) = match description.wire_schema(frame.direction, frame.bytes()) {
            Some(wire) => (self.wire_channel(key, &wire)?, None),
            None => (self.raw_channel(key)?, Some(description)),
        };
        let unix_ns = frame.monotonic_ns.saturating_add_signed(self.unix_offset_ns);
        let publish_ns = frame.origin.source_unix_ns.unwrap_or(unix_ns);
        let sequence = self.next_sequence(key, channel);
        let header = MessageHeader { channel_id: channel, sequence, log_time: unix_ns, publish_time: publish_ns };
        self.writer.write_to_known_channel(&header, frame.bytes()).map_err(self.error())?;
        self.summary.frames += 1;
        Ok(json)
    }

    fn next_sequence(&mut self, key: ChannelKey, channel: u16) -> u32 {
        let Some(channels) = self.channels.get_mut(&key) else { return 0 };
        let sequence = channels.sequence.entry(channel).or_default();
        *sequence = sequence.wrapping_add(1);
        *sequence
    }

    fn raw_channel(&mut self, key: ChannelKey) -> Result<u16, RecordError> {
        let Some(channels) = self.channels.get(&key) else { return Err(RecordError::Thread) };
        if let Some(id) = channels.raw {
            return Ok(id);
        }
        let (name, description) = (channels.name.clone(), channels.description);
        let topic = format!("/{name}/{}/raw", key.1.name());
        let metadata = Self::metadata(key, &name, description);
        // The bytes' own layout, named: not a schema a reader decodes with, but every channel
        // says what its messages are.
        let schema = self.schema_id(LAYOUT_SCHEMA_ENCODING, description.protocol(), description.layout().as_bytes())?;
        let id = self.writer.add_channel(schema, &topic, RAW_ENCODING, &metadata).map_err(self.error())?;
        if let Some(c) = self.channels.get_mut(&key) {
            c.raw = Some(id);
        }
        Ok(id)
    }

    fn wire_channel(&mut self, key: ChannelKey, wire: &WireSchema) -> Result<u16, RecordError> {
        let Some(channels) = self.channels.get(&key) else { return Err(RecordError::Thread) };
        if let Some(&id) = channels.wire.get(wire.name) {
            return Ok(id);
        }
        let (name, description) = (channels.name.clone(), channels.description);
        let schema = self.schema_id(wire.schema_encoding, wire.name, wire.text.as_bytes())?;
        let topic = format!("/{name}/{}", key.1.name());
        let metadata = Self::metadata(key, &name, description);
        let id = self.writer.add_channel(schema, &topic, wire.encoding, &metadata).map_err(self.error())?;
        self.channels.get_mut(&key).map(|c| c.wire.insert(wire.name, id));
        Ok(id)
    }

    /// Writes a frame's JSON message (made by the JSON thread) on its schema's channel.
    fn write_json(&mut self, message: &JsonMessage) -> Result<(), RecordError> {
        let Some(json) = &message.json else {
            self.summary.decode_errors += 1;
            return Ok(());
        };
        let key = (message.link, message.direction, message.origin.writer);
        let Some(channels) = self.channels.get(&key) else { return Ok(()) };
        let channel = match channels.json.get(message.schema) {
            Some(&id) => id,
            None => {
                let name = channels.name.clone();
                let text = message.schema_text.as_ref().map(serde_json::to_vec).transpose().ok().flatten();
                let schema = match text {
                    Some(text) => self.schema_id("jsonschema", message.schema, &text)?,
                    None => self.schemas.get(&("jsonschema", message.schema)).copied().unwrap_or(0),
                };
                let mut metadata = BTreeMap::from([("link".to_string(), name.clone())]);
                if let Some(writer) = key.2 {
                    metadata.insert("writer_guid".into(), writer.iter().map(|b| format!("{b:02x}")).collect());
                }
                let topic = format!("/{name}/{}/{}", key.1.name(), message.schema);
                let id = self.writer.add_channel(schema, &topic, "json", &metadata).map_err(self.error())?;
                self.channels.get_mut(&key).map(|c| c.json.insert(message.schema, id));
                id
            }
        };
        let unix_ns = message.monotonic_ns.saturating_add_signed(self.unix_offset_ns);
        let publish_ns = message.origin.source_unix_ns.unwrap_or(unix_ns);
        let sequence = self.next_sequence(key, channel);
        let header = MessageHeader { channel_id: channel, sequence, log_time: unix_ns, publish_time: publish_ns };
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
