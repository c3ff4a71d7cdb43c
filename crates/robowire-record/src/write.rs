//! The recorder: a thread that writes the taps' frames into an MCAP file.

use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

use mcap::records::{MessageHeader, Metadata};
use robowire_tap::{Direction, Tap, TapQueue, TappedFrame};

use crate::RAW_ENCODING;
use crate::protocol::Protocol;
use crate::schema::schema_of;

/// Frames the queue holds before it drops: about 4 s of a 500 Hz link both ways.
const QUEUE_FRAMES: usize = 4096;
/// How often the writer looks for the stop flag while the links are quiet.
const POLL: Duration = Duration::from_millis(50);

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
    /// Frames the queue dropped (the writer fell behind).
    pub dropped: u64,
    /// Frames whose decoding for the JSON channel failed (their raw frame is still written).
    pub decode_errors: u64,
}

type Links = Arc<Mutex<Vec<(String, Protocol)>>>;

/// Records taps into one MCAP file.
#[derive(Debug)]
pub struct Recorder {
    queue: TapQueue,
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
        let (queue, frames) = TapQueue::bounded(QUEUE_FRAMES);
        let links = Links::default();
        let stop = Arc::new(AtomicBool::new(false));
        let state = WriterState {
            writer,
            path,
            command: command.into(),
            links: links.clone(),
            channels: HashMap::new(),
            schemas: HashMap::new(),
            summary: RecordingSummary::default(),
        };
        let thread = std::thread::Builder::new()
            .name("robowire-record".into())
            .spawn({
                let stop = stop.clone();
                move || state.run(&frames, &stop)
            })
            .map_err(|source| RecordError::Create { path: PathBuf::new(), source })?;
        Ok(Self { queue, links, stop, thread: Some(thread) })
    }

    /// A tap for the link `name` (`dog/high_level`), carrying `protocol`.
    pub fn link(&self, name: &str, protocol: Protocol) -> Tap {
        let mut links = self.links.lock().unwrap_or_else(PoisonError::into_inner);
        links.push((name.trim_matches('/').into(), protocol));
        self.queue.tap(u16::try_from(links.len() - 1).unwrap_or(u16::MAX))
    }

    /// Frames dropped so far because the queue was full.
    pub fn dropped(&self) -> u64 {
        self.queue.counters().dropped()
    }

    /// Writes what is queued, the metadata and the summary, and closes the file. Frames tapped
    /// after this are dropped (counted by their taps).
    pub fn finish(mut self) -> Result<RecordingSummary, RecordError> {
        self.stop.store(true, Ordering::Release);
        let thread = self.thread.take().ok_or(RecordError::Thread)?;
        let mut summary = thread.join().map_err(|_| RecordError::Thread)??;
        summary.dropped = self.queue.counters().dropped();
        Ok(summary)
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The channels of one link and direction: raw, and one JSON channel per schema.
type LinkChannels = (u16, HashMap<&'static str, u16>);

/// The writer thread's state.
struct WriterState {
    writer: mcap::Writer<BufWriter<File>>,
    path: PathBuf,
    command: String,
    links: Links,
    /// (link, direction) → its channels.
    channels: HashMap<(u16, Direction), LinkChannels>,
    schemas: HashMap<&'static str, u16>,
    summary: RecordingSummary,
}

impl WriterState {
    fn run(mut self, frames: &Receiver<TappedFrame>, stop: &AtomicBool) -> Result<RecordingSummary, RecordError> {
        loop {
            match frames.recv_timeout(POLL) {
                Ok(frame) => self.write(&frame)?,
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if stop.load(Ordering::Acquire) {
                while let Ok(frame) = frames.try_recv() {
                    self.write(&frame)?;
                }
                break;
            }
        }
        self.close()
    }

    fn error(&self) -> impl Fn(mcap::McapError) -> RecordError + '_ {
        |source| RecordError::Write { path: self.path.clone(), source }
    }

    fn link(&self, id: u16) -> (String, Protocol) {
        let links = self.links.lock().unwrap_or_else(PoisonError::into_inner);
        links.get(usize::from(id)).cloned().unwrap_or_else(|| (format!("link{id}"), Protocol::ZslHighLevel))
    }

    fn write(&mut self, frame: &TappedFrame) -> Result<(), RecordError> {
        let key = (frame.link, frame.direction);
        let (name, protocol) = self.link(frame.link);
        if !self.channels.contains_key(&key) {
            let metadata = BTreeMap::from([
                ("link".to_string(), name.clone()),
                ("direction".to_string(), frame.direction.name().to_string()),
                ("protocol".to_string(), protocol.name().to_string()),
            ]);
            let topic = format!("/{name}/{}/raw", frame.direction.name());
            let raw = self.writer.add_channel(0, &topic, RAW_ENCODING, &metadata).map_err(self.error())?;
            self.channels.insert(key, (raw, HashMap::new()));
        }
        let header = |channel_id| MessageHeader {
            channel_id,
            sequence: 0,
            log_time: frame.unix_ns,
            publish_time: frame.unix_ns,
        };
        let raw = self.channels[&key].0;
        self.writer.write_to_known_channel(&header(raw), &frame.bytes).map_err(self.error())?;
        self.summary.frames += 1;
        let (schema_name, value) = match protocol.decode(&frame.bytes) {
            Ok(decoded) => decoded,
            Err(_) => {
                self.summary.decode_errors += 1;
                return Ok(());
            }
        };
        let json_channel = match self.channels[&key].1.get(schema_name) {
            Some(&id) => id,
            None => {
                let schema = match self.schemas.get(schema_name) {
                    Some(&id) => id,
                    None => {
                        let text = serde_json::to_vec(&schema_of(schema_name, &value)).unwrap_or_default();
                        let id = self.writer.add_schema(schema_name, "jsonschema", &text).map_err(self.error())?;
                        self.schemas.insert(schema_name, id);
                        id
                    }
                };
                let metadata = BTreeMap::from([("link".to_string(), name.clone())]);
                let topic = format!("/{name}/{}", frame.direction.name());
                let id = self.writer.add_channel(schema, &topic, "json", &metadata).map_err(self.error())?;
                self.channels.get_mut(&key).map(|c| c.1.insert(schema_name, id));
                id
            }
        };
        let json = serde_json::to_vec(&value).unwrap_or_default();
        self.writer.write_to_known_channel(&header(json_channel), &json).map_err(self.error())?;
        Ok(())
    }

    fn close(mut self) -> Result<RecordingSummary, RecordError> {
        let links = self.links.lock().unwrap_or_else(PoisonError::into_inner).clone();
        let mut metadata = BTreeMap::from([
            ("robowire_version".to_string(), env!("CARGO_PKG_VERSION").to_string()),
            ("command".to_string(), self.command.clone()),
        ]);
        for (name, protocol) in &links {
            metadata.insert(format!("link:{name}"), format!("{} ({})", protocol.name(), protocol.layout()));
        }
        self.writer.write_metadata(&Metadata { name: "robowire".into(), metadata }).map_err(self.error())?;
        self.writer.finish().map_err(self.error())?;
        Ok(self.summary)
    }
}
