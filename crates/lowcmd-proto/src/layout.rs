//! Field tables: each message's IDL fields with their struct-image offsets and scalar kinds.
//!
//! One table per struct, built from `offset_of!` on the zerocopy types, so it cannot drift from
//! them. The tables drive the CDR encoding (which walks the fields in IDL order with CDR
//! alignment), the JSON mapping, and the padding self-check in the tests.

/// A primitive IDL type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    /// `uint8` (also `octet`).
    U8,
    /// `uint16`.
    U16,
    /// `int16`.
    I16,
    /// `uint32`.
    U32,
    /// `int32`.
    I32,
    /// `float` (IEEE-754 binary32).
    F32,
}

impl Scalar {
    /// Size and CDR alignment, bytes.
    pub const fn size(self) -> usize {
        match self {
            Self::U8 => 1,
            Self::U16 | Self::I16 => 2,
            Self::U32 | Self::I32 | Self::F32 => 4,
        }
    }
}

/// What a field holds.
#[derive(Debug, Clone, Copy)]
pub enum Shape {
    /// A primitive.
    Scalar(Scalar),
    /// A nested struct.
    Struct(&'static StructLayout),
}

/// One IDL field.
#[derive(Debug, Clone, Copy)]
pub struct Field {
    /// IDL name.
    pub name: &'static str,
    /// Byte offset in the enclosing struct's image.
    pub offset: usize,
    /// Element type.
    pub shape: Shape,
    /// `None` for a single value, `Some(n)` for an array of `n`.
    pub count: Option<usize>,
}

impl Field {
    /// Bytes one element occupies in the image (its C `sizeof`).
    pub const fn stride(&self) -> usize {
        match self.shape {
            Shape::Scalar(s) => s.size(),
            Shape::Struct(layout) => layout.size,
        }
    }

    /// Elements: 1 for a single value.
    pub const fn len(&self) -> usize {
        match self.count {
            Some(n) => n,
            None => 1,
        }
    }

    /// `true` for a zero-length array (none exist in these messages).
    pub const fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// An IDL struct: its C size and its fields in IDL order.
#[derive(Debug)]
pub struct StructLayout {
    /// IDL name, e.g. `MotorCmd_`.
    pub name: &'static str,
    /// C `sizeof`, padding included.
    pub size: usize,
    /// Fields in IDL (and memory) order.
    pub fields: &'static [Field],
}

/// `Field` for `$ty::$name` of the given shape, optionally an array.
macro_rules! field {
    ($ty:ty, $name:ident, $shape:expr) => {
        $crate::layout::Field {
            name: stringify!($name),
            offset: core::mem::offset_of!($ty, $name),
            shape: $shape,
            count: None,
        }
    };
    ($ty:ty, $name:ident, $shape:expr, [$n:expr]) => {
        $crate::layout::Field {
            name: stringify!($name),
            offset: core::mem::offset_of!($ty, $name),
            shape: $shape,
            count: Some($n),
        }
    };
}
pub(crate) use field;
