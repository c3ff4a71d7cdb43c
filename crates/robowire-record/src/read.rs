//! Reading a capture back: its frames for replay, its summary for `robowire decode --mcap`.

use std::collections::BTreeMap;

use robowire_tap::Direction;

use crate::RAW_ENCODING;
use crate::protocol::Protocol;

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
    /// A raw channel whose metadata names no direction or protocol robowire knows.
    #[error("channel {topic}: {reason}")]
    Channel {
        /// The channel's topic.
        topic: String,
        /// What is wrong.
        reason: String,
    },
}

/// One frame as recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordedFrame {
    /// The link's name (`dog/high_level`).
    pub link: String,
    /// Sent or received, from the recording side.
    pub direction: Direction,
    /// What it carries.
    pub protocol: Protocol,
    /// When, ns since the Unix epoch.
    pub unix_ns: u64,
    /// The bytes as on the wire.
    pub bytes: Vec<u8>,
}

fn mcap_error(len: usize) -> impl Fn(mcap::McapError) -> ReadError {
    move |source| ReadError::Mcap { len, source }
}

/// Refuses a file whose framing is broken (see [`crate::framing`]).
fn validate(capture: &[u8]) -> Result<(), ReadError> {
    crate::framing::check(capture).map_err(|b| ReadError::Corrupt { offset: b.offset, expected: b.expected })
}

/// The raw frames of a capture, in file order (time order per link).
pub fn read_frames(capture: &[u8]) -> Result<Vec<RecordedFrame>, ReadError> {
    validate(capture)?;
    let mut frames = Vec::new();
    for message in mcap::MessageStream::new(capture).map_err(mcap_error(capture.len()))? {
        let message = message.map_err(mcap_error(capture.len()))?;
        let channel = &message.channel;
        if channel.message_encoding != RAW_ENCODING {
            continue;
        }
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
                return Err(ReadError::Channel {
                    topic: channel.topic.clone(),
                    reason: format!("direction {other:?}"),
                });
            }
        };
        let protocol = Protocol::from_name(field("protocol")?).ok_or_else(|| ReadError::Channel {
            topic: channel.topic.clone(),
            reason: format!("unknown protocol {:?}", channel.metadata.get("protocol")),
        })?;
        frames.push(RecordedFrame {
            link: field("link")?.clone(),
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
    /// Its message encoding (`robowire.raw`, `json`).
    pub encoding: String,
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
    /// Raw frames that do not decode as their protocol.
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

/// Channels, counts, rates, gaps and decode errors of a capture.
pub fn summarize(capture: &[u8]) -> Result<CaptureSummary, ReadError> {
    validate(capture)?;
    let mut channels: BTreeMap<(String, String), ChannelSummary> = BTreeMap::new();
    // Each raw channel's protocol, by channel id: a topic may have channels of several.
    let mut protocols: BTreeMap<u16, Option<Protocol>> = BTreeMap::new();
    for message in mcap::MessageStream::new(capture).map_err(mcap_error(capture.len()))? {
        let message = message.map_err(mcap_error(capture.len()))?;
        let channel = &message.channel;
        let protocol = *protocols.entry(channel.id).or_insert_with(|| {
            (channel.message_encoding == RAW_ENCODING)
                .then(|| channel.metadata.get("protocol").and_then(|p| Protocol::from_name(p)))
                .flatten()
        });
        let key = (channel.topic.clone(), channel.message_encoding.clone());
        let summary = channels.entry(key).or_insert_with(|| ChannelSummary {
            topic: channel.topic.clone(),
            encoding: channel.message_encoding.clone(),
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
        if let Some(protocol) = protocol
            && protocol.decode(&message.data).is_err()
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
/// unchecked, and panics on their overflow).
fn read_metadata(capture: &[u8]) -> BTreeMap<String, String> {
    let Ok(Some(summary)) = mcap::Summary::read(capture) else { return BTreeMap::new() };
    let inside = |index: &mcap::records::MetadataIndex| {
        index.offset.checked_add(index.length).is_some_and(|end| end <= capture.len() as u64)
    };
    summary
        .metadata_indexes
        .iter()
        .filter(|index| index.name == "robowire" && inside(index))
        .find_map(|index| mcap::read::metadata(capture, index).ok())
        .map(|m| m.metadata)
        .unwrap_or_default()
}
