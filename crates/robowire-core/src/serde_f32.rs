//! The one JSON form of a float (feature `serde`), used by every codec's JSON: a finite value is
//! a number with the shortest text that reads back to the same `f32` (`0.4`, not
//! `0.4000000059604645`); a non-finite one is a string, `"NaN"` (bits `0x7fc00000`), `"-NaN"`
//! (`0xffc00000`), `"Infinity"`, `"-Infinity"`. Another NaN payload reads back as the quiet NaN
//! of its sign: JSON has no way to say more.
//!
//! ```
//! # use robowire_core::serde_f32::F32;
//! assert_eq!(serde_json::to_string(&F32(0.4)).unwrap(), "0.4");
//! assert_eq!(serde_json::to_string(&F32(f32::NEG_INFINITY)).unwrap(), "\"-Infinity\"");
//! let back: F32 = serde_json::from_str("0.4000000059604645").unwrap();
//! assert_eq!(back.0, 0.4);
//! ```

use core::fmt;

use serde::de::{self, Deserialize, Deserializer, Visitor};
use serde::ser::{Serialize, Serializer};

/// An `f32` in robowire's JSON form.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct F32(pub f32);

/// The string of a non-finite value, or `None` for a finite one.
pub fn non_finite_name(v: f32) -> Option<&'static str> {
    if v.is_nan() {
        Some(if v.is_sign_negative() { "-NaN" } else { "NaN" })
    } else if v.is_infinite() {
        Some(if v > 0.0 { "Infinity" } else { "-Infinity" })
    } else {
        None
    }
}

/// The value of a non-finite name (`"NaN"`, `"-NaN"`, `"Infinity"`, `"-Infinity"`).
pub fn from_non_finite_name(name: &str) -> Option<f32> {
    match name {
        "NaN" => Some(f32::from_bits(0x7fc0_0000)),
        "-NaN" => Some(f32::from_bits(0xffc0_0000)),
        "Infinity" => Some(f32::INFINITY),
        "-Infinity" => Some(f32::NEG_INFINITY),
        _ => None,
    }
}

impl Serialize for F32 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match non_finite_name(self.0) {
            None => s.serialize_f32(self.0),
            Some(name) => s.serialize_str(name),
        }
    }
}

struct F32Visitor;

impl Visitor<'_> for F32Visitor {
    type Value = F32;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a number, \"NaN\", \"-NaN\", \"Infinity\" or \"-Infinity\"")
    }

    // A number written from the exact f32 (as f64) converts back exactly; others round to nearest.
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<F32, E> {
        Ok(F32(v as f32))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<F32, E> {
        Ok(F32(v as f32))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<F32, E> {
        Ok(F32(v as f32))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<F32, E> {
        from_non_finite_name(v).map(F32).ok_or_else(|| E::invalid_value(de::Unexpected::Str(v), &self))
    }
}

impl<'de> Deserialize<'de> for F32 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(F32Visitor)
    }
}

/// Serializes a slice of floats as a JSON array of [`F32`].
#[derive(Debug, Clone, Copy)]
pub struct F32Slice<'a>(pub &'a [f32]);

impl Serialize for F32Slice<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeSeq;
        let mut seq = s.serialize_seq(Some(self.0.len()))?;
        for &v in self.0 {
            seq.serialize_element(&F32(v))?;
        }
        seq.end()
    }
}
