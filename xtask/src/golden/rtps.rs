//! RTPS golden datagrams (`fixtures/rtps/*.hex`), captured on loopback from CycloneDDS 0.10.2,
//! Fast DDS 2.9 and rustdds 0.15.1 by `fixtures/rtps/capture.sh`: every datagram parses, its
//! submessages are the kinds the capture's independent dissector (`label.py`) named, every
//! little-endian submessage re-emits byte for byte, and every SPDP/SEDP payload parses as
//! participant or endpoint data. Vendor data: never rewritten.

use std::path::{Path, PathBuf};

use anyhow::Context;
use rtps_proto::discovery::{EndpointData, ParticipantData};
use rtps_proto::wire::{Message, Payload, Submessage};
use rtps_proto::{EntityId, Limits};

use super::Outcome;
use crate::{hex_decode, workspace_root};

/// The folder of the capture files.
pub fn fixtures_path() -> PathBuf {
    workspace_root().join("fixtures/rtps")
}

/// One datagram of a capture file: its label line and bytes.
struct Datagram {
    line: usize,
    label: String,
    bytes: Vec<u8>,
}

fn load(path: &Path) -> anyhow::Result<Vec<Datagram>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut out = Vec::new();
    let mut label = String::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if let Some(comment) = line.strip_prefix('#') {
            label = comment.trim().to_owned();
        } else if !line.is_empty() {
            let bytes = hex_decode(line).with_context(|| format!("{}:{}", path.display(), i + 1))?;
            out.push(Datagram { line: i + 1, label: std::mem::take(&mut label), bytes });
        }
    }
    Ok(out)
}

/// The submessage kinds a label names, e.g. "INFO_TS DATA(SPDP); from …" → [INFO_TS, DATA].
fn labelled_kinds(label: &str) -> Vec<String> {
    let kinds = label.split(';').next().unwrap_or_default();
    let mut out = Vec::new();
    let mut depth = 0;
    let mut word = String::new();
    for c in kinds.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            c if c.is_whitespace() && depth == 0 => out.extend((!word.is_empty()).then(|| std::mem::take(&mut word))),
            c if depth == 0 => word.push(c),
            _ => {}
        }
    }
    out.extend((!word.is_empty()).then_some(word));
    out
}

fn kind_name(s: &Submessage<'_>) -> &'static str {
    match s {
        Submessage::Data(_) => "DATA",
        Submessage::DataFrag(_) => "DATA_FRAG",
        Submessage::Heartbeat(_) => "HEARTBEAT",
        Submessage::HeartbeatFrag(_) => "HEARTBEAT_FRAG",
        Submessage::AckNack(_) => "ACKNACK",
        Submessage::NackFrag(_) => "NACK_FRAG",
        Submessage::Gap(_) => "GAP",
        Submessage::InfoTs(_) => "INFO_TS",
        Submessage::InfoDst(_) => "INFO_DST",
        Submessage::InfoSrc(_) => "INFO_SRC",
        Submessage::InfoReply(_) => "INFO_REPLY",
        Submessage::InfoReplyIp4(_) => "INFO_REPLY_IP4",
        Submessage::Pad => "PAD",
        Submessage::Unknown { kind, .. } if *kind >= 0x80 => "VENDOR",
        Submessage::Unknown { .. } => "UNKNOWN",
    }
}

/// The submessages' bytes (header included), walked by their lengths alone.
fn raw_submessages(datagram: &[u8]) -> Vec<&[u8]> {
    let mut out = Vec::new();
    let mut at = 20;
    while at + 4 <= datagram.len() {
        let little = datagram[at + 1] & 1 == 1;
        let len = [datagram[at + 2], datagram[at + 3]];
        let len = usize::from(if little { u16::from_le_bytes(len) } else { u16::from_be_bytes(len) });
        let end = if len == 0 && !matches!(datagram[at], 0x01 | 0x09) { datagram.len() } else { at + 4 + len };
        out.push(&datagram[at..end.min(datagram.len())]);
        at = end;
    }
    out
}

fn check_datagram(d: &Datagram, limits: &Limits) -> Vec<String> {
    let mut problems = Vec::new();
    let message = match Message::parse(&d.bytes) {
        Ok(m) => m,
        Err(e) => return vec![format!("the header is refused: {e}")],
    };
    let mut parsed = Vec::new();
    for s in message.submessages() {
        match s {
            Ok(s) => parsed.push(s),
            Err(e) => {
                problems.push(format!("submessage {} is refused: {e}", parsed.len() + 1));
                return problems;
            }
        }
    }
    let kinds: Vec<&str> = parsed.iter().map(kind_name).collect();
    let labelled = labelled_kinds(&d.label);
    if kinds != labelled {
        problems.push(format!("parsed {kinds:?}, the capture's dissector says {labelled:?}"));
    }
    for (s, raw) in parsed.iter().zip(raw_submessages(&d.bytes)) {
        if raw.get(1).is_some_and(|f| f & 1 == 1) {
            let mut buf = vec![0u8; raw.len() + 8];
            match s.emit(&mut buf) {
                Ok(n) if buf[..n] == *raw => {}
                Ok(n) => problems.push(format!(
                    "{} re-emits as {} bytes that differ from the {} captured",
                    kind_name(s),
                    n,
                    raw.len()
                )),
                Err(e) => problems.push(format!("{} does not re-emit: {e}", kind_name(s))),
            }
        }
        if let Submessage::Data(data) = s {
            let Payload::Data(payload) = data.payload else { continue };
            let key_hash = data
                .inline_qos
                .and_then(|q| q.find(rtps_proto::wire::pid::KEY_HASH))
                .and_then(|p| p.value.get(..16)?.try_into().ok());
            let outcome = match data.writer_id {
                EntityId::SPDP_WRITER => ParticipantData::parse_payload(payload, limits).map(|_| ()),
                EntityId::SEDP_PUBLICATIONS_WRITER | EntityId::SEDP_SUBSCRIPTIONS_WRITER => {
                    EndpointData::parse_payload(payload, key_hash, limits).map(|_| ())
                }
                _ => Ok(()),
            };
            if let Err(e) = outcome {
                problems.push(format!("discovery data of writer {:?} is refused: {e}", data.writer_id));
            }
        }
    }
    problems
}

/// Checks every capture file in `dir`.
pub fn check(dir: &Path) -> anyhow::Result<Vec<Outcome>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "hex"))
        .collect();
    files.sort();
    anyhow::ensure!(!files.is_empty(), "no capture files in {}", dir.display());
    let limits = Limits::default();
    let mut outcomes = Vec::new();
    for file in files {
        let stem = file.file_stem().and_then(|s| s.to_str()).unwrap_or("?").to_owned();
        for d in load(&file)? {
            let name = format!("{stem}:{} {}", d.line, labelled_kinds(&d.label).join(" "));
            outcomes.push(Outcome::new(name, check_datagram(&d, &limits)));
        }
    }
    Ok(outcomes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_name_the_kinds_outside_parentheses() {
        assert_eq!(labelled_kinds("INFO_TS DATA(SPDP); from a to b"), ["INFO_TS", "DATA"]);
        assert_eq!(labelled_kinds("INFO_DST ACKNACK(base 1, bits 0) HEARTBEAT"), ["INFO_DST", "ACKNACK", "HEARTBEAT"]);
    }
}
