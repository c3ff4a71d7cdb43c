//! `robowire decode …`: frames and messages from hex, for humans or (`--json`) for scripts.
//!
//! The JSON of every codec is the codec's own (`serde` features, floats in robowire-core's one
//! form); the human form is derived from it here.

mod kmc;
mod pcap;
mod rtps;
mod rtps_json;
mod rtps_names;
mod rtps_params;
pub(crate) mod unitree;
pub(crate) mod zsl;

use std::process::ExitCode;

use clap::{Args, Subcommand};
use serde::Serialize;
use serde_json::Value;

use unitree::UnitreeMessage;

#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub(crate) struct DecodeArgs {
    /// Summarize an MCAP capture instead: channels, counts, rates, gaps, decode errors.
    #[arg(long, value_name = "FILE.mcap")]
    mcap: Option<std::path::PathBuf>,
    /// With --mcap: the summary as one JSON object.
    #[arg(long, requires = "mcap")]
    json: bool,
    #[command(subcommand)]
    command: Option<DecodeCommand>,
}

#[derive(Debug, Subcommand)]
pub(crate) enum DecodeCommand {
    /// KMC chassis UART frames (0xA5, 0xB3, 0xAF). Exit status 1 if no frame was found.
    Kmc(kmc::KmcDecodeArgs),
    /// A ZSL-1 / ZSL-1W UDP datagram, told by its length and magic, decoded strictly.
    Zsl(zsl::ZslDecodeArgs),
    /// RTPS (DDS) datagrams: one in hex, a file of hex lines (--file) or a pcap capture (--pcap),
    /// as JSON. Exit status 1 if any datagram was refused.
    Rtps(rtps::RtpsDecodeArgs),
    /// Unitree Go2 LowCmd (812-byte struct image, or a CDR payload with --cdr).
    Lowcmd(unitree::DecodeArgs),
    /// Unitree Go2 LowState (1180-byte struct image, or a CDR payload with --cdr).
    Lowstate(unitree::DecodeArgs),
    /// Unitree HG (G1, H1-2) LowCmd (1004 bytes).
    LowcmdHg(unitree::DecodeArgs),
    /// Unitree HG (G1, H1-2) LowState (2092 bytes).
    LowstateHg(unitree::DecodeArgs),
}

pub(crate) fn run(args: &DecodeArgs) -> anyhow::Result<ExitCode> {
    let command = match (&args.mcap, &args.command) {
        (Some(path), _) => return crate::cmd::record::summarize(path, args.json),
        (None, Some(command)) => command,
        (None, None) => anyhow::bail!("give what to decode (kmc, zsl, rtps, lowcmd, …) or --mcap FILE"),
    };
    match command {
        DecodeCommand::Kmc(args) => kmc::run(args),
        DecodeCommand::Zsl(args) => zsl::run(args),
        DecodeCommand::Rtps(args) => rtps::run(args),
        DecodeCommand::Lowcmd(args) => unitree::decode(UnitreeMessage::LowCmd, args),
        DecodeCommand::Lowstate(args) => unitree::decode(UnitreeMessage::LowState, args),
        DecodeCommand::LowcmdHg(args) => unitree::decode(UnitreeMessage::HgLowCmd, args),
        DecodeCommand::LowstateHg(args) => unitree::decode(UnitreeMessage::HgLowState, args),
    }
}

/// A value's JSON, through text, so that floats keep the shortest form their codec wrote
/// (`0.4`, not `0.4000000059604645`) when printed again.
pub(crate) fn json_value<T: Serialize>(value: &T) -> anyhow::Result<Value> {
    Ok(serde_json::from_str(&serde_json::to_string(value)?)?)
}

/// A JSON value in a table cell or after `name =`: strings bare, the rest as JSON.
pub(crate) fn cell(value: &Value) -> String {
    match value {
        Value::String(s) => s.clone(),
        Value::Array(items) => format!("[{}]", items.iter().map(cell).collect::<Vec<_>>().join(", ")),
        other => other.to_string(),
    }
}
