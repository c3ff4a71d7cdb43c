#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod channels;
mod framing;
mod json_thread;
mod read;
mod write;

pub use read::{CaptureSummary, ChannelSummary, ReadError, RecordedFrame, read_frames, summarize};
pub use robowire_core::json::{FrameError, JsonFrame, LinkDescription, WireSchema};
pub use robowire_tap::RecordLinks;
pub use robowire_tap::{Direction, SampleOrigin, Tap};
pub use write::{Compression, RecordError, Recorder, RecorderOptions, RecordingSummary};

/// The message encoding of the raw channels: the frame's bytes, as on the wire.
pub const RAW_ENCODING: &str = "robowire.raw";

/// The schema encoding of the raw channels' schemas: named by the protocol, the text is the
/// layout its frames follow (`zsl1-udp, vendor SDK v0.2.7`), for people, not for a decoder.
pub const LAYOUT_SCHEMA_ENCODING: &str = "robowire.layout";

/// The replay reader's check for the fuzz target: any bytes read as a capture, with the
/// descriptions `known`, give frames or a typed error, never a panic; what reads as frames also
/// summarizes.
pub fn fuzz_read(bytes: &[u8], known: &[&'static dyn LinkDescription]) {
    let frames = read_frames(bytes, known);
    let summary = summarize(bytes, known);
    if let (Ok(frames), Ok(summary)) = (frames, summary) {
        let raw: u64 = summary.channels.iter().filter(|c| c.frames).map(|c| c.count).sum();
        assert_eq!(raw, frames.len() as u64, "the summary counts every frame read");
    }
}
