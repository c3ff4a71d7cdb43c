//! JSON with the IDL field names and nesting (feature `json`): what `robowire decode … --json`
//! prints and `robowire encode …` reads, and the shape of the golden vectors' `fields`.
//!
//! Floats are numbers holding the exact f32 value (written as the f64 of it, so reading back is
//! exact); non-finite floats are the strings `"NaN"` (bits `0x7fc00000`), `"-NaN"`
//! (`0xffc00000`), `"Infinity"`, `"-Infinity"`. Another NaN payload reads back as the quiet NaN
//! of its sign: JSON has no way to say more.

use serde_json::{Map, Number, Value};

use crate::Message;
use crate::layout::{Scalar, Shape, StructLayout};

/// Why a JSON value is not a message.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum JsonError {
    /// A field is missing.
    #[error("{path}: missing")]
    Missing {
        /// Where, e.g. `motor_cmd[3].q`.
        path: String,
    },
    /// A key that is no field of the message.
    #[error("{path}: no such field")]
    Unknown {
        /// Where.
        path: String,
    },
    /// A value of the wrong JSON type.
    #[error("{path}: expected {expected}")]
    Type {
        /// Where.
        path: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A number outside its field's type.
    #[error("{path}: {value} does not fit {ty}")]
    Range {
        /// Where.
        path: String,
        /// The value.
        value: String,
        /// The IDL type.
        ty: &'static str,
    },
    /// An array of the wrong length.
    #[error("{path}: expected {expected} elements, found {found}")]
    Length {
        /// Where.
        path: String,
        /// Elements the field has.
        expected: usize,
        /// Elements given.
        found: usize,
    },
}

/// The message as a JSON object, `crc` included.
pub fn to_json<M: Message>(message: &M) -> Value {
    struct_to_json(M::FIELDS, message.as_bytes(), 0)
}

/// The sealed message a JSON object describes; its `crc` field, if present, is ignored.
pub fn from_json<M: Message>(value: &Value) -> Result<M, JsonError> {
    let mut image = vec![0u8; M::IMAGE_LEN];
    struct_from_json(M::FIELDS, value, &mut image, 0, "", true)?;
    let mut message = M::read_from_bytes(&image).map_err(|_| JsonError::Length {
        path: String::new(),
        expected: M::IMAGE_LEN,
        found: image.len(),
    })?;
    message.seal();
    Ok(message)
}

fn struct_to_json(layout: &StructLayout, image: &[u8], base: usize) -> Value {
    let mut object = Map::new();
    for field in layout.fields {
        let at = |i: usize| base + field.offset + i * field.stride();
        let element = |i: usize| match field.shape {
            Shape::Scalar(s) => scalar_to_json(s, &image[at(i)..at(i) + s.size()]),
            Shape::Struct(sub) => struct_to_json(sub, image, at(i)),
        };
        let value = match field.count {
            None => element(0),
            Some(n) => Value::Array((0..n).map(element).collect()),
        };
        object.insert(field.name.to_string(), value);
    }
    Value::Object(object)
}

fn scalar_to_json(scalar: Scalar, b: &[u8]) -> Value {
    match scalar {
        Scalar::U8 => Value::from(b[0]),
        Scalar::U16 => Value::from(u16::from_le_bytes([b[0], b[1]])),
        Scalar::I16 => Value::from(i16::from_le_bytes([b[0], b[1]])),
        Scalar::U32 => Value::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        Scalar::I32 => Value::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        Scalar::F32 => f32_to_json(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    }
}

fn f32_to_json(v: f32) -> Value {
    match Number::from_f64(f64::from(v)) {
        Some(n) => Value::Number(n),
        None if v.is_nan() => Value::from(if v.is_sign_negative() { "-NaN" } else { "NaN" }),
        None => Value::from(if v > 0.0 { "Infinity" } else { "-Infinity" }),
    }
}

fn struct_from_json(
    layout: &StructLayout,
    value: &Value,
    image: &mut [u8],
    base: usize,
    path: &str,
    top_level: bool,
) -> Result<(), JsonError> {
    let join = |name: &str| if path.is_empty() { name.to_string() } else { format!("{path}.{name}") };
    let object = value.as_object().ok_or_else(|| JsonError::Type { path: path.to_string(), expected: "an object" })?;
    if let Some(unknown) = object.keys().find(|k| !layout.fields.iter().any(|f| f.name == k.as_str())) {
        return Err(JsonError::Unknown { path: join(unknown) });
    }
    for field in layout.fields {
        // The crc is the encoder's to write.
        if top_level && field.name == "crc" {
            continue;
        }
        let field_path = join(field.name);
        let v = object.get(field.name).ok_or_else(|| JsonError::Missing { path: field_path.clone() })?;
        let elements: Vec<(&Value, String)> = match field.count {
            None => vec![(v, field_path.clone())],
            Some(n) => {
                let array =
                    v.as_array().ok_or_else(|| JsonError::Type { path: field_path.clone(), expected: "an array" })?;
                if array.len() != n {
                    return Err(JsonError::Length { path: field_path, expected: n, found: array.len() });
                }
                array.iter().enumerate().map(|(i, e)| (e, format!("{field_path}[{i}]"))).collect()
            }
        };
        for (i, (element, element_path)) in elements.into_iter().enumerate() {
            let at = base + field.offset + i * field.stride();
            match field.shape {
                Shape::Scalar(s) => {
                    let bytes = scalar_from_json(s, element, &element_path)?;
                    image[at..at + s.size()].copy_from_slice(&bytes[..s.size()]);
                }
                Shape::Struct(sub) => struct_from_json(sub, element, image, at, &element_path, false)?,
            }
        }
    }
    Ok(())
}

/// The little-endian bytes of `value` as `scalar` (first `scalar.size()` bytes used).
fn scalar_from_json(scalar: Scalar, value: &Value, path: &str) -> Result<[u8; 4], JsonError> {
    let range = |ty| JsonError::Range { path: path.to_string(), value: value.to_string(), ty };
    let integer = |ty| {
        value.as_i64().or_else(|| value.as_u64().and_then(|u| i64::try_from(u).ok())).ok_or_else(|| {
            if value.is_number() {
                range(ty)
            } else {
                JsonError::Type { path: path.to_string(), expected: "an integer" }
            }
        })
    };
    let widen2 = |b: [u8; 2]| [b[0], b[1], 0, 0];
    Ok(match scalar {
        Scalar::U8 => [u8::try_from(integer("uint8")?).map_err(|_| range("uint8"))?, 0, 0, 0],
        Scalar::U16 => widen2(u16::try_from(integer("uint16")?).map_err(|_| range("uint16"))?.to_le_bytes()),
        Scalar::I16 => widen2(i16::try_from(integer("int16")?).map_err(|_| range("int16"))?.to_le_bytes()),
        Scalar::U32 => u32::try_from(integer("uint32")?).map_err(|_| range("uint32"))?.to_le_bytes(),
        Scalar::I32 => i32::try_from(integer("int32")?).map_err(|_| range("int32"))?.to_le_bytes(),
        Scalar::F32 => f32_from_json(value, path)?.to_le_bytes(),
    })
}

fn f32_from_json(value: &Value, path: &str) -> Result<f32, JsonError> {
    match value {
        // The exact f32 written as f64 converts back exactly; other numbers round to nearest.
        Value::Number(n) => {
            n.as_f64().map(|v| v as f32).ok_or_else(|| JsonError::Type { path: path.to_string(), expected: "a number" })
        }
        Value::String(s) => match s.as_str() {
            "NaN" => Ok(f32::from_bits(0x7fc0_0000)),
            "-NaN" => Ok(f32::from_bits(0xffc0_0000)),
            "Infinity" => Ok(f32::INFINITY),
            "-Infinity" => Ok(f32::NEG_INFINITY),
            _ => {
                Err(JsonError::Type { path: path.to_string(), expected: "a number, NaN, -NaN, Infinity or -Infinity" })
            }
        },
        _ => Err(JsonError::Type { path: path.to_string(), expected: "a number" }),
    }
}
