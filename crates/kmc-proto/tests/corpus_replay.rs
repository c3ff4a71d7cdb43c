//! Replays the fuzz seed corpus (made from the golden fixtures, as `cargo xtask fuzz` makes it)
//! through the same checks the fuzz targets run.

use kmc_proto::harness;

#[derive(serde::Deserialize)]
struct Fixture {
    direction: String,
    hex: String,
}

fn fixtures() -> Vec<Fixture> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/kmc/frames.json");
    let text = std::fs::read_to_string(path).expect("fixtures/kmc/frames.json");
    serde_json::from_str(&text).expect("fixture schema")
}

fn hex(s: &str) -> Vec<u8> {
    (0..s.len()).step_by(2).map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap()).collect()
}

/// The seeds of one direction: each frame alone, then all of them back to back, each with the
/// chunk-size byte 0 (1-byte chunks) and 7 (8-byte chunks).
fn seeds(direction: &str) -> Vec<Vec<u8>> {
    let frames: Vec<Vec<u8>> = fixtures().iter().filter(|f| f.direction == direction).map(|f| hex(&f.hex)).collect();
    assert!(!frames.is_empty());
    let mut streams: Vec<Vec<u8>> = frames.clone();
    streams.push(frames.concat());
    let mut out = Vec::new();
    for stream in streams {
        for chunk in [0u8, 7] {
            let mut seed = vec![chunk];
            seed.extend_from_slice(&stream);
            out.push(seed);
        }
    }
    out
}

#[test]
fn host_to_chassis_seeds() {
    for seed in seeds("host->chassis") {
        harness::host_frame_stream(&seed);
    }
}

#[test]
fn chassis_to_host_seeds() {
    for seed in seeds("chassis->host") {
        harness::chassis_frame_stream(&seed);
    }
}

#[test]
fn committed_fuzz_corpus_if_present() {
    // Inputs the fuzzer found interesting and that were committed under fuzz/regressions/.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/regressions");
    for (target, check) in [
        ("kmc_host_decoder", harness::chassis_frame_stream as fn(&[u8])),
        ("kmc_device_decoder", harness::host_frame_stream),
    ] {
        let Ok(entries) = std::fs::read_dir(format!("{dir}/{target}")) else { continue };
        for entry in entries {
            check(&std::fs::read(entry.unwrap().path()).unwrap());
        }
    }
}
