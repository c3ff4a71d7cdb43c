//! `robowire decode zsl`: a ZSL-1 UDP datagram, told by its length and magic, decoded strictly.

use std::process::ExitCode;

use clap::Args;
use serde_json::Value;
use zsl_proto::udp::AnyDatagram;

use super::json_value;
use crate::hex;

#[derive(Debug, Args)]
pub(crate) struct ZslDecodeArgs {
    /// The datagram in hex (40, 248, 272 or 560 bytes), or '-' for standard input.
    hex: String,
    /// One JSON object on one line.
    #[arg(long)]
    json: bool,
}

/// The datagram as JSON (zsl-proto's `serde` form).
fn decode(bytes: &[u8]) -> anyhow::Result<Value> {
    json_value(&AnyDatagram::decode(bytes)?)
}

pub(super) fn run(args: &ZslDecodeArgs) -> anyhow::Result<ExitCode> {
    let bytes = hex::parse_arg(&args.hex)?;
    let value = decode(&bytes)?;
    if args.json {
        println!("{}", serde_json::to_string(&value)?);
    } else {
        println!("{}", serde_json::to_string_pretty(&value)?);
    }
    Ok(ExitCode::SUCCESS)
}
