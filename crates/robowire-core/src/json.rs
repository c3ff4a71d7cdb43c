//! A link described to a recorder (feature `json`, needs an allocator): what its protocol is
//! called, which layout its frames follow, and how one of its frames reads as JSON, with a JSON
//! schema. Each codec crate describes its links behind its `serde` feature; an application
//! registers the descriptions it knows with a recorder, which holds them as
//! `&'static dyn LinkDescription` and knows no device. A codec declares each link as a
//! [`LinkProtocol`] (name, layout, decode function); the example implements the trait itself.
//!
//! ```
//! use robowire_core::Direction;
//! use robowire_core::json::serde_json::json;
//! use robowire_core::json::{FrameError, JsonFrame, LinkDescription};
//!
//! /// A toy link: every frame is one byte, a count.
//! #[derive(Debug)]
//! struct Counter;
//!
//! #[derive(Debug, thiserror::Error)]
//! #[error("a count is one byte")]
//! struct NotOneByte;
//!
//! impl LinkDescription for Counter {
//!     fn protocol(&self) -> &'static str {
//!         "toy.counter"
//!     }
//!     fn layout(&self) -> &'static str {
//!         "one byte"
//!     }
//!     fn decode(&self, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
//!         let [count] = frame else { return Err(FrameError::decode(self.protocol(), frame, NotOneByte)) };
//!         Ok(JsonFrame { schema: "toy.Count", value: json!({ "count": count }) })
//!     }
//! }
//!
//! let link: &'static dyn LinkDescription = &Counter;
//! let frame = link.decode(Direction::Received, &[7]).unwrap();
//! assert_eq!(link.schema(&frame)["title"], "toy.Count");
//! assert_eq!((frame.schema, frame.value), ("toy.Count", json!({ "count": 7 })));
//! let error = link.decode(Direction::Received, &[1, 2]).unwrap_err();
//! assert_eq!(error.to_string(), "2 bytes are not a toy.counter frame");
//! ```

extern crate alloc;

use alloc::boxed::Box;
use core::error::Error;

pub use serde_json::{self, Value};
use serde_json::{Map, json};

use crate::Direction;

/// How the frames of one kind of link read as JSON. Object-safe: recorders hold
/// `&'static dyn LinkDescription`.
pub trait LinkDescription: core::fmt::Debug + Send + Sync {
    /// The protocol's name, as a capture's metadata records it (`zsl1.high_level`); unique
    /// among the descriptions an application registers.
    fn protocol(&self) -> &'static str;

    /// The layout the frames follow, the spec they were checked against
    /// (`zsl1-udp, vendor SDK v0.2.7`).
    fn layout(&self) -> &'static str;

    /// `frame`, which went `direction` as seen from the recording end of the link, as JSON
    /// under its schema name; a typed error, never a panic, for any bytes.
    fn decode(&self, direction: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError>;

    /// The JSON schema of the messages named `frame.schema`, given the first of them. By
    /// default derived from its structure ([`schema_of`]).
    fn schema(&self, frame: &JsonFrame) -> Value {
        schema_of(frame.schema, &frame.value)
    }

    /// The standard encoding `frame` already is as it travels (a DDS payload is `cdr`), with its
    /// schema, for frames that MCAP readers decode as they are; a recorder then writes them once,
    /// under that encoding, instead of raw bytes beside JSON. `None` (the default): the frames are
    /// the protocol's own bytes.
    fn wire_schema(&self, direction: Direction, frame: &[u8]) -> Option<WireSchema> {
        let _ = (direction, frame);
        None
    }
}

/// A message encoding that MCAP readers (Foxglove, `ros2 bag`) decode without a plugin, and its
/// schema, by the names of MCAP's registry of well-known encodings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WireSchema {
    /// The message encoding (`cdr`).
    pub encoding: &'static str,
    /// The schema's name: the fully qualified type (`unitree_go::msg::dds_::LowState_`).
    pub name: &'static str,
    /// The schema's encoding (`omgidl`, `ros2msg`).
    pub schema_encoding: &'static str,
    /// The schema itself, self-contained.
    pub text: &'static str,
}

/// [`LinkDescription::wire_schema`] as a function.
pub type WireSchemaOf = fn(direction: Direction, frame: &[u8]) -> Option<WireSchema>;

/// A [`LinkDescription`] from its parts: what each codec declares its links with.
#[derive(Debug, Clone, Copy)]
pub struct LinkProtocol {
    /// The protocol's name ([`LinkDescription::protocol`]).
    pub name: &'static str,
    /// The layout its frames follow ([`LinkDescription::layout`]).
    pub layout: &'static str,
    /// [`LinkDescription::decode`], given the protocol's name for its errors.
    pub decode: fn(name: &'static str, direction: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError>,
    /// [`LinkDescription::wire_schema`]; `None` for a protocol of its own bytes.
    pub wire_schema: Option<WireSchemaOf>,
}

impl LinkDescription for LinkProtocol {
    fn protocol(&self) -> &'static str {
        self.name
    }

    fn layout(&self) -> &'static str {
        self.layout
    }

    fn decode(&self, direction: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
        (self.decode)(self.name, direction, frame)
    }

    fn wire_schema(&self, direction: Direction, frame: &[u8]) -> Option<WireSchema> {
        self.wire_schema.and_then(|wire| wire(direction, frame))
    }
}

/// The bytes a stream decoder skipped while looking for frames (line noise, broken or rejected
/// frames), recorded beside a serial link's frames: as JSON, their count and hex.
pub static SKIPPED_BYTES: LinkProtocol = LinkProtocol {
    name: "stream.skipped",
    layout: "bytes a stream decoder skipped between frames, as they were on the line",
    decode: |_, _, bytes| {
        let hex: alloc::string::String = bytes.iter().map(|b| alloc::format!("{b:02x}")).collect();
        Ok(JsonFrame { schema: "robowire.SkippedBytes", value: json!({ "len": bytes.len(), "hex": hex }) })
    },
    wire_schema: None,
};

/// What to plot of one protocol's frames (`robowire plot`), as its codec describes it: panels of
/// series, each a number read from the frames' JSON.
#[derive(Debug, Clone, Copy)]
pub struct LinkPlots {
    /// The protocol ([`LinkDescription::protocol`]).
    pub protocol: &'static str,
    /// Its panels, top to bottom.
    pub panels: &'static [PanelSpec],
}

/// One panel: the series drawn against one y axis.
#[derive(Debug, Clone, Copy)]
pub struct PanelSpec {
    /// What it shows (`forward velocity`).
    pub title: &'static str,
    /// The y axis, with its unit (`velocity (m/s)`).
    pub y_label: &'static str,
    /// Its series.
    pub series: &'static [SeriesSpec],
}

/// One series: a number in each frame of one message type, one way.
#[derive(Debug, Clone, Copy)]
pub struct SeriesSpec {
    /// Its legend (`commanded`, `observed`).
    pub name: &'static str,
    /// The frames' direction, from the recording end.
    pub direction: Direction,
    /// The frames' JSON schema name ([`JsonFrame::schema`]).
    pub schema: &'static str,
    /// Where the number is in the frame's JSON: a JSON pointer (RFC 6901, `/motor_cmd/0/q`).
    pub pointer: &'static str,
    /// A command held until the next (drawn as steps), not a sample.
    pub held: bool,
    /// Values outside this range are not drawn (a protocol's "no target" marker, such as
    /// Unitree's 2.146e9).
    pub range: (f64, f64),
}

/// [`SeriesSpec::range`] for a series whose every finite value is drawn.
pub const ANY_VALUE: (f64, f64) = (-1e300, 1e300);

impl SeriesSpec {
    /// The series' value in `frame` (a message of its schema), if it is a number in range.
    pub fn value(&self, frame: &JsonFrame) -> Option<f64> {
        if frame.schema != self.schema {
            return None;
        }
        let value = frame.value.pointer(self.pointer)?.as_f64()?;
        (self.range.0..=self.range.1).contains(&value).then_some(value)
    }
}

/// A frame as JSON.
#[derive(Debug, Clone, PartialEq)]
pub struct JsonFrame {
    /// The message's schema name (`zsl1.HighLevelState`).
    pub schema: &'static str,
    /// The message.
    pub value: Value,
}

impl JsonFrame {
    /// `frame` read by the codec's `parse`, as JSON under the schema name `schema` gives the
    /// message; the codec's error is a [`FrameError::Decode`] of `protocol`.
    pub fn parse<M: serde::Serialize, E: Error + Send + Sync + 'static>(
        protocol: &'static str,
        frame: &[u8],
        parse: impl FnOnce(&[u8]) -> Result<M, E>,
        schema: impl FnOnce(&M) -> &'static str,
    ) -> Result<Self, FrameError> {
        let message = parse(frame).map_err(|e| FrameError::decode(protocol, frame, e))?;
        Self::serialize(protocol, schema(&message), &message)
    }

    /// `message` as JSON under `schema`; a serializer's failure is a [`FrameError::Json`] of
    /// `protocol`.
    pub fn serialize<T: serde::Serialize + ?Sized>(
        protocol: &'static str,
        schema: &'static str,
        message: &T,
    ) -> Result<Self, FrameError> {
        let value = serde_json::to_value(message).map_err(|source| FrameError::Json { protocol, schema, source })?;
        Ok(Self { schema, value })
    }
}

/// Why a frame has no JSON form.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FrameError {
    /// The bytes are not a frame of the protocol; the codec's error says why.
    #[error("{len} bytes are not a {protocol} frame")]
    Decode {
        /// The link's protocol.
        protocol: &'static str,
        /// The frame's length, bytes.
        len: usize,
        /// The codec's error.
        #[source]
        source: Box<dyn Error + Send + Sync>,
    },
    /// The frame decoded, but its JSON could not be made.
    #[error("a {schema} frame of {protocol} has no JSON form")]
    Json {
        /// The link's protocol.
        protocol: &'static str,
        /// The message's schema name.
        schema: &'static str,
        /// The serializer's error.
        #[source]
        source: serde_json::Error,
    },
}

impl FrameError {
    /// `frame` is not a frame of `protocol`, for the reason `source`.
    pub fn decode(protocol: &'static str, frame: &[u8], source: impl Error + Send + Sync + 'static) -> Self {
        Self::Decode { protocol, len: frame.len(), source: Box::new(source) }
    }
}

/// The JSON schema (draft 2020-12) of values shaped like `value`, titled `title`: every field
/// with its type, nested objects and arrays described the same way (an array by its first
/// element). What Foxglove needs to list and plot the fields.
pub fn schema_of(title: &str, value: &Value) -> Value {
    let mut schema = describe(value);
    if let Value::Object(map) = &mut schema {
        map.insert("$schema".into(), json!("https://json-schema.org/draft/2020-12/schema"));
        map.insert("title".into(), json!(title));
    }
    schema
}

fn describe(value: &Value) -> Value {
    match value {
        Value::Null => json!({ "type": "null" }),
        Value::Bool(_) => json!({ "type": "boolean" }),
        Value::Number(n) if n.is_f64() => json!({ "type": "number" }),
        Value::Number(_) => json!({ "type": "integer" }),
        Value::String(_) => json!({ "type": "string" }),
        Value::Array(items) => match items.first() {
            Some(first) => json!({ "type": "array", "items": describe(first) }),
            None => json!({ "type": "array" }),
        },
        Value::Object(fields) => {
            let properties: Map<_, Value> = fields.iter().map(|(k, v)| (k.clone(), describe(v))).collect();
            json!({ "type": "object", "properties": properties })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_nested_objects_and_arrays_are_described() {
        let schema = schema_of("t", &json!({"mode": 18, "vx": 0.5, "legs": [[0.1, 0.2]], "ok": true, "name": "x"}));
        assert_eq!(schema["title"], "t");
        assert_eq!(schema["properties"]["mode"]["type"], "integer");
        assert_eq!(schema["properties"]["vx"]["type"], "number");
        assert_eq!(schema["properties"]["legs"]["items"]["items"]["type"], "number");
        assert_eq!(schema["properties"]["ok"]["type"], "boolean");
        assert_eq!(schema["properties"]["name"]["type"], "string");
    }
}
