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
use robowire_core::json::{JsonFrame, LinkDescription};
use robowire_tap::{Direction, Tap, TapRing, TappedFrame};

use crate::RAW_ENCODING;

/// Slots of the taps' ring (each [`robowire_tap::SLOT_BYTES`], about 4.8 MB in all): 2 s of a
/// 500 Hz link both ways, for the writer to fall behind by before frames are dropped.
const RING_SLOTS: usize = 2048;
/// How long the writer sleeps when the ring is empty.
const POLL: Duration = Duration::from_millis(5);

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
    /// Frames written, raw channels.
    pub frames: u64,
    /// Frames the taps dropped because the ring was full (the writer fell behind).
    pub dropped: u64,
    /// Frames the taps dropped because they were longer than a slot.
    pub oversize: u64,
    /// Frames whose decoding for the JSON channel failed (their raw frame is still written).
    pub decode_errors: u64,
}

/// Every link's name and description, by link number.
type Links = Arc<Mutex<Vec<(String, &'static dyn LinkDescription)>>>;

/// Records taps into one MCAP file.
///
/// The taps stamp frames with the monotonic clock; the writer logs them at Unix time, through
/// the offset between the two clocks taken once when the recorder is created (a step of the wall
/// clock while recording does not move the frames' times).
#[derive(Debug)]
pub struct Recorder {
    ring: TapRing,
    links: Links,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Result<RecordingSummary, RecordError>>>,
}

impl Recorder {
    /// Creates `path` and starts the writer thread. `command` is what is recording (for the
    /// metadata: `robowire dog … --record`).
    pub fn create(path: impl AsRef<Path>, command: &str) -> Result<Self, RecordError> {
        let path = path.as_ref().to_path_buf();
        let file = File::create(&path).map_err(|source| RecordError::Create { path: path.clone(), source })?;
        let write_error = |path: &Path| {
            let path = path.to_path_buf();
            move |source| RecordError::Write { path, source }
        };
        let writer = mcap::WriteOptions::new()
            .compression(None)
            .profile("")
            .library(concat!("robowire ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .map_err(write_error(&path))?;
        let ring = TapRing::with_slots(RING_SLOTS);
        let links = Links::default();
        let stop = Arc::new(AtomicBool::new(false));
        let mut state = WriterState {
            writer,
            path,
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
                    let result = state.run(&ring, &stop);
                    ring.close();
                    result
                }
            })
            .map_err(|source| RecordError::Create { path: PathBuf::new(), source })?;
        Ok(Self { ring, links, stop, thread: Some(thread) })
    }

    /// A tap for the link `name` (`dog/high_level`), whose frames `description` describes: the
    /// capture names its protocol, and its frames are decoded by it for the JSON channels.
    pub fn link(&self, name: &str, description: &'static dyn LinkDescription) -> Tap {
        let mut links = robowire_rt::lock(&self.links);
        links.push((name.trim_matches('/').into(), description));
        self.ring.tap(u16::try_from(links.len() - 1).unwrap_or(u16::MAX))
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

/// The channels of one link and direction: raw, and one JSON channel per schema.
struct LinkChannels {
    name: String,
    description: &'static dyn LinkDescription,
    raw: u16,
    json: HashMap<&'static str, u16>,
}

/// The writer thread's state.
struct WriterState {
    writer: mcap::Writer<BufWriter<File>>,
    path: PathBuf,
    command: String,
    links: Links,
    /// Added to a tap's monotonic stamp: Unix time, ns.
    unix_offset_ns: i64,
    /// (link, direction) → its channels.
    channels: HashMap<(u16, Direction), LinkChannels>,
    schemas: HashMap<&'static str, u16>,
    summary: RecordingSummary,
}

impl WriterState {
    fn run(&mut self, ring: &TapRing, stop: &AtomicBool) -> Result<RecordingSummary, RecordError> {
        loop {
            let stopping = stop.load(Ordering::Acquire);
            if stopping {
                ring.close();
            }
            while let Some(written) = ring.pop(|frame| self.write(frame)) {
                written?;
            }
            if stopping {
                return self.close();
            }
            std::thread::park_timeout(POLL);
        }
    }

    fn error(&self) -> impl Fn(mcap::McapError) -> RecordError + '_ {
        |source| RecordError::Write { path: self.path.clone(), source }
    }

    /// The raw channel and description of `frame`'s link and direction, the channel made on
    /// its first frame. `None` for a link number no one registered (taps are only handed out
    /// for registered links).
    fn raw_channel(&mut self, frame: &TappedFrame) -> Result<Option<(u16, &'static dyn LinkDescription)>, RecordError> {
        let key = (frame.link, frame.direction);
        if let Some(c) = self.channels.get(&key) {
            return Ok(Some((c.raw, c.description)));
        }
        let link = robowire_rt::lock(&self.links).get(usize::from(frame.link)).cloned();
        let Some((name, description)) = link else { return Ok(None) };
        let metadata = BTreeMap::from([
            ("link".to_string(), name.clone()),
            ("direction".to_string(), frame.direction.name().to_string()),
            ("protocol".to_string(), description.protocol().to_string()),
        ]);
        let topic = format!("/{name}/{}/raw", frame.direction.name());
        let raw = self.writer.add_channel(0, &topic, RAW_ENCODING, &metadata).map_err(self.error())?;
        self.channels.insert(key, LinkChannels { name, description, raw, json: HashMap::new() });
        Ok(Some((raw, description)))
    }

    /// The JSON channel of `decoded`'s schema on the link and direction `key`, made with its
    /// schema on its first message; `None` if `key` has no raw channel yet.
    fn json_channel(&mut self, key: (u16, Direction), decoded: &JsonFrame) -> Result<Option<u16>, RecordError> {
        let Some(c) = self.channels.get(&key) else { return Ok(None) };
        if let Some(&id) = c.json.get(decoded.schema) {
            return Ok(Some(id));
        }
        let (name, description) = (c.name.clone(), c.description);
        let schema = match self.schemas.get(decoded.schema) {
            Some(&id) => id,
            None => {
                let text = serde_json::to_vec(&description.schema(decoded)).unwrap_or_default();
                let id = self.writer.add_schema(decoded.schema, "jsonschema", &text).map_err(self.error())?;
                self.schemas.insert(decoded.schema, id);
                id
            }
        };
        let metadata = BTreeMap::from([("link".to_string(), name.clone())]);
        let topic = format!("/{name}/{}", key.1.name());
        let id = self.writer.add_channel(schema, &topic, "json", &metadata).map_err(self.error())?;
        self.channels.get_mut(&key).map(|c| c.json.insert(decoded.schema, id));
        Ok(Some(id))
    }

    fn write(&mut self, frame: &TappedFrame) -> Result<(), RecordError> {
        let unix_ns = frame.monotonic_ns.saturating_add_signed(self.unix_offset_ns);
        let header = |channel_id| MessageHeader { channel_id, sequence: 0, log_time: unix_ns, publish_time: unix_ns };
        let Some((raw, description)) = self.raw_channel(frame)? else {
            self.summary.decode_errors += 1;
            return Ok(());
        };
        self.writer.write_to_known_channel(&header(raw), frame.bytes()).map_err(self.error())?;
        self.summary.frames += 1;
        let Ok(decoded) = description.decode(frame.direction, frame.bytes()) else {
            self.summary.decode_errors += 1;
            return Ok(());
        };
        let Some(json_channel) = self.json_channel((frame.link, frame.direction), &decoded)? else { return Ok(()) };
        let json = serde_json::to_vec(&decoded.value).unwrap_or_default();
        self.writer.write_to_known_channel(&header(json_channel), &json).map_err(self.error())?;
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
