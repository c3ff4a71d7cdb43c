//! 10 % random garbage between valid frames: every frame the garbage did not overlap is
//! recovered, and the counters account for every other byte.

use kmc_proto::{ChassisFrameDecoder, HostFrameDecoder, MAX_FRAME_LEN, StreamDecoder};
use proptest::prelude::*;

use crate::strategies::*;

/// Positions `[start, end)` of the original frames in a stream with garbage between them.
fn interleave(frames: &[Vec<u8>], garbage: &[Vec<u8>]) -> (Vec<u8>, Vec<(usize, usize)>) {
    let mut stream = Vec::new();
    let mut spans = Vec::new();
    for (frame, junk) in frames.iter().zip(garbage) {
        stream.extend_from_slice(junk);
        spans.push((stream.len(), stream.len() + frame.len()));
        stream.extend_from_slice(frame);
    }
    (stream, spans)
}

/// Decodes `stream` whole and returns the spans of accepted frames and the pending tail start.
fn accepted_spans<D: StreamDecoder>(
    decoder: &mut D,
    stream: &[u8],
    frame_len: impl Fn(&D::Frame) -> usize,
) -> (Vec<(usize, usize)>, usize) {
    let mut spans = Vec::new();
    let mut pos = 0;
    loop {
        let step = decoder.decode(&stream[pos..]);
        pos += step.consumed;
        match step.frame {
            Some(frame) => spans.push((pos - frame_len(&frame), pos)),
            None => return (spans, pos),
        }
    }
}

fn check_recovery(
    stream: &[u8],
    originals: &[(usize, usize)],
    accepted: &[(usize, usize)],
    pending_from: usize,
    skipped: u64,
) {
    let overlaps = |a: (usize, usize), b: (usize, usize)| a.0 < b.1 && b.0 < a.1;
    // Frames the decoder accepted that are not an original frame at its own position.
    let false_frames: Vec<_> = accepted.iter().filter(|s| !originals.contains(s)).copied().collect();
    for &original in originals {
        let hidden = false_frames.iter().any(|&f| overlaps(f, original)) || original.1 > pending_from;
        if !hidden {
            assert!(accepted.contains(&original), "frame at {original:?} was not recovered");
        }
    }
    let frame_bytes: usize = accepted.iter().map(|(s, e)| e - s).sum();
    assert_eq!(frame_bytes as u64 + skipped + (stream.len() - pending_from) as u64, stream.len() as u64);
    assert!(stream.len() - pending_from < MAX_FRAME_LEN);
}

/// Garbage before each frame: none in most gaps, so that about 10 % of all bytes are garbage.
fn garbage_for(count: usize) -> impl Strategy<Value = Vec<Vec<u8>>> {
    prop::collection::vec(prop_oneof![3 => Just(Vec::new()), 1 => prop::collection::vec(any::<u8>(), 1..8)], count)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn chassis_stream_with_garbage(
        (frames, garbage) in prop::collection::vec(chassis_frame(), 1..60)
            .prop_flat_map(|f| { let n = f.len(); (Just(f), garbage_for(n)) })
    ) {
        let encoded: Vec<Vec<u8>> = frames.iter().map(emit_chassis).collect();
        let (stream, originals) = interleave(&encoded, &garbage);
        let mut decoder = ChassisFrameDecoder::new();
        let (accepted, pending_from) = accepted_spans(&mut decoder, &stream, |f| f.buffer_len());
        check_recovery(&stream, &originals, &accepted, pending_from, decoder.counters().skipped_bytes);
    }

    #[test]
    fn host_stream_with_garbage(
        (frames, garbage) in prop::collection::vec(host_frame(), 1..60)
            .prop_flat_map(|f| { let n = f.len(); (Just(f), garbage_for(n)) })
    ) {
        let encoded: Vec<Vec<u8>> = frames.iter().map(emit_host).collect();
        let (stream, originals) = interleave(&encoded, &garbage);
        let mut decoder = HostFrameDecoder::new();
        let (accepted, pending_from) = accepted_spans(&mut decoder, &stream, |f| f.buffer_len());
        check_recovery(&stream, &originals, &accepted, pending_from, decoder.counters().skipped_bytes);
    }
}

/// Garbage chosen to be nasty: frame IDs and plausible headers right before real frames.
#[test]
fn adversarial_prefixes_do_not_hide_untouched_frames() {
    let real = emit_chassis(&kmc_proto::ChassisFrame::VehicleSpeed(kmc_proto::VehicleSpeed { speed_mps: 1.25 }));
    for junk in
        [&[0xaf][..], &[0xaf, 0x00], &[0xaf, 0x00, 0x01], &[0xaf, 0x00, 0x01, 0x01], &[0xb3], &[0xb3, 0xff, 0xff]]
    {
        let mut stream = junk.to_vec();
        stream.extend_from_slice(&real);
        let mut decoder = ChassisFrameDecoder::new();
        let (accepted, pending_from) = accepted_spans(&mut decoder, &stream, |f| f.buffer_len());
        let original = (junk.len(), stream.len());
        check_recovery(&stream, &[original], &accepted, pending_from, decoder.counters().skipped_bytes);
        if junk[0] == 0xaf {
            // A header that cannot be completed plausibly is rejected, and the real frame found.
            assert_eq!(accepted, [original], "junk {junk:02x?}");
            assert!(decoder.counters().rejected_candidates >= 1);
        }
    }
}

/// Spec §6.2: a stray 0xB3 followed by a plausible float is a false frame that hides the real
/// one. The protocol has no checksum; the decoder cannot know better, and the counters say so.
#[test]
fn stray_speed_id_can_form_a_false_frame() {
    let stream = [0xb3, 0xb3, 0x00, 0x00, 0xa0, 0x3f];
    let mut decoder = ChassisFrameDecoder::new();
    let (accepted, pending_from) = accepted_spans(&mut decoder, &stream, |f| f.buffer_len());
    assert_eq!(accepted, [(0, 5)]);
    // The real frame's last byte, 0x3f, is no frame ID: skipped.
    assert_eq!(pending_from, 6);
    assert_eq!(decoder.counters().skipped_bytes, 1);
}
