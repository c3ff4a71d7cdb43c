//! Field tables: each message's IDL fields with their struct-image offsets and scalar kinds.
//!
//! A message type and its table come from one declaration (the crate's `idl_struct!` macro), so they cannot
//! drift. The tables drive the CDR encoding (which walks the fields in IDL order with CDR
//! alignment), the JSON mapping, and padding: padding is a field of the table too
//! ([`Shape::Pad`]), and [`padding_ranges`] flattens a table into the byte ranges that must stay
//! zero, at compile time.

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

    /// The IDL name.
    pub const fn idl_name(self) -> &'static str {
        match self {
            Self::U8 => "uint8",
            Self::U16 => "uint16",
            Self::I16 => "int16",
            Self::U32 => "uint32",
            Self::I32 => "int32",
            Self::F32 => "float",
        }
    }
}

/// What a field holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A primitive.
    Scalar(Scalar),
    /// A nested struct.
    Struct(&'static StructLayout),
    /// C padding: not an IDL field, not in CDR or JSON, always zero in a sealed image.
    Pad,
}

/// One field of the struct image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// IDL name (the Rust field's name for padding).
    pub name: &'static str,
    /// Byte offset in the enclosing struct's image.
    pub offset: usize,
    /// Element type.
    pub shape: Shape,
    /// `None` for a single value, `Some(n)` for an array of `n` (padding: `n` bytes).
    pub count: Option<usize>,
}

impl Field {
    /// Bytes one element occupies in the image (its C `sizeof`).
    pub const fn stride(&self) -> usize {
        match self.shape {
            Shape::Scalar(s) => s.size(),
            Shape::Struct(layout) => layout.size,
            Shape::Pad => 1,
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

    /// Whether this is C padding rather than an IDL field.
    pub const fn is_padding(&self) -> bool {
        matches!(self.shape, Shape::Pad)
    }
}

/// An IDL struct: its C size and its fields (padding included) in memory order. Two layouts are
/// equal when their names, sizes and fields are (the Go2 and HG `MotorCmd_` are not).
#[derive(Debug, PartialEq, Eq)]
pub struct StructLayout {
    /// IDL name, e.g. `MotorCmd_`.
    pub name: &'static str,
    /// C `sizeof`, padding included.
    pub size: usize,
    /// Fields in IDL (and memory) order, padding fields where C puts padding.
    pub fields: &'static [Field],
}

impl StructLayout {
    /// The IDL fields (padding left out).
    pub fn idl_fields(&self) -> impl Iterator<Item = &'static Field> {
        self.fields.iter().filter(|f| !f.is_padding())
    }
}

/// A byte range of a struct image that must be zero: `(offset, len)`.
pub type PadRange = (usize, usize);

/// Padding ranges in `layout`, nested structs included.
pub const fn padding_count(layout: &StructLayout) -> usize {
    let mut count = 0;
    let mut i = 0;
    while i < layout.fields.len() {
        let field = &layout.fields[i];
        count += match field.shape {
            Shape::Pad => 1,
            Shape::Struct(sub) => field.len() * padding_count(sub),
            Shape::Scalar(_) => 0,
        };
        i += 1;
    }
    count
}

/// The `N` (= [`padding_count`]) padding ranges of `layout`, in memory order.
pub const fn padding_ranges<const N: usize>(layout: &StructLayout) -> [PadRange; N] {
    let mut out = [(0, 0); N];
    let mut next = 0;
    collect_padding(layout, 0, &mut out, &mut next);
    assert!(next == N, "padding_ranges: N must be padding_count(layout)");
    out
}

/// An `L`-byte mask of `layout`'s image: 0x00 on padding, 0xFF elsewhere. ANDing an image
/// with it zeroes the padding in one vectorizable pass. `N` is [`padding_count`].
pub const fn padding_mask<const L: usize, const N: usize>(layout: &StructLayout) -> [u8; L] {
    let ranges = padding_ranges::<N>(layout);
    let mut mask = [0xFF; L];
    let mut i = 0;
    while i < N {
        let (offset, len) = ranges[i];
        let mut k = 0;
        while k < len {
            mask[offset + k] = 0;
            k += 1;
        }
        i += 1;
    }
    mask
}

const fn collect_padding<const N: usize>(
    layout: &StructLayout,
    base: usize,
    out: &mut [PadRange; N],
    next: &mut usize,
) {
    let mut i = 0;
    while i < layout.fields.len() {
        let field = &layout.fields[i];
        match field.shape {
            Shape::Pad => {
                out[*next] = (base + field.offset, field.len());
                *next += 1;
            }
            Shape::Struct(sub) => {
                let mut k = 0;
                while k < field.len() {
                    collect_padding(sub, base + field.offset + k * sub.size, out, next);
                    k += 1;
                }
            }
            Shape::Scalar(_) => {}
        }
        i += 1;
    }
}

/// Declares a message struct and its [`StructLayout`] from one list of fields.
///
/// Each field is `name: Type => kind`, the kind one of `scalar(K)`, `array(K)` (a `[T; n]` of
/// scalar `K`), `nested(LAYOUT)`, `nested_array(LAYOUT)` or `pad` (C padding: a private
/// `[u8; n]`, zero in every sealed image). Array lengths come from the type.
macro_rules! idl_struct {
    (
        $(#[$meta:meta])*
        pub struct $name:ident as $idl:literal in $layout:ident {
            $( $(#[$fmeta:meta])* $fvis:vis $field:ident : $fty:ty => $kind:ident $( ( $arg:ident ) )? ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(
            Debug, Clone, Copy, PartialEq, Eq, Hash,
            zerocopy::FromBytes, zerocopy::IntoBytes, zerocopy::KnownLayout, zerocopy::Immutable, zerocopy::Unaligned,
        )]
        #[repr(C)]
        pub struct $name {
            $( $(#[$fmeta])* $fvis $field: $fty, )*
        }

        #[doc = concat!("Layout of [`", stringify!($name), "`] (IDL `", $idl, "`).")]
        pub const $layout: $crate::layout::StructLayout = $crate::layout::StructLayout {
            name: $idl,
            size: size_of::<$name>(),
            fields: &[ $( $crate::layout::idl_struct!(@field $name, $field, $fty, $kind $( ( $arg ) )?) ),* ],
        };
    };
    (@field $s:ident, $f:ident, $fty:ty, scalar($k:ident)) => {
        $crate::layout::Field {
            name: stringify!($f),
            offset: core::mem::offset_of!($s, $f),
            shape: $crate::layout::Shape::Scalar($crate::layout::Scalar::$k),
            count: None,
        }
    };
    (@field $s:ident, $f:ident, $fty:ty, array($k:ident)) => {
        $crate::layout::Field {
            name: stringify!($f),
            offset: core::mem::offset_of!($s, $f),
            shape: $crate::layout::Shape::Scalar($crate::layout::Scalar::$k),
            count: Some(size_of::<$fty>() / $crate::layout::Scalar::$k.size()),
        }
    };
    (@field $s:ident, $f:ident, $fty:ty, nested($l:ident)) => {
        $crate::layout::Field {
            name: stringify!($f),
            offset: core::mem::offset_of!($s, $f),
            shape: $crate::layout::Shape::Struct(&$l),
            count: None,
        }
    };
    (@field $s:ident, $f:ident, $fty:ty, nested_array($l:ident)) => {
        $crate::layout::Field {
            name: stringify!($f),
            offset: core::mem::offset_of!($s, $f),
            shape: $crate::layout::Shape::Struct(&$l),
            count: Some(size_of::<$fty>() / $l.size),
        }
    };
    (@field $s:ident, $f:ident, $fty:ty, pad) => {
        $crate::layout::Field {
            name: stringify!($f),
            offset: core::mem::offset_of!($s, $f),
            shape: $crate::layout::Shape::Pad,
            count: Some(size_of::<$fty>()),
        }
    };
}
pub(crate) use idl_struct;
