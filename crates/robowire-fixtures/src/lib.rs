#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod interop;
pub mod peers;
pub mod rtps;
pub mod wait;
pub mod zsl1;

use std::path::PathBuf;

/// The workspace's `fixtures/` directory.
pub fn fixtures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

/// Bytes from hex without separators (lowercase or uppercase); `None` if it is not hex.
pub fn hex_bytes(text: &str) -> Option<Vec<u8>> {
    if !text.len().is_multiple_of(2) {
        return None;
    }
    (0..text.len()).step_by(2).map(|i| u8::from_str_radix(text.get(i..i + 2)?, 16).ok()).collect()
}
