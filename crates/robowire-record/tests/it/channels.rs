//! How frames become channels: a frame already in a wire encoding (`cdr` under an `omgidl`
//! schema) is written once under it, with no JSON beside it; a DDS writer's GUID makes a channel
//! of its own and its source timestamp is the publish time; JSON can be turned off; a JSON
//! thread that falls behind skips JSON messages, counted, never a raw frame.

use std::collections::BTreeMap;

use robowire_core::json::{FrameError, JsonFrame, LinkDescription, WireSchema};
use robowire_record::{Compression, Direction, Recorder, RecorderOptions, RecordingSummary, SampleOrigin, read_frames};

/// A toy protocol: frames starting with `C` are "CDR" under a schema, the rest are its own bytes
/// whose JSON is their length.
#[derive(Debug)]
struct Toy;

impl LinkDescription for Toy {
    fn protocol(&self) -> &'static str {
        "toy.mixed"
    }
    fn layout(&self) -> &'static str {
        "a C, then CDR; or any bytes"
    }
    fn decode(&self, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
        Ok(JsonFrame { schema: "toy.Length", value: frame.len().into() })
    }
    fn wire_schema(&self, _: Direction, frame: &[u8]) -> Option<WireSchema> {
        frame.first().filter(|b| **b == b'C').map(|_| WireSchema {
            encoding: "cdr",
            name: "toy::Message",
            schema_encoding: "omgidl",
            text: "module toy { struct Message { octet c; }; };",
        })
    }
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-channels-{}-{name}.mcap", std::process::id()))
}

/// Records `frames` with `options`; the summary and the file's bytes.
fn record(
    name: &str,
    options: RecorderOptions,
    frames: &[(Direction, &[u8], SampleOrigin)],
) -> (RecordingSummary, Vec<u8>) {
    let path = temp(name);
    let recorder = Recorder::create_with(&path, "test", options).unwrap();
    let tap = recorder.link("toy/link", &Toy);
    for (direction, bytes, origin) in frames {
        tap.record_parts(*direction, &[bytes], *origin);
    }
    let summary = recorder.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(path);
    (summary, bytes)
}

/// (topic, message encoding, schema name, schema encoding, metadata) → messages: (log, publish).
type Seen = BTreeMap<(String, String, String, String, BTreeMap<String, String>), Vec<(u64, u64)>>;

fn channels(bytes: &[u8]) -> Seen {
    let mut seen = Seen::new();
    for message in mcap::MessageStream::new(bytes).unwrap() {
        let message = message.unwrap();
        let c = &message.channel;
        let (schema, encoding) =
            c.schema.as_ref().map_or((String::new(), String::new()), |s| (s.name.clone(), s.encoding.clone()));
        let key = (c.topic.clone(), c.message_encoding.clone(), schema, encoding, c.metadata.clone());
        seen.entry(key).or_default().push((message.log_time, message.publish_time));
    }
    seen
}

#[test]
fn a_wire_encoded_frame_is_written_once_under_its_schema() {
    let none = SampleOrigin::NONE;
    let frames = [
        (Direction::Sent, &b"C1"[..], none),
        (Direction::Sent, &b"xyz"[..], none),
        (Direction::Sent, &b"C2"[..], none),
    ];
    let (summary, bytes) = record("wire", RecorderOptions::default(), &frames);
    assert_eq!((summary.frames, summary.dropped, summary.json_skipped, summary.decode_errors), (3, 0, 0, 0));
    let seen = channels(&bytes);
    let topics: Vec<_> =
        seen.iter().map(|(k, v)| (k.0.as_str(), k.1.as_str(), k.2.as_str(), k.3.as_str(), v.len())).collect();
    assert_eq!(
        topics,
        [
            ("/toy/link/sent", "cdr", "toy::Message", "omgidl", 2),
            ("/toy/link/sent/raw", "robowire.raw", "toy.mixed", "robowire.layout", 1),
            ("/toy/link/sent/toy.Length", "json", "toy.Length", "jsonschema", 1),
        ]
    );
    // Both kinds of frame channel read back as frames, in file order, byte for byte.
    let frames = read_frames(&bytes, &[&Toy]).unwrap();
    let bytes: Vec<&[u8]> = frames.iter().map(|f| f.bytes.as_slice()).collect();
    assert_eq!(bytes, [&b"C1"[..], b"xyz", b"C2"]);
}

#[test]
fn each_dds_writer_has_its_channel_and_its_source_time_is_the_publish_time() {
    let (a, b) = ([1u8; 16], [2u8; 16]);
    let origin = |writer, source| SampleOrigin { writer: Some(writer), source_unix_ns: Some(source) };
    let frames = [
        (Direction::Received, &b"C1"[..], origin(a, 1_000)),
        (Direction::Received, &b"C2"[..], origin(b, 2_000)),
        (Direction::Received, &b"C3"[..], origin(a, 3_000)),
    ];
    let (_, bytes) = record("writers", RecorderOptions::default(), &frames);
    let seen = channels(&bytes);
    assert_eq!(seen.len(), 2, "{seen:?}");
    let by_writer = |writer: [u8; 16]| {
        let hex: String = writer.iter().map(|b| format!("{b:02x}")).collect();
        seen.iter().find(|(k, _)| k.4.get("writer_guid") == Some(&hex)).map(|(_, v)| v.clone()).unwrap()
    };
    let publish = |v: Vec<(u64, u64)>| v.into_iter().map(|(_, p)| p).collect::<Vec<_>>();
    assert_eq!(publish(by_writer(a)), [1_000, 3_000]);
    assert_eq!(publish(by_writer(b)), [2_000]);
}

#[test]
fn without_json_only_the_frames_are_written() {
    let frames = [(Direction::Received, &b"abc"[..], SampleOrigin::NONE)];
    let (summary, bytes) = record("nojson", RecorderOptions { json: false, ..Default::default() }, &frames);
    assert_eq!(summary.frames, 1);
    let encodings: Vec<_> = channels(&bytes).into_keys().map(|k| k.1).collect();
    assert_eq!(encodings, ["robowire.raw"]);
}

#[test]
fn compressed_captures_read_back_the_same() {
    let frames: Vec<(Direction, Vec<u8>)> =
        (0..500u32).map(|n| (Direction::Sent, format!("frame {n} {}", "x".repeat(100)).into_bytes())).collect();
    let taps: Vec<(Direction, &[u8], SampleOrigin)> =
        frames.iter().map(|(d, b)| (*d, b.as_slice(), SampleOrigin::NONE)).collect();
    let (_, plain) = record("plain", RecorderOptions::default(), &taps);
    for compression in [Compression::Zstd, Compression::Lz4] {
        let (summary, bytes) = record("packed", RecorderOptions { compression, ..Default::default() }, &taps);
        assert_eq!(summary.frames, 500);
        assert!(bytes.len() * 3 < plain.len(), "{compression:?}: {} of {} bytes", bytes.len(), plain.len());
        let read: Vec<Vec<u8>> = read_frames(&bytes, &[&Toy]).unwrap().into_iter().map(|f| f.bytes).collect();
        assert_eq!(read, frames.iter().map(|(_, b)| b.clone()).collect::<Vec<_>>(), "{compression:?}");
    }
}

#[test]
fn a_corrupt_or_cut_compressed_capture_is_an_error_never_a_panic() {
    let taps: Vec<(Direction, Vec<u8>, SampleOrigin)> =
        (0..200u32).map(|n| (Direction::Sent, format!("frame {n}").into_bytes(), SampleOrigin::NONE)).collect();
    let taps: Vec<(Direction, &[u8], SampleOrigin)> = taps.iter().map(|(d, b, o)| (*d, b.as_slice(), *o)).collect();
    for compression in [Compression::Zstd, Compression::Lz4] {
        let (_, whole) = record("cut", RecorderOptions { compression, ..Default::default() }, &taps);
        for cut in (0..whole.len()).step_by(7) {
            let _ = read_frames(&whole[..cut], &[&Toy]);
        }
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..2_000 {
            let mut bad = whole.clone();
            for _ in 0..3 {
                rng ^= rng << 13;
                rng ^= rng >> 7;
                rng ^= rng << 17;
                let at = (rng % bad.len() as u64) as usize;
                bad[at] ^= (rng >> 32) as u8 | 1;
            }
            if let Ok(frames) = read_frames(&bad, &[&Toy]) {
                assert!(frames.len() <= 200);
            }
        }
    }
}

/// A description whose decoding is slow: the JSON thread falls behind a burst.
#[derive(Debug)]
struct Slow;

impl LinkDescription for Slow {
    fn protocol(&self) -> &'static str {
        "toy.slow"
    }
    fn layout(&self) -> &'static str {
        "any bytes"
    }
    fn decode(&self, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
        // About 50 µs of work per frame.
        let mut x = 0u64;
        for i in 0..20_000u64 {
            x = std::hint::black_box(x.wrapping_mul(31).wrapping_add(i));
        }
        Ok(JsonFrame {
            schema: "toy.Slow",
            value: (frame.len() as u64 + u64::from(std::hint::black_box(x) == u64::MAX)).into(),
        })
    }
}

#[test]
fn a_json_thread_behind_skips_json_counted_and_never_a_frame() {
    let path = temp("slow");
    let recorder =
        Recorder::create_with(&path, "test", RecorderOptions { ring_slots: 64, ..Default::default() }).unwrap();
    let tap = recorder.link("toy/slow", &Slow);
    const N: u64 = 20_000;
    for n in 0..N {
        tap.record(Direction::Sent, &n.to_le_bytes());
    }
    let summary = recorder.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(path);
    // Every tapped frame is written or counted as dropped; every written one has its JSON
    // message or is counted as skipped.
    assert_eq!(summary.frames + summary.dropped, N, "{summary:?}");
    let seen = channels(&bytes);
    let count = |encoding: &str| seen.iter().filter(|(k, _)| k.1 == encoding).map(|(_, v)| v.len() as u64).sum::<u64>();
    assert_eq!(count("robowire.raw"), summary.frames);
    assert_eq!(count("json") + summary.json_skipped, summary.frames, "{summary:?}");
    assert_eq!(read_frames(&bytes, &[&Slow]).unwrap().len() as u64, summary.frames);
}
