//! `robowire decode rtps`: RTPS (DDS) datagrams as JSON, from hex, a file of hex lines, or a
//! pcap capture. A datagram the wire layer refuses prints no JSON: one `error:` line on standard
//! error, and exit status 1 (after the other datagrams of a file or capture).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{ArgGroup, Args};
use serde_json::{Map, Value, json};

use super::pcap::{Capture, Packet};
use super::rtps_json::datagram;
use crate::hex;

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("input").required(true).args(["hex", "file", "pcap"])))]
pub(crate) struct RtpsDecodeArgs {
    /// One datagram in hex (spaces, ':' and '0x' allowed), or '-' for standard input: one JSON
    /// document.
    hex: Option<String>,
    /// A file of datagrams in hex, one a line (blank lines and lines starting with '#' skipped):
    /// one JSON object per line, with its "line".
    #[arg(long, value_name = "FILE")]
    file: Option<PathBuf>,
    /// A classic libpcap capture (not pcapng) of UDP over IPv4: one JSON object per RTPS
    /// datagram, with its "packet", "time", "source" and "destination"; other packets are
    /// skipped and counted on standard error.
    #[arg(long, value_name = "FILE.pcap")]
    pcap: Option<PathBuf>,
}

pub(super) fn run(args: &RtpsDecodeArgs) -> anyhow::Result<ExitCode> {
    if let Some(path) = &args.file {
        return lines(path);
    }
    if let Some(path) = &args.pcap {
        return capture(path);
    }
    let bytes = hex::parse_arg(args.hex.as_deref().unwrap_or("-"))?;
    match datagram(&bytes) {
        Ok(json) => {
            println!("{}", serde_json::to_string_pretty(&Value::Object(json))?);
            Ok(ExitCode::SUCCESS)
        }
        Err(refusal) => {
            eprintln!("error: {refusal}");
            Ok(ExitCode::FAILURE)
        }
    }
}

/// `--file`: each line's JSON, `"line"` first.
fn lines(path: &PathBuf) -> anyhow::Result<ExitCode> {
    let file = File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut out = std::io::stdout().lock();
    let mut failed = 0u64;
    for (i, line) in BufReader::new(file).split(b'\n').enumerate() {
        let line = line.with_context(|| format!("reading {}", path.display()))?;
        let number = i + 1;
        let text = String::from_utf8_lossy(&line);
        let text = text.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let decoded =
            hex::parse(text).map_err(|e| format!("{e:#}")).and_then(|b| datagram(&b).map_err(|r| r.to_string()));
        match decoded {
            Ok(json) => print_line(&mut out, [("line", json!(number))], json)?,
            Err(why) => {
                failed += 1;
                eprintln!("error: line {number}: {why}");
            }
        }
    }
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// `--pcap`: each RTPS datagram's JSON, `"packet"`, `"time"`, `"source"`, `"destination"` first;
/// a summary of what was skipped on standard error.
fn capture(path: &PathBuf) -> anyhow::Result<ExitCode> {
    let file = File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let mut capture = Capture::new(BufReader::new(file)).with_context(|| path.display().to_string())?;
    let mut out = std::io::stdout().lock();
    let (mut packets, mut decoded, mut failed) = (0u64, 0u64, 0u64);
    let mut skipped: BTreeMap<&'static str, u64> = BTreeMap::new();
    let mut broken = false;
    loop {
        let number = packets + 1;
        let packet = match capture.next_packet() {
            Ok(Some(packet)) => packet,
            Ok(None) => break,
            Err(e) => {
                // The file cannot be followed past a bad record.
                eprintln!("error: packet {number}: {e:#}");
                broken = true;
                break;
            }
        };
        packets = number;
        let udp = match packet {
            Packet::Udp(udp) if udp.payload.starts_with(b"RTPS") => udp,
            Packet::Udp(_) => {
                *skipped.entry("UDP but not RTPS").or_default() += 1;
                continue;
            }
            Packet::Skipped(why) => {
                *skipped.entry(why).or_default() += 1;
                continue;
            }
        };
        match datagram(&udp.payload) {
            Ok(json) => {
                decoded += 1;
                let meta = [
                    ("packet", json!(number)),
                    ("time", json!(udp.time)),
                    ("source", json!(udp.source.to_string())),
                    ("destination", json!(udp.destination.to_string())),
                ];
                print_line(&mut out, meta, json)?;
            }
            Err(refusal) => {
                failed += 1;
                eprintln!("error: packet {number}: {refusal}");
            }
        }
    }
    let skipped_text = skipped.iter().map(|(why, n)| format!("{n} {why}")).collect::<Vec<_>>().join(", ");
    eprintln!(
        "{}: {packets} packets, {decoded} RTPS datagrams decoded, {failed} refused, {} skipped{}",
        path.display(),
        skipped.values().sum::<u64>(),
        if skipped_text.is_empty() { String::new() } else { format!(" ({skipped_text})") },
    );
    Ok(if failed == 0 && !broken { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// One JSON object on one line: `meta` first, then the datagram's fields.
fn print_line<const N: usize>(
    out: &mut impl Write,
    meta: [(&str, Value); N],
    json: Map<String, Value>,
) -> anyhow::Result<()> {
    let mut object: Map<String, Value> = meta.into_iter().map(|(k, v)| (k.to_string(), v)).collect();
    object.extend(json);
    writeln!(out, "{}", serde_json::to_string(&Value::Object(object))?)?;
    Ok(())
}
