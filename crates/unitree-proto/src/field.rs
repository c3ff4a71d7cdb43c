//! Field access by IDL name over a message's struct image (`motor_cmd[3].q`, `imu_state.rpy[0]`,
//! `head[1]`), for the Go2 and HG messages alike, from their field tables ([`crate::layout`]).
//!
//! A [`FieldPlace`] is where a scalar, a nested struct or an array lies in an image. It is made
//! only by stepping from a message (or any struct) through its table, by IDL field name and
//! array index, each step checked, so every place lies inside its image; reading and writing
//! check the image's length, the value's type and, on conversion, its range. Nothing here
//! panics, whatever the path or the image.
//!
//! No field is read-only: `crc` is written like any other, and [`Message::seal`] (so every
//! encoder) overwrites it with the CRC of the image.
//!
//! ```
//! use unitree_proto::{FieldError, FieldValue, LowCmd, Message};
//!
//! let mut cmd = LowCmd::default();
//! cmd.set_field("motor_cmd[3].q", FieldValue::F32(0.5))?;
//! assert_eq!(cmd.motor_cmd[3].q.get(), 0.5);
//! assert_eq!(cmd.field("head[1]")?, FieldValue::U8(0xEF));
//! assert_eq!(cmd.field("motor_cmd[20].q"), Err(FieldError::IndexOutOfRange { index: 20, len: 20 }));
//! # Ok::<(), FieldError>(())
//! ```

use core::fmt;
use core::ops::Range;

use crate::Message;
use crate::layout::{Scalar, Shape, StructLayout};

/// The element type of an array.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Element {
    /// A primitive.
    Scalar(Scalar),
    /// A nested struct.
    Struct(&'static StructLayout),
}

impl Element {
    /// Bytes one element occupies in the image (its C `sizeof`).
    pub const fn size(self) -> usize {
        match self {
            Self::Scalar(scalar) => scalar.size(),
            Self::Struct(layout) => layout.size,
        }
    }

    /// The element alone, as a place's kind.
    pub const fn kind(self) -> PlaceKind {
        match self {
            Self::Scalar(scalar) => PlaceKind::Scalar(scalar),
            Self::Struct(layout) => PlaceKind::Struct(layout),
        }
    }
}

/// What lies at a [`FieldPlace`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlaceKind {
    /// One value of a primitive IDL type.
    Scalar(Scalar),
    /// A struct: a whole message, or a nested one (`MotorCmd_`, `IMUState_`, …).
    Struct(&'static StructLayout),
    /// A fixed-length array.
    Array {
        /// Its elements' type.
        element: Element,
        /// Elements.
        len: usize,
    },
}

impl PlaceKind {
    /// Bytes it occupies in the image.
    pub const fn size(self) -> usize {
        match self {
            Self::Scalar(scalar) => scalar.size(),
            Self::Struct(layout) => layout.size,
            Self::Array { element, len } => element.size() * len,
        }
    }
}

impl fmt::Display for Element {
    /// The IDL type name; a struct's with its size (the Go2 and HG `MotorCmd_` differ in it).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Scalar(scalar) => f.write_str(scalar.idl_name()),
            Self::Struct(layout) => write!(f, "{} ({} bytes)", layout.name, layout.size),
        }
    }
}

impl fmt::Display for PlaceKind {
    /// `uint8`, `MotorCmd_ (36 bytes)`, `float[3]`, `MotorCmd_ (36 bytes)[20]`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Scalar(scalar) => Element::Scalar(scalar).fmt(f),
            Self::Struct(layout) => Element::Struct(layout).fmt(f),
            Self::Array { element, len } => write!(f, "{element}[{len}]"),
        }
    }
}

/// The value of a scalar field, in its IDL type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FieldValue {
    /// `uint8` (also `octet`).
    U8(u8),
    /// `uint16`.
    U16(u16),
    /// `int16`.
    I16(i16),
    /// `uint32`.
    U32(u32),
    /// `int32`.
    I32(i32),
    /// `float`.
    F32(f32),
}

impl FieldValue {
    /// Its IDL type.
    pub const fn scalar(self) -> Scalar {
        match self {
            Self::U8(_) => Scalar::U8,
            Self::U16(_) => Scalar::U16,
            Self::I16(_) => Scalar::I16,
            Self::U32(_) => Scalar::U32,
            Self::I32(_) => Scalar::I32,
            Self::F32(_) => Scalar::F32,
        }
    }

    /// An integer as a value of `scalar`: [`FieldError::OutOfRange`] outside an integer type's
    /// range; for `float`, the nearest `f32`.
    pub fn from_i64(scalar: Scalar, value: i64) -> Result<Self, FieldError> {
        let range = |min: i64, max: i64| FieldError::OutOfRange { scalar, value, min, max };
        match scalar {
            Scalar::U8 => u8::try_from(value).map(Self::U8).map_err(|_| range(0, u8::MAX.into())),
            Scalar::U16 => u16::try_from(value).map(Self::U16).map_err(|_| range(0, u16::MAX.into())),
            Scalar::I16 => i16::try_from(value).map(Self::I16).map_err(|_| range(i16::MIN.into(), i16::MAX.into())),
            Scalar::U32 => u32::try_from(value).map(Self::U32).map_err(|_| range(0, u32::MAX.into())),
            Scalar::I32 => i32::try_from(value).map(Self::I32).map_err(|_| range(i32::MIN.into(), i32::MAX.into())),
            Scalar::F32 => Ok(Self::F32(value as f32)),
        }
    }

    /// A float as a value of `scalar`: for `float` the nearest `f32` (NaN and the infinities
    /// kept: the codec carries them, a command check refuses them); an integer type takes no
    /// float ([`FieldError::WrongType`]).
    pub fn from_f64(scalar: Scalar, value: f64) -> Result<Self, FieldError> {
        match scalar {
            Scalar::F32 => Ok(Self::F32(value as f32)),
            _ => Err(FieldError::WrongType {
                expected: PlaceKind::Scalar(scalar),
                found: PlaceKind::Scalar(Scalar::F32),
            }),
        }
    }

    /// The value of `scalar` in little-endian `bytes` (missing bytes read as zero).
    pub(crate) fn from_le_bytes(scalar: Scalar, bytes: &[u8]) -> Self {
        let mut w = [0u8; 4];
        w.iter_mut().zip(bytes).for_each(|(dst, src)| *dst = *src);
        match scalar {
            Scalar::U8 => Self::U8(w[0]),
            Scalar::U16 => Self::U16(u16::from_le_bytes([w[0], w[1]])),
            Scalar::I16 => Self::I16(i16::from_le_bytes([w[0], w[1]])),
            Scalar::U32 => Self::U32(u32::from_le_bytes(w)),
            Scalar::I32 => Self::I32(i32::from_le_bytes(w)),
            Scalar::F32 => Self::F32(f32::from_le_bytes(w)),
        }
    }

    /// Writes the value's little-endian bytes into `out` (its type's size; a shorter `out` gets
    /// the first bytes).
    pub(crate) fn write_le_bytes(self, out: &mut [u8]) {
        let mut w = [0u8; 4];
        match self {
            Self::U8(v) => w[0] = v,
            Self::U16(v) => w[..2].copy_from_slice(&v.to_le_bytes()),
            Self::I16(v) => w[..2].copy_from_slice(&v.to_le_bytes()),
            Self::U32(v) => w = v.to_le_bytes(),
            Self::I32(v) => w = v.to_le_bytes(),
            Self::F32(v) => w = v.to_le_bytes(),
        }
        out.iter_mut().zip(&w[..self.scalar().size()]).for_each(|(dst, src)| *dst = *src);
    }
}

macro_rules! value_from {
    ($($ty:ty => $variant:ident),*) => {$(
        impl From<$ty> for FieldValue {
            fn from(value: $ty) -> Self {
                Self::$variant(value)
            }
        }
    )*};
}
value_from!(u8 => U8, u16 => U16, i16 => I16, u32 => U32, i32 => I32, f32 => F32);

/// Why a field cannot be reached, read or written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldError {
    /// The struct has no IDL field of that name (padding has none).
    #[error("{within} has no such field")]
    UnknownField {
        /// The struct's IDL name.
        within: &'static str,
    },
    /// An array index at or past the array's end.
    #[error("index {index} is out of range ({len} elements)")]
    IndexOutOfRange {
        /// The index given (saturated at `usize::MAX` in a path).
        index: usize,
        /// The array's length.
        len: usize,
    },
    /// A field name after something that is not a struct.
    #[error("a {found} has no fields")]
    NotAStruct {
        /// What is there.
        found: PlaceKind,
    },
    /// An index after something that is not an array.
    #[error("a {found} is not an array")]
    NotAnArray {
        /// What is there.
        found: PlaceKind,
    },
    /// A value read or written where a struct or an array lies.
    #[error("a {found} is not a single value")]
    NotAScalar {
        /// What is there.
        found: PlaceKind,
    },
    /// A value (or a copied struct) of another type than the place's.
    #[error("expected a {expected}, found a {found}")]
    WrongType {
        /// The place's type.
        expected: PlaceKind,
        /// The value's type.
        found: PlaceKind,
    },
    /// An integer outside the field type's range.
    #[error("{value} is outside the {} range {min}..={max}", .scalar.idl_name())]
    OutOfRange {
        /// The field's type.
        scalar: Scalar,
        /// The value given.
        value: i64,
        /// The type's least value.
        min: i64,
        /// The type's greatest value.
        max: i64,
    },
    /// A path that is not names joined by `.` and indices in `[]`.
    #[error("malformed path at byte {at}: expected a field name after `.`, or a decimal index in `[]`")]
    Syntax {
        /// Byte offset in the path.
        at: usize,
    },
    /// An image that is not the message's length.
    #[error("the image is {found} bytes, the message's is {expected}")]
    ImageLength {
        /// The message's image length.
        expected: usize,
        /// Bytes given.
        found: usize,
    },
}

/// Where a scalar, a nested struct or an array lies in a message's struct image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldPlace {
    /// The whole image's length.
    image_len: usize,
    /// Where the place starts in the image.
    offset: usize,
    kind: PlaceKind,
}

impl FieldPlace {
    /// The whole message `M`.
    pub fn of<M: Message>() -> Self {
        Self::root(M::FIELDS)
    }

    /// The whole struct `layout`, over an image of `layout.size` bytes.
    pub const fn root(layout: &'static StructLayout) -> Self {
        Self { image_len: layout.size, offset: 0, kind: PlaceKind::Struct(layout) }
    }

    /// What lies here.
    pub const fn kind(&self) -> PlaceKind {
        self.kind
    }

    /// The IDL field `name` of the struct here.
    pub fn field(self, name: &str) -> Result<Self, FieldError> {
        let PlaceKind::Struct(layout) = self.kind else { return Err(FieldError::NotAStruct { found: self.kind }) };
        let unknown = FieldError::UnknownField { within: layout.name };
        let field = layout.idl_fields().find(|f| f.name == name).ok_or(unknown)?;
        let element = match field.shape {
            Shape::Scalar(scalar) => Element::Scalar(scalar),
            Shape::Struct(layout) => Element::Struct(layout),
            Shape::Pad => return Err(unknown),
        };
        let kind = match field.count {
            None => element.kind(),
            Some(len) => PlaceKind::Array { element, len },
        };
        Ok(Self { offset: self.offset + field.offset, kind, ..self })
    }

    /// Element `index` of the array here.
    pub fn index(self, index: usize) -> Result<Self, FieldError> {
        let PlaceKind::Array { element, len } = self.kind else {
            return Err(FieldError::NotAnArray { found: self.kind });
        };
        if index >= len {
            return Err(FieldError::IndexOutOfRange { index, len });
        }
        Ok(Self { offset: self.offset + index * element.size(), kind: element.kind(), ..self })
    }

    /// The place `path` names from here: IDL field names joined by `.`, array indices in `[]`
    /// (`motor_cmd[3].q`, `imu_state.rpy[0]`, `head[1]`; `[3].q` from an array; `""` is here).
    pub fn path(self, path: &str) -> Result<Self, FieldError> {
        let bytes = path.as_bytes();
        let mut place = self;
        let mut at = 0;
        while let Some(&byte) = bytes.get(at) {
            if byte == b'[' {
                let digits = bytes.get(at + 1..).unwrap_or_default().iter().take_while(|b| b.is_ascii_digit()).count();
                let close = at + 1 + digits;
                if digits == 0 || bytes.get(close) != Some(&b']') {
                    return Err(FieldError::Syntax { at: close });
                }
                let index = bytes
                    .get(at + 1..close)
                    .unwrap_or_default()
                    .iter()
                    .fold(0usize, |n, d| n.saturating_mul(10).saturating_add(usize::from(d - b'0')));
                place = place.index(index)?;
                at = close + 1;
            } else {
                // A name: at the start, or after a dot.
                let start = match (at, byte) {
                    (0, b'.') => return Err(FieldError::Syntax { at }),
                    (0, _) => 0,
                    (_, b'.') => at + 1,
                    _ => return Err(FieldError::Syntax { at }),
                };
                let len =
                    bytes.get(start..).unwrap_or_default().iter().take_while(|b| !matches!(b, b'.' | b'[')).count();
                let name = path.get(start..start + len).filter(|n| !n.is_empty());
                place = place.field(name.ok_or(FieldError::Syntax { at: start })?)?;
                at = start + len;
            }
        }
        Ok(place)
    }

    /// The place's bytes in `image` (a whole struct or array too: for comparing or copying).
    pub fn bytes<'a>(&self, image: &'a [u8]) -> Result<&'a [u8], FieldError> {
        image.get(self.span(image.len())?).ok_or(self.wrong_length(image.len()))
    }

    /// The scalar here, read from `image`.
    pub fn get(&self, image: &[u8]) -> Result<FieldValue, FieldError> {
        let PlaceKind::Scalar(scalar) = self.kind else { return Err(FieldError::NotAScalar { found: self.kind }) };
        Ok(FieldValue::from_le_bytes(scalar, self.bytes(image)?))
    }

    /// Writes the scalar here into `image`; `value` must be of its IDL type (convert with
    /// [`FieldValue::from_i64`] / [`FieldValue::from_f64`]). Only the field's bytes change.
    pub fn set(&self, image: &mut [u8], value: FieldValue) -> Result<(), FieldError> {
        let PlaceKind::Scalar(scalar) = self.kind else { return Err(FieldError::NotAScalar { found: self.kind }) };
        if value.scalar() != scalar {
            return Err(FieldError::WrongType { expected: self.kind, found: PlaceKind::Scalar(value.scalar()) });
        }
        value.write_le_bytes(self.bytes_mut(image)?);
        Ok(())
    }

    /// Copies what lies at `from` in `source` (a struct, an array or a scalar of this place's
    /// type, in an image of any message) here in `image`. Only this place's bytes change.
    pub fn copy_from(&self, image: &mut [u8], from: &FieldPlace, source: &[u8]) -> Result<(), FieldError> {
        if from.kind != self.kind {
            return Err(FieldError::WrongType { expected: self.kind, found: from.kind });
        }
        let source = from.bytes(source)?;
        self.bytes_mut(image)?.iter_mut().zip(source).for_each(|(dst, src)| *dst = *src);
        Ok(())
    }

    fn bytes_mut<'a>(&self, image: &'a mut [u8]) -> Result<&'a mut [u8], FieldError> {
        let len = image.len();
        image.get_mut(self.span(len)?).ok_or(self.wrong_length(len))
    }

    /// The place's byte range, in an image of `image_len` bytes.
    fn span(&self, image_len: usize) -> Result<Range<usize>, FieldError> {
        if image_len != self.image_len {
            return Err(self.wrong_length(image_len));
        }
        Ok(self.offset..self.offset + self.kind.size())
    }

    fn wrong_length(&self, found: usize) -> FieldError {
        FieldError::ImageLength { expected: self.image_len, found }
    }
}
