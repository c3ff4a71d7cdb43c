//! A capture holds every tapped frame byte for byte, in order, with its direction and time; it
//! reads back with the descriptions the application knows, and a protocol none of them has is a
//! typed error; captures written before descriptions still read; any truncation or corruption
//! of a capture is a typed error, never a panic.

use std::time::{SystemTime, UNIX_EPOCH};

use proptest::prelude::*;
use robowire_record::{Direction, ReadError, Recorder, read_frames, summarize};
use robowire_tap::SLOT_BYTES;
use zsl_proto::description::{DESCRIPTIONS, HIGH_LEVEL};
use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelCommand, HighLevelState, Model};

fn unix_ns() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).unwrap().as_nanos() as u64
}

fn capture(frames: &[(Direction, Vec<u8>)]) -> Vec<u8> {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = std::env::temp_dir().join(format!("robowire-capture-{}-{n}.mcap", std::process::id()));
    let recorder = Recorder::create(&path, "test").unwrap();
    let tap = recorder.link("zsl1/high_level", &HIGH_LEVEL);
    for (direction, bytes) in frames {
        tap.record(*direction, bytes);
    }
    let summary = recorder.finish().unwrap();
    assert_eq!((summary.frames, summary.dropped, summary.oversize), (frames.len() as u64, 0, 0));
    let bytes = std::fs::read(&path).unwrap();
    let _ = std::fs::remove_file(path);
    bytes
}

fn session() -> Vec<(Direction, Vec<u8>)> {
    let stand = HighLevelCommand::stand_up().encode(Model::Zsl1).to_vec();
    let walk = HighLevelCommand::move_velocity(0.5, 0.0, 0.1).encode(Model::Zsl1).to_vec();
    let state = HighLevelState { header: HIGH_LEVEL_STATE_HEADER, ..HighLevelState::default() }.encode().to_vec();
    vec![
        (Direction::Sent, stand),
        (Direction::Received, state.clone()),
        (Direction::Sent, walk),
        (Direction::Received, vec![1, 2, 3]),
    ]
}

#[test]
fn frames_come_back_byte_for_byte_in_order_at_unix_time() {
    let frames = session();
    let before = unix_ns();
    let capture = capture(&frames);
    let after = unix_ns();
    let read = read_frames(&capture, &DESCRIPTIONS).unwrap();
    let got: Vec<_> = read.iter().map(|f| (f.direction, f.bytes.clone())).collect();
    assert_eq!(got, frames);
    assert!(read.windows(2).all(|w| w[0].unix_ns <= w[1].unix_ns));
    assert!(read.iter().all(|f| f.link == "zsl1/high_level" && f.protocol.protocol() == "zsl1.high_level"));
    // The taps' monotonic stamps, logged at Unix time (1 ms of slack for the clocks' reads).
    assert!(read.iter().all(|f| (before - 1_000_000..=after + 1_000_000).contains(&f.unix_ns)), "{before} {after}");
    assert_eq!(read[0].decode().unwrap().schema, "zsl1.HighLevelCommand");
}

#[test]
fn a_protocol_nobody_described_is_an_error_naming_it() {
    let capture = capture(&session());
    for result in [read_frames(&capture, &[]).map(|_| ()), summarize(&capture, &[]).map(|_| ())] {
        match result {
            Err(e @ ReadError::UnknownProtocol { .. }) => {
                assert!(e.to_string().contains("protocol \"zsl1.high_level\""), "{e}");
            }
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn a_capture_written_before_link_descriptions_still_reads() {
    // Written by the recorder whose protocols were a closed enum; never regenerated (its links
    // carry the ZSL-1's names of then, `dog/…`: the reader takes a link's name as recorded).
    let capture = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/before-descriptions.mcap")).unwrap();
    let frames = read_frames(&capture, &DESCRIPTIONS).unwrap();
    let protocols: Vec<_> = frames.iter().map(|f| (f.link.as_str(), f.protocol.protocol(), f.bytes.len())).collect();
    assert_eq!(
        protocols,
        [
            ("dog/high_level", "zsl1.high_level", 40),
            ("dog/high_level", "zsl1.high_level", 560),
            ("dog/high_level", "zsl1.high_level", 3),
            ("dog/low_level", "zsl1.low_level", 272)
        ]
    );
    let schemas: Vec<_> = frames.iter().map(|f| f.decode().map(|j| j.schema).ok()).collect();
    assert_eq!(schemas, [Some("zsl1.HighLevelCommand"), Some("zsl1.HighLevelState"), None, Some("zsl1.LowLevelState")]);
    let summary = summarize(&capture, &DESCRIPTIONS).unwrap();
    assert_eq!(summary.metadata["link:dog/low_level"], "zsl1.low_level (zsl1-udp, vendor SDK v0.2.7)");
    assert_eq!(summary.channels.iter().map(|c| c.decode_errors).sum::<u64>(), 1);
}

#[test]
fn an_oversize_frame_is_counted_apart_and_the_rest_recorded() {
    let path = std::env::temp_dir().join(format!("robowire-capture-{}-oversize.mcap", std::process::id()));
    let recorder = Recorder::create(&path, "test").unwrap();
    let tap = recorder.link("zsl1/high_level", &HIGH_LEVEL);
    tap.record(Direction::Received, &[0; SLOT_BYTES + 1]);
    tap.record(Direction::Sent, &HighLevelCommand::stand_up().encode(Model::Zsl1));
    assert_eq!(recorder.oversize(), 1);
    let summary = recorder.finish().unwrap();
    assert_eq!((summary.frames, summary.dropped, summary.oversize), (1, 0, 1));
    // A tap used after the recorder finished drops and counts; nothing waits.
    tap.record(Direction::Sent, &[1]);
    let frames = read_frames(&std::fs::read(&path).unwrap(), &DESCRIPTIONS).unwrap();
    assert_eq!(frames.len(), 1);
    let _ = std::fs::remove_file(path);
}

#[test]
fn the_summary_counts_channels_and_decode_errors() {
    let summary = summarize(&capture(&session()), &DESCRIPTIONS).unwrap();
    let topic = |t: &str| summary.channels.iter().find(|c| c.topic == t).unwrap_or_else(|| panic!("{t}: {summary:?}"));
    assert_eq!(topic("/zsl1/high_level/sent/raw").count, 2);
    assert_eq!(topic("/zsl1/high_level/received/raw").count, 2);
    assert_eq!(topic("/zsl1/high_level/received/raw").decode_errors, 1, "the 3-byte junk");
    assert_eq!(topic("/zsl1/high_level/received/zsl1.HighLevelState").count, 1, "only the state decoded");
    assert_eq!(summary.metadata["command"], "test");
    assert_eq!(summary.metadata["link:zsl1/high_level"], "zsl1.high_level (zsl1-udp, vendor SDK v0.2.7)");
}

#[test]
fn every_truncation_is_an_error_or_a_prefix_never_a_panic() {
    let whole = capture(&session());
    for len in 0..whole.len() {
        let _ = summarize(&whole[..len], &DESCRIPTIONS);
        if let Ok(frames) = read_frames(&whole[..len], &DESCRIPTIONS) {
            assert!(frames.len() <= 4);
        }
    }
}

#[test]
fn a_metadata_index_pointing_outside_the_file_is_skipped() {
    let whole = capture(&session());
    let channels = summarize(&whole, &DESCRIPTIONS).unwrap().channels;
    let summary = mcap::Summary::read(&whole).unwrap().unwrap();
    let index = &summary.metadata_indexes[0];
    let target = [index.offset.to_le_bytes(), index.length.to_le_bytes()].concat();
    let at = whole.windows(16).position(|w| w == target).expect("the metadata index record");
    for (offset, length) in [(u64::MAX - 8, 0xff00), (whole.len() as u64, 1), (8, u64::MAX)] {
        let mut bad = whole.clone();
        bad[at..at + 8].copy_from_slice(&offset.to_le_bytes());
        bad[at + 8..at + 16].copy_from_slice(&length.to_le_bytes());
        let summary = summarize(&bad, &DESCRIPTIONS).unwrap();
        assert!(summary.metadata.is_empty(), "offset {offset}, length {length}");
        assert_eq!(summary.channels, channels);
    }
}

#[test]
fn a_raw_and_a_json_channel_on_one_topic_are_summarized_apart() {
    let mut writer = mcap::WriteOptions::new().compression(None).create(std::io::Cursor::new(Vec::new())).unwrap();
    let raw_metadata = [("link", "zsl1/high_level"), ("direction", "sent"), ("protocol", "zsl1.high_level")]
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .into();
    let json = writer.add_channel(0, "/zsl1/high_level/sent/raw", "json", &Default::default()).unwrap();
    let raw = writer.add_channel(0, "/zsl1/high_level/sent/raw", "robowire.raw", &raw_metadata).unwrap();
    let header =
        |channel_id, log_time| mcap::records::MessageHeader { channel_id, sequence: 0, log_time, publish_time: 0 };
    writer.write_to_known_channel(&header(json, 1), b"{}").unwrap();
    for t in 2..5 {
        writer.write_to_known_channel(&header(raw, t), &[1, 2, 3]).unwrap();
    }
    writer.finish().unwrap();
    let bytes = writer.into_inner().into_inner();
    assert_eq!(read_frames(&bytes, &DESCRIPTIONS).unwrap().len(), 3);
    let summary = summarize(&bytes, &DESCRIPTIONS).unwrap();
    let counts: Vec<_> = summary.channels.iter().map(|c| (c.encoding.as_str(), c.count, c.decode_errors)).collect();
    assert_eq!(counts, [("json", 1, 0), ("robowire.raw", 3, 3)]);
}

#[test]
fn a_summary_start_off_a_record_is_refused() {
    let whole = capture(&session());
    let field = whole.len() - 8 - 20; // the footer's summary start, before its offset start and CRC
    let start = u64::from_le_bytes(whole[field..field + 8].try_into().unwrap());
    assert_ne!(start, 0, "robowire writes a summary section");
    for bad in [start + 1, start - 1, whole.len() as u64 - 8, u64::MAX] {
        let mut bytes = whole.clone();
        bytes[field..field + 8].copy_from_slice(&bad.to_le_bytes());
        assert!(
            matches!(summarize(&bytes, &DESCRIPTIONS), Err(ReadError::Corrupt { offset, .. }) if offset == field),
            "{bad}"
        );
        assert!(matches!(read_frames(&bytes, &DESCRIPTIONS), Err(ReadError::Corrupt { .. })), "{bad}");
    }
    let mut no_summary = whole.clone();
    no_summary[field..field + 8].fill(0);
    assert!(summarize(&no_summary, &DESCRIPTIONS).unwrap().metadata.is_empty(), "no summary, no metadata index");
}

proptest! {
    #[test]
    fn corrupt_bytes_never_panic(flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8)) {
        let mut bytes = capture(&session());
        for (at, value) in flips {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        robowire_record::fuzz_read(&bytes, &DESCRIPTIONS);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        robowire_record::fuzz_read(&bytes, &DESCRIPTIONS);
    }
}
