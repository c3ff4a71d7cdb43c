//! `robowire decode zsl`: a ZSL-1 UDP datagram, told by its length and magic, decoded strictly.

use std::process::ExitCode;

use anyhow::bail;
use clap::Args;
use serde_json::Value;
use zsl_proto::udp::{HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState};

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
    match bytes.len() {
        HighLevelCommand::LEN => json_value(&HighLevelCommand::decode(bytes)?.0),
        LowLevelCommand::LEN => json_value(&LowLevelCommand::decode(bytes)?.0),
        HighLevelState::LEN => json_value(&HighLevelState::decode_strict(bytes)?),
        LowLevelState::LEN => json_value(&LowLevelState::decode_strict(bytes)?),
        n => bail!(
            "{n} bytes is no ZSL-1 datagram (40 HighLevel command, 560 HighLevel state, 248 LowLevel command, 272 LowLevel state)"
        ),
    }
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
