//! The recorder's throughput, measured in one run: 560-byte states (a ZSL-1 HighLevel state,
//! encoded by its codec) tapped as fast as one thread can, written raw and decoded to JSON
//! (frames/s and MB/s of what was written, what the ring dropped); tapped at 1 M frames/s
//! (560-byte and 64-byte frames, raw); 100 links at 1 kHz each, with JSON (what was dropped,
//! what went without JSON), and with zstd chunks.
//!
//! What recording costs a live stream (against the simulators, through the facades) is the CLI
//! crate's bench `recorded` (`crates/robowire/benches/recorded.rs`): this crate knows no device.
//! Figures to `ROBOWIRE_BENCH_META_RECORD` for `cargo xtask bench`.

use std::time::{Duration, Instant};

use robowire_record::{Compression, Direction, Recorder, RecorderOptions};
use serde_json::json;
use zsl_proto::description::HIGH_LEVEL;
use zsl_proto::udp::{HIGH_LEVEL_STATE_HEADER, HighLevelState};

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("robowire-bench-{}-{name}.mcap", std::process::id()))
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let quick = std::env::var_os("ROBOWIRE_BENCH_QUICK").is_some();
    let frames = if quick { 50_000 } else { 300_000 };
    let state =
        HighLevelState { header: HIGH_LEVEL_STATE_HEADER, control_mode: 18.into(), ..Default::default() }.encode();
    let unpaced_raw = throughput(&state, frames, 1, None, false);
    let unpaced_json = throughput(&state, frames, 1, None, true);
    let million = throughput(&state, 2_000_000, 1, Some(1e6), false);
    let million_small = throughput(&state[..64], 2_000_000, 1, Some(1e6), false);
    let hundred_links = throughput(&state, if quick { 100_000 } else { 1_000_000 }, 100, Some(100e3), true);
    let zstd = RecorderOptions { compression: Compression::Zstd, ..Default::default() };
    let hundred_links_zstd = throughput_with(&state, if quick { 100_000 } else { 1_000_000 }, 100, Some(100e3), zstd);
    let meta = json!({
        "frame_bytes": state.len(),
        "unpaced_raw": unpaced_raw, "unpaced_json": unpaced_json, "paced_1m_raw": million, "paced_1m_raw_64b": million_small, "links_100_at_1khz": hundred_links, "links_100_at_1khz_zstd": hundred_links_zstd,
    });
    println!("record: {meta}");
    if let Ok(path) = std::env::var("ROBOWIRE_BENCH_META_RECORD") {
        std::fs::write(path, meta.to_string()).unwrap();
    }
}

/// `frames` copies of `frame` tapped by one thread over `links` links in turn, as fast as it can
/// or at `rate` frames/s (a busy wait to each frame's due time), into a recorder with its JSON
/// thread or without: what was written per second of the run, and what was dropped or skipped.
fn throughput(frame: &[u8], frames: u64, links: u16, rate: Option<f64>, json: bool) -> serde_json::Value {
    throughput_with(frame, frames, links, rate, RecorderOptions { json, ..Default::default() })
}

/// As [`throughput`], with `options`; also the file's size.
fn throughput_with(
    frame: &[u8],
    frames: u64,
    links: u16,
    rate: Option<f64>,
    options: RecorderOptions,
) -> serde_json::Value {
    let path = temp("throughput");
    let json = options.json;
    let recorder = Recorder::create_with(&path, "bench", options).unwrap();
    let taps: Vec<_> = (0..links).map(|n| recorder.link(&format!("zsl1-{n}/high_level"), &HIGH_LEVEL)).collect();
    let start = Instant::now();
    for n in 0..frames {
        if let Some(rate) = rate {
            let due = Duration::from_secs_f64(n as f64 / rate);
            while start.elapsed() < due {
                std::hint::spin_loop();
            }
        }
        taps[(n % u64::from(links)) as usize].record(Direction::Received, frame);
    }
    let tapped_s = start.elapsed().as_secs_f64();
    let summary = recorder.finish().unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
    let _ = std::fs::remove_file(&path);
    json!({
        "offered": frames, "offered_per_s": frames as f64 / tapped_s, "written": summary.frames,
        "written_per_s": summary.frames as f64 / elapsed, "mb_per_s": bytes as f64 / elapsed / 1e6,
        "dropped": summary.dropped, "json_skipped": summary.json_skipped, "links": links, "json": json,
        "file_bytes": bytes,
    })
}
