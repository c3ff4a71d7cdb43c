//! `robowire decode kmc`: KMC chassis UART frames from either side of the line.

use std::process::ExitCode;

use clap::{Args, ValueEnum};
use kmc_proto::{ChassisFrame, ChassisFrameDecoder, HostFrame, HostFrameDecoder, StreamDecoder};

use super::json_value;
use crate::hex;

/// Who sent the bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum Direction {
    /// Sent by the host (host → chassis: 0xA5, 0xB3 requests, 0xAF requests).
    Host,
    /// Sent by the device (chassis → host: 0xB3 speed, 0xAF responses).
    Device,
}

#[derive(Debug, Args)]
pub(crate) struct KmcDecodeArgs {
    /// The bytes in hex (spaces, ':' and '0x' allowed), or '-' to read them from standard input.
    hex: String,
    /// Who sent the bytes: the host (commands) or the device (responses).
    #[arg(long, value_enum, default_value = "host")]
    direction: Direction,
    /// One JSON object per frame on standard output (field names of the spec); the decoder
    /// counters go to standard error.
    #[arg(long)]
    json: bool,
}

pub(super) fn run(args: &KmcDecodeArgs) -> anyhow::Result<ExitCode> {
    let bytes = hex::parse_arg(&args.hex)?;
    let found = match args.direction {
        Direction::Host => print_stream(&bytes, HostFrameDecoder::new(), HostFrame::buffer_len, args.json)?,
        Direction::Device => print_stream(&bytes, ChassisFrameDecoder::new(), ChassisFrame::buffer_len, args.json)?,
    };
    Ok(if found > 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// Prints every frame in `bytes` and the decoder's counters; returns the number of frames.
fn print_stream<D>(bytes: &[u8], mut decoder: D, frame_len: fn(&D::Frame) -> usize, json: bool) -> anyhow::Result<u64>
where
    D: StreamDecoder,
    D::Frame: serde::Serialize,
{
    let mut pos = 0;
    loop {
        let step = decoder.decode(&bytes[pos..]);
        pos += step.consumed;
        let Some(frame) = step.frame else { break };
        let len = frame_len(&frame);
        let start = pos - len;
        if json {
            println!("{}", serde_json::to_string(&frame)?);
        } else {
            println!("@{start:<4} {len:<3} {}  [{}]", human(&json_value(&frame)?), hex::format(&bytes[start..pos]));
        }
    }
    let c = decoder.counters();
    let pending = bytes.len() - pos;
    let summary = format!(
        "{} bytes: frames={} skipped_bytes={} rejected_candidates={} pending_bytes={pending}{}",
        bytes.len(),
        c.frames,
        c.skipped_bytes,
        c.rejected_candidates,
        if pending > 0 { " (an incomplete frame at the end)" } else { "" }
    );
    if json {
        eprintln!("{summary}")
    } else {
        println!("{summary}")
    }
    Ok(c.frames)
}

/// `pc_control velocity_mps=0.5 curvature_per_m=0.4`.
fn human(value: &serde_json::Value) -> String {
    let Some(object) = value.as_object() else { return value.to_string() };
    let mut out = object.get("frame").and_then(|f| f.as_str()).unwrap_or("?").to_string();
    for (key, v) in object.iter().filter(|(k, _)| *k != "frame") {
        out.push_str(&format!(" {key}={v}"));
    }
    out
}
