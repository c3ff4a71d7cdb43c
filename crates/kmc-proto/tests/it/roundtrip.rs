//! Every frame type survives encode → decode, alone and in a stream cut at random places.

use kmc_proto::{ChassisFrame, ChassisFrameDecoder, FrameBuffer, HostFrame, HostFrameDecoder, StreamDecoder};
use proptest::prelude::*;

use crate::strategies::*;

/// Feeds `stream` in the given chunk sizes (cycled) and returns the re-encoded frames.
fn decode_chunked<D: StreamDecoder>(
    decoder: D,
    stream: &[u8],
    chunks: &[usize],
    emit: fn(&D::Frame) -> Vec<u8>,
) -> (Vec<Vec<u8>>, FrameBuffer<D, 128>) {
    let mut rx = FrameBuffer::new(decoder);
    let mut out = Vec::new();
    let mut rest = stream;
    for &size in chunks.iter().cycle() {
        if rest.is_empty() {
            break;
        }
        let (part, tail) = rest.split_at(size.min(rest.len()));
        rx.push_all(part, |f| out.push(emit(&f)));
        rest = tail;
    }
    (out, rx)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn host_frame_round_trips(frame in host_frame()) {
        let bytes = emit_host(&frame);
        prop_assert_eq!(bytes.len(), frame.buffer_len());
        prop_assert_eq!(HostFrame::parse(&bytes), Ok(frame));
    }

    #[test]
    fn chassis_frame_round_trips_bit_exact(frame in chassis_frame()) {
        let bytes = emit_chassis(&frame);
        prop_assert_eq!(bytes.len(), frame.buffer_len());
        let parsed = ChassisFrame::parse(&bytes).expect("an emitted frame parses");
        // NaN payloads in reserved slots defeat `==`; the bytes do not lie.
        prop_assert_eq!(emit_chassis(&parsed), bytes);
        prop_assert_eq!(core::mem::discriminant(&parsed), core::mem::discriminant(&frame));
    }

    #[test]
    fn host_stream_in_random_chunks(
        frames in prop::collection::vec(host_frame(), 1..40),
        chunks in prop::collection::vec(1usize..100, 1..10),
    ) {
        let encoded: Vec<Vec<u8>> = frames.iter().map(emit_host).collect();
        let (decoded, rx) = decode_chunked(HostFrameDecoder::new(), &encoded.concat(), &chunks, emit_host);
        prop_assert_eq!(decoded, encoded);
        let c = rx.counters();
        prop_assert_eq!((c.frames, c.skipped_bytes, c.rejected_candidates), (frames.len() as u64, 0, 0));
        prop_assert!(rx.pending().is_empty());
    }

    #[test]
    fn chassis_stream_in_random_chunks(
        frames in prop::collection::vec(chassis_frame(), 1..40),
        chunks in prop::collection::vec(1usize..100, 1..10),
    ) {
        let encoded: Vec<Vec<u8>> = frames.iter().map(emit_chassis).collect();
        let (decoded, rx) = decode_chunked(ChassisFrameDecoder::new(), &encoded.concat(), &chunks, emit_chassis);
        prop_assert_eq!(decoded, encoded);
        let c = rx.counters();
        prop_assert_eq!((c.frames, c.skipped_bytes, c.rejected_candidates), (frames.len() as u64, 0, 0));
    }

    #[test]
    fn partial_frames_wait_instead_of_failing(frame in chassis_frame()) {
        let bytes = emit_chassis(&frame);
        let mut rx: FrameBuffer<ChassisFrameDecoder, 128> = FrameBuffer::new(ChassisFrameDecoder::new());
        for (i, &b) in bytes.iter().enumerate() {
            rx.push(&[b]);
            let got = rx.next_frame();
            prop_assert_eq!(got.is_some(), i + 1 == bytes.len(), "byte {}", i);
        }
        prop_assert_eq!(rx.counters().rejected_candidates, 0);
    }
}
