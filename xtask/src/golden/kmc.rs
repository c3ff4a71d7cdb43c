//! KMC golden frames (`fixtures/kmc/frames.json`): the 12 worked examples of the spec.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use kmc_proto::{
    ChassisFrame, ChassisFrameDecoder, DecoderCounters, EncodeError, FrameBuffer, HostFrame, HostFrameDecoder,
    MAX_FRAME_LEN, StreamDecoder,
};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{Outcome, to_json};
use crate::{hex_decode, hex_encode, workspace_root};

/// One KMC golden frame (`fixtures/kmc/frames.json`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct KmcFixture {
    /// Worked example number in the spec (§5).
    pub example: u32,
    /// Identifier.
    pub name: String,
    /// What the frame means.
    pub description: String,
    /// `host->chassis` or `chassis->host`.
    pub direction: String,
    /// The frame, lowercase hex.
    pub hex: String,
    /// The decoded frame as `robowire decode kmc --json` prints it.
    pub fields: Value,
}

/// The KMC fixture file.
pub fn kmc_fixture_path() -> PathBuf {
    workspace_root().join("fixtures/kmc/frames.json")
}

/// Loads the KMC fixtures.
pub fn load_kmc(path: &Path) -> anyhow::Result<Vec<KmcFixture>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("parsing {}", path.display()))
}

/// Decodes, compares and re-encodes one fixture; returns the decoded fields and the problems.
fn check_one(fixture: &KmcFixture) -> anyhow::Result<(Option<Value>, Vec<String>)> {
    let bytes = hex_decode(&fixture.hex)?;
    let mut out = [0u8; MAX_FRAME_LEN];
    let (fields, reencoded) = match fixture.direction.as_str() {
        "host->chassis" => match HostFrame::parse(&bytes) {
            Ok(frame) => (to_json(&frame)?, frame.emit(&mut out).map(|n| out[..n].to_vec())),
            Err(e) => return Ok((None, vec![format!("does not decode: {e}")])),
        },
        "chassis->host" => match ChassisFrame::parse(&bytes) {
            Ok(frame) => (to_json(&frame)?, frame.emit(&mut out).map(|n| out[..n].to_vec())),
            Err(e) => return Ok((None, vec![format!("does not decode: {e}")])),
        },
        other => bail!("fixture {}: unknown direction {other:?}", fixture.name),
    };
    let mut problems = Vec::new();
    if fields != fixture.fields {
        problems.push(format!("decoded {fields} but the fixture expects {}", fixture.fields));
    }
    match reencoded {
        Ok(again) if again == bytes => {}
        Ok(again) => problems.push(format!("re-encodes to {} instead of {}", hex_encode(&again), fixture.hex)),
        Err(e) => problems.push(format!("does not re-encode: {e}")),
    }
    Ok((Some(fields), problems))
}

/// Each direction's fixtures back to back through its stream decoder, fed byte by byte: every
/// frame comes out, in order, and nothing is skipped.
fn check_streams(fixtures: &[KmcFixture]) -> anyhow::Result<Vec<String>> {
    let mut problems = Vec::new();
    for direction in ["host->chassis", "chassis->host"] {
        let frames: Vec<Vec<u8>> = fixtures
            .iter()
            .filter(|f| f.direction == direction)
            .map(|f| hex_decode(&f.hex))
            .collect::<Result<_, _>>()?;
        let stream = frames.concat();
        let (decoded, counters) = if direction == "host->chassis" {
            byte_by_byte(HostFrameDecoder::new(), &stream, HostFrame::emit)
        } else {
            byte_by_byte(ChassisFrameDecoder::new(), &stream, ChassisFrame::emit)
        };
        if decoded != frames || counters.skipped_bytes != 0 || counters.rejected_candidates != 0 {
            problems.push(format!(
                "{direction} stream of {} fixtures: {} frames decoded, counters {counters:?}",
                frames.len(),
                decoded.len()
            ));
        }
    }
    Ok(problems)
}

/// Feeds `stream` one byte at a time; returns the re-encoded frames and the counters.
fn byte_by_byte<D: StreamDecoder>(
    decoder: D,
    stream: &[u8],
    emit: fn(&D::Frame, &mut [u8]) -> Result<usize, EncodeError>,
) -> (Vec<Vec<u8>>, DecoderCounters) {
    let mut rx: FrameBuffer<D, 128> = FrameBuffer::new(decoder);
    let mut decoded = Vec::new();
    for byte in stream {
        rx.push_all(std::slice::from_ref(byte), |f| {
            let mut out = [0u8; MAX_FRAME_LEN];
            decoded.push(emit(&f, &mut out).map(|n| out[..n].to_vec()).unwrap_or_default());
        });
    }
    (decoded, rx.counters())
}

/// Runs the KMC suite on `path`; with `bless`, rewrites mismatching `fields` and saves.
pub fn check_kmc(path: &Path, bless: bool) -> anyhow::Result<Vec<Outcome>> {
    let mut fixtures = load_kmc(path)?;
    let mut outcomes = Vec::new();
    let mut changed = false;
    for fixture in &mut fixtures {
        let (fields, mut problems) = check_one(fixture)?;
        let mut blessed = false;
        if bless
            && let Some(fields) = fields
            && fields != fixture.fields
        {
            fixture.fields = fields;
            blessed = true;
            changed = true;
            problems.retain(|p| !p.starts_with("decoded "));
        }
        outcomes.push(Outcome { name: fixture.name.clone(), problems, blessed });
    }
    let stream_problems = check_streams(&fixtures)?;
    outcomes.push(Outcome { name: "streams (byte by byte)".into(), problems: stream_problems, blessed: false });
    if changed {
        let text = serde_json::to_string_pretty(&fixtures)? + "\n";
        std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(outcomes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The golden suite runs under `cargo test` too.
    #[test]
    fn kmc_fixtures_pass() {
        let outcomes = check_kmc(&kmc_fixture_path(), false).unwrap();
        assert_eq!(outcomes.len(), 13, "12 worked examples of spec §5 and the stream check");
        for outcome in outcomes {
            assert!(outcome.problems.is_empty(), "{}: {:?}", outcome.name, outcome.problems);
        }
    }

    /// A fixture that disagrees with the codec fails, and only `bless` rewrites its fields.
    #[test]
    fn a_wrong_expectation_fails_and_bless_rewrites_only_the_fields() {
        let dir = std::env::temp_dir().join(format!("robowire-golden-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("frames.json");
        let mut fixtures = load_kmc(&kmc_fixture_path()).unwrap();
        fixtures[0].fields["velocity_mps"] = serde_json::json!(0.25);
        std::fs::write(&path, serde_json::to_string(&fixtures).unwrap()).unwrap();
        let failing = check_kmc(&path, false).unwrap();
        assert_eq!(failing.iter().filter(|o| !o.problems.is_empty()).count(), 1);
        let blessed = check_kmc(&path, true).unwrap();
        assert!(blessed.iter().all(|o| o.problems.is_empty()));
        assert!(blessed[0].blessed);
        let rewritten = load_kmc(&path).unwrap();
        assert_eq!(rewritten[0].fields["velocity_mps"], serde_json::json!(0.5));
        assert_eq!(rewritten[0].hex, fixtures[0].hex);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
