//! The capture's channels and schemas, made on first use: for each link (by number), direction
//! and writer, the channel of its frames (raw, or per wire schema) and one JSON channel per
//! message type. Looked up by index, not by hashing, on the writer's per-frame path.

use std::collections::{BTreeMap, HashMap};
use std::io::Write;

use mcap::McapError;
use robowire_core::json::{LinkDescription, Value, WireSchema};
use robowire_tap::Direction;

use crate::{LAYOUT_SCHEMA_ENCODING, RAW_ENCODING};

/// Which channels a frame goes to: its link (number), direction and writer.
pub(crate) type ChannelKey = (u16, Direction, Option<[u8; 16]>);

/// The channels of one link, direction and writer.
struct LinkChannels {
    direction: Direction,
    writer: Option<[u8; 16]>,
    name: String,
    description: &'static dyn LinkDescription,
    raw: Option<u16>,
    /// By wire schema name.
    wire: Vec<(&'static str, u16)>,
    /// By JSON schema name.
    json: Vec<(&'static str, u16)>,
}

/// Where a frame goes: its channel, and the description to decode it to JSON with if it went
/// raw (a wire encoding is one readers decode themselves).
pub(crate) struct FrameChannel {
    pub(crate) id: u16,
    pub(crate) json_by: Option<&'static dyn LinkDescription>,
}

/// What became of a frame.
pub(crate) enum Placed {
    /// It goes on this channel.
    On(FrameChannel),
    /// Its link number was never registered.
    UnknownLink,
    /// It is not in a wire encoding, and only those are written.
    NotWire,
}

/// Every channel and schema made so far.
#[derive(Default)]
pub(crate) struct Channels {
    /// By link number, then direction and writer.
    links: Vec<Vec<LinkChannels>>,
    /// Schema ids by (encoding, name).
    schemas: HashMap<(&'static str, &'static str), u16>,
    /// Messages written per channel id, for their sequence numbers.
    sequences: Vec<u32>,
}

impl Channels {
    /// The entry of `key`, made on its first frame from `registered` (the links' names and
    /// descriptions by number); `None` for a link number no one registered.
    fn entry(
        &mut self,
        key: ChannelKey,
        registered: impl FnOnce(usize) -> Option<(String, &'static dyn LinkDescription)>,
    ) -> Option<&mut LinkChannels> {
        let link = usize::from(key.0);
        let found = self.links.get(link).and_then(|l| l.iter().position(|c| (c.direction, c.writer) == (key.1, key.2)));
        let index = match found {
            Some(index) => index,
            None => {
                let (name, description) = registered(link)?;
                if self.links.len() <= link {
                    self.links.resize_with(link + 1, Vec::new);
                }
                let entry = LinkChannels {
                    direction: key.1,
                    writer: key.2,
                    name,
                    description,
                    raw: None,
                    wire: Vec::new(),
                    json: Vec::new(),
                };
                self.links[link].push(entry);
                self.links[link].len() - 1
            }
        };
        self.links.get_mut(link)?.get_mut(index)
    }

    fn schema<W: Write + std::io::Seek>(
        &mut self,
        writer: &mut mcap::Writer<W>,
        encoding: &'static str,
        name: &'static str,
        text: &[u8],
    ) -> Result<u16, McapError> {
        if let Some(&id) = self.schemas.get(&(encoding, name)) {
            return Ok(id);
        }
        let id = writer.add_schema(name, encoding, text)?;
        self.schemas.insert((encoding, name), id);
        Ok(id)
    }

    /// The channel of `frame`, of link, direction and writer `key`: its wire encoding's if its
    /// description names one, else (unless `wire_only`) the raw channel; made on first use.
    pub(crate) fn frame_channel<W: Write + std::io::Seek>(
        &mut self,
        writer: &mut mcap::Writer<W>,
        key: ChannelKey,
        frame: &[u8],
        wire_only: bool,
        registered: impl FnOnce(usize) -> Option<(String, &'static dyn LinkDescription)>,
    ) -> Result<Placed, McapError> {
        let Some(entry) = self.entry(key, registered) else { return Ok(Placed::UnknownLink) };
        let description = entry.description;
        let wire = description.wire_schema(key.1, frame);
        if wire.is_none() && wire_only {
            return Ok(Placed::NotWire);
        }
        let known = match &wire {
            Some(wire) => entry.wire.iter().find(|(name, _)| *name == wire.name).map(|(_, id)| *id),
            None => entry.raw,
        };
        let json_by = if wire.is_some() { None } else { Some(description) };
        if let Some(id) = known {
            return Ok(Placed::On(FrameChannel { id, json_by }));
        }
        let name = entry.name.clone();
        let metadata = metadata(key, &name, Some(description));
        let id = match wire {
            Some(wire) => self.add_wire_channel(writer, key, &name, &wire, &metadata)?,
            None => {
                // The bytes' own layout, named: not a schema a reader decodes with, but every
                // channel says what its messages are.
                let (protocol, layout) = (description.protocol(), description.layout().as_bytes());
                let schema = self.schema(writer, LAYOUT_SCHEMA_ENCODING, protocol, layout)?;
                let topic = format!("/{name}/{}/raw", key.1.name());
                let id = writer.add_channel(schema, &topic, RAW_ENCODING, &metadata)?;
                if let Some(entry) = self.entry(key, |_| None) {
                    entry.raw = Some(id);
                }
                id
            }
        };
        Ok(Placed::On(FrameChannel { id, json_by }))
    }

    fn add_wire_channel<W: Write + std::io::Seek>(
        &mut self,
        writer: &mut mcap::Writer<W>,
        key: ChannelKey,
        name: &str,
        wire: &WireSchema,
        metadata: &BTreeMap<String, String>,
    ) -> Result<u16, McapError> {
        let schema = self.schema(writer, wire.schema_encoding, wire.name, wire.text.as_bytes())?;
        // A ROS 2 message goes on its ROS topic (`/kmc/odom`), as `ros2 bag` records it; its
        // direction is in the metadata.
        let topic =
            if wire.schema_encoding == "ros2msg" { format!("/{name}") } else { format!("/{name}/{}", key.1.name()) };
        let id = writer.add_channel(schema, &topic, wire.encoding, metadata)?;
        if let Some(entry) = self.entry(key, |_| None) {
            entry.wire.push((wire.name, id));
        }
        Ok(id)
    }

    /// The JSON channel of message type `schema` on `key`'s link, made on its first message with
    /// the schema `schema_text` (given with the first message of each type); `None` if the link
    /// has no frame channel yet.
    pub(crate) fn json_channel<W: Write + std::io::Seek>(
        &mut self,
        writer: &mut mcap::Writer<W>,
        key: ChannelKey,
        schema: &'static str,
        schema_text: Option<&Value>,
    ) -> Result<Option<u16>, McapError> {
        let Some(entry) = self.entry(key, |_| None) else { return Ok(None) };
        if let Some((_, id)) = entry.json.iter().find(|(name, _)| *name == schema) {
            return Ok(Some(*id));
        }
        let name = entry.name.clone();
        let text = schema_text.and_then(|t| serde_json::to_vec(t).ok());
        let schema_id = match text {
            Some(text) => self.schema(writer, "jsonschema", schema, &text)?,
            None => self.schemas.get(&("jsonschema", schema)).copied().unwrap_or(0),
        };
        let topic = format!("/{name}/{}/{schema}", key.1.name());
        let id = writer.add_channel(schema_id, &topic, "json", &metadata(key, &name, None))?;
        if let Some(entry) = self.entry(key, |_| None) {
            entry.json.push((schema, id));
        }
        Ok(Some(id))
    }

    /// The next sequence number of `channel` (1, 2, …).
    pub(crate) fn next_sequence(&mut self, channel: u16) -> u32 {
        let index = usize::from(channel);
        if self.sequences.len() <= index {
            self.sequences.resize(index + 1, 0);
        }
        let sequence = &mut self.sequences[index];
        *sequence = sequence.wrapping_add(1);
        *sequence
    }
}

/// A channel's metadata: its link, and for a channel of frames its direction and protocol (what
/// readers tell frames by); the DDS writer's GUID if known.
fn metadata(key: ChannelKey, name: &str, frames_of: Option<&dyn LinkDescription>) -> BTreeMap<String, String> {
    let mut metadata = BTreeMap::from([("link".to_string(), name.to_string())]);
    if let Some(description) = frames_of {
        metadata.insert("direction".into(), key.1.name().into());
        metadata.insert("protocol".into(), description.protocol().into());
    }
    if let Some(writer) = key.2 {
        metadata.insert("writer_guid".into(), writer.iter().map(|b| format!("{b:02x}")).collect());
    }
    metadata
}
