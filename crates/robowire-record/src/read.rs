//! Reading a capture back: its frames for replay, its summary for `robowire decode --mcap`.

use std::collections::BTreeMap;

use robowire_core::json::{FrameError, JsonFrame, LinkDescription};
use robowire_tap::Direction;

/// Why a capture could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// Not an MCAP file, truncated, or corrupt.
    #[error("not a readable MCAP capture ({len} bytes): {source}")]
    Mcap {
        /// The file's length.
        len: usize,
        /// What the MCAP reader expected and found.
        source: mcap::McapError,
    },
    /// The file's record framing is broken: found at `offset` what does not fit.
    #[error("corrupt capture at byte {offset}: expected {expected}")]
    Corrupt {
        /// Where, from the start of the file.
        offset: usize,
        /// What should have been there.
        expected: String,
    },
    /// A raw channel whose metadata lacks its link, direction or protocol.
    #[error("channel {topic}: {reason}")]
    Channel {
        /// The channel's topic.
        topic: String,
        /// What is wrong.
        reason: String,
    },
    /// A raw channel of a protocol no description the application registered has: its frames
    /// cannot be told apart, and are not guessed at.
    #[error("channel {topic}: protocol {protocol:?} is not one this application describes")]
    UnknownProtocol {
        /// The channel's topic.
        topic: String,
        /// The protocol its metadata names.
        protocol: String,
    },
}

/// One frame as recorded.
#[derive(Debug, Clone)]
pub struct RecordedFrame {
    /// The link's name (`zsl1/high_level`).
    pub link: String,
    /// Sent or received, from the recording side.
    pub direction: Direction,
    /// The description of the link's protocol, among those the reader was given.
    pub protocol: &'static dyn LinkDescription,
    /// When, ns since the Unix epoch.
    pub unix_ns: u64,
    /// The bytes as on the wire.
    pub bytes: Vec<u8>,
}

impl RecordedFrame {
    /// The frame as JSON, by its link's description.
    pub fn decode(&self) -> Result<JsonFrame, FrameError> {
        self.protocol.decode(self.direction, &self.bytes)
    }
}

/// Equal frames: same link, direction, protocol name, time and bytes.
impl PartialEq for RecordedFrame {
    fn eq(&self, other: &Self) -> bool {
        (&self.link, self.direction, self.protocol.protocol(), self.unix_ns, &self.bytes)
            == (&other.link, other.direction, other.protocol.protocol(), other.unix_ns, &other.bytes)
    }
}

impl Eq for RecordedFrame {}

/// What the metadata of a raw channel says: link, direction, and the description of its
/// protocol among `known`.
fn raw_channel(
    channel: &mcap::Channel<'_>,
    known: &[&'static dyn LinkDescription],
) -> Result<(String, Direction, &'static dyn LinkDescription), ReadError> {
    let field = |key: &str| {
        channel.metadata.get(key).ok_or_else(|| ReadError::Channel {
            topic: channel.topic.clone(),
            reason: format!("no {key} in its metadata"),
        })
    };
    let direction = match field("direction")?.as_str() {
        "sent" => Direction::Sent,
        "received" => Direction::Received,
        other => {
            return Err(ReadError::Channel { topic: channel.topic.clone(), reason: format!("direction {other:?}") });
        }
    };
    let protocol = field("protocol")?;
    let description = known
        .iter()
        .copied()
        .find(|d| d.protocol() == protocol)
        .ok_or_else(|| ReadError::UnknownProtocol { topic: channel.topic.clone(), protocol: protocol.clone() })?;
    Ok((field("link")?.clone(), direction, description))
}

/// Whether `channel` holds a link's frames as they were on the wire: raw
/// ([`RAW_ENCODING`](crate::RAW_ENCODING)) or in their wire encoding (a DDS payload as `cdr`).
/// Such a channel names its protocol in its metadata; a JSON channel does not.
fn carries_frames(channel: &mcap::Channel<'_>) -> bool {
    channel.metadata.contains_key("protocol")
}

fn mcap_error(len: usize) -> impl Fn(mcap::McapError) -> ReadError {
    move |source| ReadError::Mcap { len, source }
}

/// Refuses a file whose framing is broken (see [`crate::framing`]).
fn validate(capture: &[u8]) -> Result<(), ReadError> {
    crate::framing::check(capture).map_err(|b| ReadError::Corrupt { offset: b.offset, expected: b.expected })
}

/// The raw frames of a capture, in file order (time order per link). `known` are the
/// descriptions the application registers; a link of another protocol is an error.
pub fn read_frames(capture: &[u8], known: &[&'static dyn LinkDescription]) -> Result<Vec<RecordedFrame>, ReadError> {
    validate(capture)?;
    let mut frames = Vec::new();
    for message in mcap::MessageStream::new(capture).map_err(mcap_error(capture.len()))? {
        let message = message.map_err(mcap_error(capture.len()))?;
        if !carries_frames(&message.channel) {
            continue;
        }
        let (link, direction, protocol) = raw_channel(&message.channel, known)?;
        frames.push(RecordedFrame {
            link,
            direction,
            protocol,
            unix_ns: message.log_time,
            bytes: message.data.into_owned(),
        });
    }
    Ok(frames)
}

/// One channel of a capture.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelSummary {
    /// The topic.
    pub topic: String,
    /// Its message encoding (`robowire.raw`, `cdr`, `json`).
    pub encoding: String,
    /// Whether it holds a link's frames as they were on the wire (raw or `cdr`), not JSON.
    pub frames: bool,
    /// Messages.
    pub count: u64,
    /// First and last log time, ns since the epoch.
    pub span_ns: (u64, u64),
    /// Mean rate over the span, Hz.
    pub rate_hz: f64,
    /// Longest gap between two messages, ns.
    pub max_gap_ns: u64,
    /// Log times that went backwards.
    pub out_of_order: u64,
    /// Raw frames that do not decode by their link's description.
    pub decode_errors: u64,
}

/// What a capture holds.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureSummary {
    /// The `robowire` metadata record (version, command, links), if any.
    pub metadata: BTreeMap<String, String>,
    /// Every channel, by topic and encoding (channels that share both are counted together).
    pub channels: Vec<ChannelSummary>,
}

/// Channels, counts, rates, gaps and decode errors of a capture. `known` are the descriptions
/// the application registers; a link of another protocol is an error.
pub fn summarize(capture: &[u8], known: &[&'static dyn LinkDescription]) -> Result<CaptureSummary, ReadError> {
    validate(capture)?;
    type Decoder = Option<(Direction, &'static dyn LinkDescription)>;
    let mut channels: BTreeMap<(String, String), ChannelSummary> = BTreeMap::new();
    // Each raw channel's decoder, by channel id: a topic may have channels of several encodings.
    let mut decoders: BTreeMap<u16, Decoder> = BTreeMap::new();
    for message in mcap::MessageStream::new(capture).map_err(mcap_error(capture.len()))? {
        let message = message.map_err(mcap_error(capture.len()))?;
        let channel = &message.channel;
        let decoder = match decoders.get(&channel.id) {
            Some(decoder) => *decoder,
            None => {
                let decoder = if carries_frames(channel) {
                    let (_, direction, description) = raw_channel(channel, known)?;
                    Some((direction, description))
                } else {
                    None
                };
                decoders.insert(channel.id, decoder);
                decoder
            }
        };
        let key = (channel.topic.clone(), channel.message_encoding.clone());
        let summary = channels.entry(key).or_insert_with(|| ChannelSummary {
            topic: channel.topic.clone(),
            encoding: channel.message_encoding.clone(),
            frames: decoder.is_some(),
            count: 0,
            span_ns: (message.log_time, message.log_time),
            rate_hz: 0.0,
            max_gap_ns: 0,
            out_of_order: 0,
            decode_errors: 0,
        });
        let last = summary.span_ns.1;
        if summary.count > 0 {
            if message.log_time < last {
                summary.out_of_order += 1;
            } else {
                summary.max_gap_ns = summary.max_gap_ns.max(message.log_time - last);
            }
        }
        summary.span_ns.1 = summary.span_ns.1.max(message.log_time);
        summary.count += 1;
        if let Some((direction, description)) = decoder
            && description.decode(direction, &message.data).is_err()
        {
            summary.decode_errors += 1;
        }
    }
    let metadata = read_metadata(capture);
    let channels = channels
        .into_values()
        .map(|mut c| {
            let span_s = (c.span_ns.1 - c.span_ns.0) as f64 / 1e9;
            c.rate_hz = if span_s > 0.0 { (c.count - 1) as f64 / span_s } else { 0.0 };
            c
        })
        .collect();
    Ok(CaptureSummary { metadata, channels })
}

/// The `robowire` metadata record, read through the summary section's index. An index whose
/// range is not inside the file is skipped (`mcap::read::metadata` adds offset and length
/// unchecked, and panics on their overflow), and so is one that does not point at a metadata
/// record the framing check walked (the reader parses whatever bytes are there, and sizes its
/// strings by them: 2 GiB from a 32 KiB file).
fn read_metadata(capture: &[u8]) -> BTreeMap<String, String> {
    let Ok(Some(summary)) = mcap::Summary::read(capture) else { return BTreeMap::new() };
    let inside = |index: &mcap::records::MetadataIndex| {
        index.offset.checked_add(index.length).is_some_and(|end| end <= capture.len() as u64)
            && usize::try_from(index.offset).is_ok_and(|offset| {
                capture.get(offset) == Some(&0x0C) && crate::framing::record_starts_at(capture, offset)
            })
    };
    summary
        .metadata_indexes
        .iter()
        .filter(|index| index.name == "robowire" && inside(index))
        .find_map(|index| mcap::read::metadata(capture, index).ok())
        .map(|m| m.metadata)
        .unwrap_or_default()
}
