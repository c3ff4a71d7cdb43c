//! Stream consistency: the property the fuzz targets (`fuzz/`) and xtask's corpus replay check,
//! so that the fuzzer and `cargo test` check the same thing (feature `fuzzing`: internal, not
//! public API).
//!
//! Input layout: byte 0 chooses the chunk size (1..=64) the stream is fed in; the rest is the
//! stream. Each check panics (that is what a fuzzer reports) if:
//! - decoding in chunks through a [`FrameBuffer`] yields other frames or counters than decoding
//!   the whole stream at once;
//! - a decoded frame does not re-encode to exactly the bytes it was decoded from, or those bytes
//!   do not parse back to it;
//! - frames + skipped bytes + pending bytes do not add up to the stream's length.

use robowire_core::{DecoderCounters, FrameBuffer, StreamDecoder};

use crate::{ChassisFrame, ChassisFrameDecoder, DecodeError, EncodeError, HostFrame, HostFrameDecoder, MAX_FRAME_LEN};

/// Checks the host-side decoder ([`ChassisFrame`]s) on `data`.
pub fn chassis_frame_stream(data: &[u8]) {
    check_stream(data, ChassisFrameDecoder::new, ChassisFrame::emit, ChassisFrame::parse);
}

/// Checks the device-side decoder ([`HostFrame`]s) on `data`.
pub fn host_frame_stream(data: &[u8]) {
    check_stream(data, HostFrameDecoder::new, HostFrame::emit, HostFrame::parse);
}

/// FNV-1a over every frame's bytes: compares frame sequences without allocating.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
struct Fingerprint(u64);

impl Fingerprint {
    fn add(&mut self, bytes: &[u8]) {
        for &b in bytes.iter().chain(&[0xFF]) {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
        }
    }
}

fn check_stream<D: StreamDecoder>(
    data: &[u8],
    new_decoder: fn() -> D,
    emit: fn(&D::Frame, &mut [u8]) -> Result<usize, EncodeError>,
    parse: fn(&[u8]) -> Result<D::Frame, DecodeError>,
) where
    D::Frame: core::fmt::Debug,
{
    let Some((&seed, stream)) = data.split_first() else { return };
    let chunk = 1 + usize::from(seed % 64);

    // Whole stream at once, checking every frame against the bytes it came from.
    let mut whole = new_decoder();
    let mut whole_print = Fingerprint(0xcbf2_9ce4_8422_2325);
    let mut frame_bytes = 0usize;
    let mut pos = 0;
    loop {
        let step = whole.decode(&stream[pos..]);
        assert!(step.consumed <= stream.len() - pos, "consumed past the end");
        pos += step.consumed;
        let Some(frame) = step.frame else { break };
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = emit(&frame, &mut buf).expect("a decoded frame re-encodes");
        let original = &stream[pos - len..pos];
        assert_eq!(&buf[..len], original, "re-encoding differs from the decoded bytes: {frame:?}");
        let reparsed = parse(original).expect("decoded bytes parse as one frame");
        let mut again = [0u8; MAX_FRAME_LEN];
        let len2 = emit(&reparsed, &mut again).expect("a parsed frame re-encodes");
        assert_eq!(&again[..len2], original);
        whole_print.add(original);
        frame_bytes += len;
    }
    let pending = stream.len() - pos;
    assert!(pending < MAX_FRAME_LEN, "pending {pending} bytes, more than a frame");
    let c: DecoderCounters = whole.counters();
    assert_eq!(frame_bytes as u64 + c.skipped_bytes + pending as u64, stream.len() as u64, "byte accounting");

    // The same stream in chunks through a FrameBuffer.
    let mut chunked: FrameBuffer<D, { MAX_FRAME_LEN + 16 }> = FrameBuffer::new(new_decoder());
    let mut chunked_print = Fingerprint(0xcbf2_9ce4_8422_2325);
    for part in stream.chunks(chunk) {
        chunked.push_all(part, |frame| {
            let mut buf = [0u8; MAX_FRAME_LEN];
            let len = emit(&frame, &mut buf).expect("a decoded frame re-encodes");
            chunked_print.add(&buf[..len]);
        });
    }
    assert_eq!(chunked_print, whole_print, "chunked decoding found other frames");
    assert_eq!(chunked.counters(), c, "chunked decoding counted differently");
    assert_eq!(chunked.pending(), &stream[pos..], "chunked decoding left other bytes pending");
}
