//! JSON (and any serde format) with the IDL field names and nesting (feature `serde`): what
//! `robowire decode … --json` prints and `robowire encode …` reads, and the shape of the golden
//! vectors' `fields`. Driven by the field tables, so it cannot drift from the struct images.
//!
//! Floats are in robowire-core's one JSON form (shortest text that reads back to the same `f32`;
//! non-finite values as `"NaN"`, `"-NaN"`, `"Infinity"`, `"-Infinity"`). Deserializing checks
//! every field is present once, with the right type, range and array length; unknown fields are
//! refused; the `crc` field, if present, is ignored and the decoded message is sealed.

use core::fmt;

use robowire_core::serde_f32::F32 as Float;
use serde::de::{self, DeserializeSeed, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::ser::{Serialize, SerializeMap, SerializeSeq, Serializer};
use zerocopy::IntoBytes;

use crate::layout::{Field, Scalar, Shape, StructLayout};
use crate::{FieldValue, HgLowCmd, HgLowState, LowCmd, LowState, MAX_IMAGE_LEN, Message};

/// The struct at `base` of `image`, described by `layout`.
struct StructView<'a> {
    layout: &'static StructLayout,
    image: &'a [u8],
    base: usize,
}

impl Serialize for StructView<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        for field in self.layout.idl_fields() {
            let view = FieldView { field, image: self.image, base: self.base + field.offset };
            map.serialize_entry(field.name, &view)?;
        }
        map.end()
    }
}

/// A field (one element, or an array) at `base`.
struct FieldView<'a> {
    field: &'static Field,
    image: &'a [u8],
    base: usize,
}

impl FieldView<'_> {
    fn element<S: Serializer>(&self, i: usize, s: S) -> Result<S::Ok, S::Error> {
        let at = self.base + i * self.field.stride();
        match self.field.shape {
            Shape::Scalar(scalar) => {
                let bytes = self.image.get(at..at + scalar.size()).unwrap_or_default();
                FieldValue::from_le_bytes(scalar, bytes).serialize(s)
            }
            Shape::Struct(layout) => StructView { layout, image: self.image, base: at }.serialize(s),
            Shape::Pad => s.serialize_unit(),
        }
    }
}

/// A value as its IDL type: an integer, or a float in robowire-core's one JSON form.
impl Serialize for FieldValue {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            Self::U8(v) => s.serialize_u8(v),
            Self::U16(v) => s.serialize_u16(v),
            Self::I16(v) => s.serialize_i16(v),
            Self::U32(v) => s.serialize_u32(v),
            Self::I32(v) => s.serialize_i32(v),
            Self::F32(v) => Float(v).serialize(s),
        }
    }
}

/// Element `i` of a field, for array serialization.
struct ElementView<'a, 'b>(&'b FieldView<'a>, usize);

impl Serialize for ElementView<'_, '_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.element(self.1, s)
    }
}

impl Serialize for FieldView<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.field.count {
            None => self.element(0, s),
            Some(n) => {
                let mut seq = s.serialize_seq(Some(n))?;
                for i in 0..n {
                    seq.serialize_element(&ElementView(self, i))?;
                }
                seq.end()
            }
        }
    }
}

/// Where in the message a value is (`motor_cmd[3].mode`), for errors; a chain on the stack.
#[derive(Clone, Copy)]
struct Path<'p> {
    parent: Option<&'p Path<'p>>,
    segment: Segment,
}

#[derive(Clone, Copy)]
enum Segment {
    Root,
    Field(&'static str),
    Index(usize),
}

impl<'p> Path<'p> {
    const ROOT: Path<'static> = Path { parent: None, segment: Segment::Root };

    fn field(&'p self, name: &'static str) -> Path<'p> {
        Path { parent: Some(self), segment: Segment::Field(name) }
    }

    fn index(&'p self, i: usize) -> Path<'p> {
        Path { parent: Some(self), segment: Segment::Index(i) }
    }
}

impl fmt::Display for Path<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(parent) = self.parent {
            parent.fmt(f)?;
        }
        match self.segment {
            Segment::Root => Ok(()),
            Segment::Field(name) if matches!(self.parent.map(|p| p.segment), Some(Segment::Root) | None) => {
                f.write_str(name)
            }
            Segment::Field(name) => write!(f, ".{name}"),
            Segment::Index(i) => write!(f, "[{i}]"),
        }
    }
}

/// Where a value goes: the image, the offset in it, the path to it.
struct At<'a, 'p> {
    image: &'a mut [u8],
    offset: usize,
    path: Path<'p>,
}

/// Reads the struct at an offset of the image from a map.
struct StructSeed<'a, 'p> {
    layout: &'static StructLayout,
    at: At<'a, 'p>,
}

impl<'de> DeserializeSeed<'de> for StructSeed<'_, '_> {
    type Value = ();
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for StructSeed<'_, '_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "an object with the fields of {}", self.layout.name)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        // The message itself ignores its `crc`: the encoder writes it.
        let top_level = self.at.path.parent.is_none();
        let mut seen = 0u64;
        while let Some(index) = map.next_key_seed(KeySeed { layout: self.layout, path: self.at.path })? {
            let field = &self.layout.fields[index];
            let path = self.at.path.field(field.name);
            if seen & (1 << index) != 0 {
                return Err(de::Error::custom(format_args!("{path}: given twice")));
            }
            seen |= 1 << index;
            if top_level && field.name == "crc" {
                map.next_value::<IgnoredAny>()?;
                continue;
            }
            let at = At { image: &mut *self.at.image, offset: self.at.offset + field.offset, path };
            map.next_value_seed(FieldSeed { field, at })?;
        }
        for (index, field) in self.layout.fields.iter().enumerate() {
            let optional = field.is_padding() || (top_level && field.name == "crc");
            if !optional && seen & (1 << index) == 0 {
                return Err(de::Error::custom(format_args!("{}: missing", self.at.path.field(field.name))));
            }
        }
        Ok(())
    }
}

/// A map key: the index of the IDL field it names.
struct KeySeed<'p> {
    layout: &'static StructLayout,
    path: Path<'p>,
}

impl<'de> DeserializeSeed<'de> for KeySeed<'_> {
    type Value = usize;
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<usize, D::Error> {
        d.deserialize_str(self)
    }
}

impl Visitor<'_> for KeySeed<'_> {
    type Value = usize;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a field name of {}", self.layout.name)
    }

    fn visit_str<E: de::Error>(self, key: &str) -> Result<usize, E> {
        self.layout.fields.iter().position(|f| !f.is_padding() && f.name == key).ok_or_else(|| {
            let at = if self.path.parent.is_none() { "" } else { "." };
            E::custom(format_args!("{}{at}{key}: no such field in {}", self.path, self.layout.name))
        })
    }
}

/// Reads a field (one element, or an array of exactly its length).
struct FieldSeed<'a, 'p> {
    field: &'static Field,
    at: At<'a, 'p>,
}

impl<'de> DeserializeSeed<'de> for FieldSeed<'_, '_> {
    type Value = ();
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        if self.field.count.is_some() {
            return d.deserialize_seq(self);
        }
        ElementSeed { field: self.field, at: self.at }.deserialize(d)
    }
}

impl<'de> Visitor<'de> for FieldSeed<'_, '_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "an array of {} elements", self.field.len())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let n = self.field.len();
        let path = self.at.path;
        let wrong_length =
            |found: &dyn fmt::Display| de::Error::custom(format_args!("{path}: expected {n} elements, found {found}"));
        for i in 0..n {
            let offset = self.at.offset + i * self.field.stride();
            let at = At { image: &mut *self.at.image, offset, path: path.index(i) };
            let element = ElementSeed { field: self.field, at };
            if seq.next_element_seed(element)?.is_none() {
                return Err(wrong_length(&i));
            }
        }
        if seq.next_element::<IgnoredAny>()?.is_some() {
            return Err(wrong_length(&format_args!("more")));
        }
        Ok(())
    }
}

/// Reads one element of a field into the image.
struct ElementSeed<'a, 'p> {
    field: &'static Field,
    at: At<'a, 'p>,
}

impl<'de> DeserializeSeed<'de> for ElementSeed<'_, '_> {
    type Value = ();
    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        let scalar = match self.field.shape {
            Shape::Struct(layout) => return StructSeed { layout, at: self.at }.deserialize(d),
            Shape::Pad => return Ok(()),
            Shape::Scalar(scalar) => scalar,
        };
        let At { image, offset, path } = self.at;
        let value = d.deserialize_any(ScalarVisitor { scalar, path })?;
        if let Some(dst) = image.get_mut(offset..offset + scalar.size()) {
            value.write_le_bytes(dst);
        }
        Ok(())
    }
}

/// A scalar, range-checked.
struct ScalarVisitor<'p> {
    scalar: Scalar,
    path: Path<'p>,
}

impl ScalarVisitor<'_> {
    fn integer<E: de::Error>(self, v: i128) -> Result<FieldValue, E> {
        if self.scalar == Scalar::F32 {
            return Ok(FieldValue::F32(v as f32));
        }
        let value = i64::try_from(v).ok().and_then(|v| FieldValue::from_i64(self.scalar, v).ok());
        value.ok_or_else(|| E::custom(format_args!("{}: {v} does not fit {}", self.path, self.scalar.idl_name())))
    }

    fn wrong_type<E: de::Error>(&self, found: &dyn fmt::Display) -> E {
        let expected = if self.scalar == Scalar::F32 { "a number" } else { "an integer" };
        E::custom(format_args!("{}: expected {expected} ({}), found {found}", self.path, self.scalar.idl_name()))
    }
}

impl Visitor<'_> for ScalarVisitor<'_> {
    type Value = FieldValue;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "a {} for {}", self.scalar.idl_name(), self.path)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<FieldValue, E> {
        self.integer(i128::from(v))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<FieldValue, E> {
        self.integer(i128::from(v))
    }

    // The exact f32 written as f64 converts back exactly; other numbers round to nearest.
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<FieldValue, E> {
        FieldValue::from_f64(self.scalar, v).map_err(|_| self.wrong_type(&v))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<FieldValue, E> {
        match robowire_core::serde_f32::from_non_finite_name(v) {
            Some(f) if self.scalar == Scalar::F32 => Ok(FieldValue::F32(f)),
            _ => Err(self.wrong_type(&format_args!("{v:?}"))),
        }
    }

    fn visit_bool<E: de::Error>(self, v: bool) -> Result<FieldValue, E> {
        Err(self.wrong_type(&v))
    }
}

/// The sealed message a serde value describes.
fn deserialize_message<'de, M: Message, D: de::Deserializer<'de>>(d: D) -> Result<M, D::Error> {
    let mut image = [0u8; MAX_IMAGE_LEN];
    let image = &mut image[..M::IMAGE_LEN];
    StructSeed { layout: M::FIELDS, at: At { image: &mut *image, offset: 0, path: Path::ROOT } }.deserialize(d)?;
    let mut message = M::new_zeroed();
    message.as_mut_bytes().copy_from_slice(image);
    message.seal();
    Ok(message)
}

macro_rules! serde_message {
    ($($ty:ty),*) => {$(
        /// The message as an object with the IDL field names, `crc` included.
        impl Serialize for $ty {
            fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                StructView { layout: <$ty as Message>::FIELDS, image: self.as_bytes(), base: 0 }.serialize(s)
            }
        }

        /// The sealed message an object with the IDL field names describes (`crc` ignored).
        impl<'de> de::Deserialize<'de> for $ty {
            fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                deserialize_message(d)
            }
        }
    )*};
}

serde_message!(LowCmd, LowState, HgLowCmd, HgLowState);
