//! The golden regression suite: every fixture decodes to its expected fields and re-encodes
//! byte for byte. `--bless` rewrites robowire's own expected fields from the decoder (never the
//! bytes); vendor-generated vectors (Unitree) are never rewritten.

pub mod kmc;
pub mod rtps;
pub mod unitree;
pub mod zsl1;

use serde::Serialize;
use serde_json::Value;

/// What the suite found for one fixture.
#[derive(Debug)]
pub struct Outcome {
    /// Fixture name.
    pub name: String,
    /// Everything that did not match; empty when the fixture passed.
    pub problems: Vec<String>,
    /// The expected fields were rewritten (`--bless`).
    pub blessed: bool,
}

impl Outcome {
    /// A passed or failed check.
    pub fn new(name: impl Into<String>, problems: Vec<String>) -> Self {
        Self { name: name.into(), problems, blessed: false }
    }
}

/// A value as JSON, through text so that f32 values keep their shortest form.
pub(crate) fn to_json<T: Serialize>(value: &T) -> anyhow::Result<Value> {
    Ok(serde_json::from_str(&serde_json::to_string(value)?)?)
}
