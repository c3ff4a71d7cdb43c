//! `robowire decode lowcmd|lowstate|lowcmd-hg|lowstate-hg`: Unitree low-level messages (Go2 and
//! HG `LowCmd_`/`LowState_`), from their struct image or a DDS CDR payload.

use std::process::ExitCode;

use anyhow::bail;
use clap::Args;
use serde::Serialize;
use serde_json::Value;
use unitree_proto::{CdrEncoding, Message, Unverified};

use super::{cell, json_value};
use crate::hex;

/// Which Unitree message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum UnitreeMessage {
    /// Go2 `unitree_go::msg::dds_::LowCmd_`.
    LowCmd,
    /// Go2 `unitree_go::msg::dds_::LowState_`.
    LowState,
    /// HG `unitree_hg::msg::dds_::LowCmd_`.
    HgLowCmd,
    /// HG `unitree_hg::msg::dds_::LowState_`.
    HgLowState,
}

/// What to do with a Unitree message type, chosen at run time ([`UnitreeMessage::dispatch`]).
pub(crate) trait WithMessage {
    /// The result.
    type Output;
    /// Does it with `M`.
    fn with<M: Message + Serialize + serde::de::DeserializeOwned>(self) -> Self::Output;
}

impl UnitreeMessage {
    /// Calls `action` with this message's Rust type.
    pub(crate) fn dispatch<A: WithMessage>(self, action: A) -> A::Output {
        match self {
            Self::LowCmd => action.with::<unitree_proto::LowCmd>(),
            Self::LowState => action.with::<unitree_proto::LowState>(),
            Self::HgLowCmd => action.with::<unitree_proto::HgLowCmd>(),
            Self::HgLowState => action.with::<unitree_proto::HgLowState>(),
        }
    }
}

#[derive(Debug, Args)]
pub(crate) struct DecodeArgs {
    /// The struct image (or with --cdr the DDS payload) in hex, or '-' for standard input.
    hex: String,
    /// The bytes are a DDS CDR payload (XCDR1 or XCDR2, told by its header), not the struct image.
    #[arg(long)]
    cdr: bool,
    /// Print the message as one JSON object with the IDL field names.
    #[arg(long)]
    json: bool,
    /// Decode even if the CRC or the padding is wrong (the problem is reported on standard error).
    #[arg(long)]
    lenient: bool,
}

pub(crate) fn decode(message: UnitreeMessage, args: &DecodeArgs) -> anyhow::Result<ExitCode> {
    struct Decode<'a>(&'a DecodeArgs);
    impl WithMessage for Decode<'_> {
        type Output = anyhow::Result<ExitCode>;
        fn with<M: Message + Serialize + serde::de::DeserializeOwned>(self) -> Self::Output {
            decode_as::<M>(self.0)
        }
    }
    message.dispatch(Decode(args))
}

fn decode_as<M: Message + Serialize>(args: &DecodeArgs) -> anyhow::Result<ExitCode> {
    let bytes = hex::parse_arg(&args.hex)?;
    let name = M::DDS_TYPE_NAME;
    let (unverified, what): (Unverified<M>, String) = if args.cdr {
        let (u, encoding) =
            M::decode_cdr_unverified(&bytes).map_err(|e| anyhow::anyhow!("{name}: {}", e.without_message()))?;
        (
            u,
            format!(
                "{} CDR payload, {} bytes",
                if encoding == CdrEncoding::Xcdr1 { "XCDR1" } else { "XCDR2" },
                bytes.len()
            ),
        )
    } else {
        let u = M::decode_image_unverified(&bytes).map_err(|e| anyhow::anyhow!("{name}: {}", e.without_message()))?;
        (u, format!("struct image, {} bytes", bytes.len()))
    };
    let problem = match unverified.verify() {
        Ok(_) => None,
        Err(e) => Some(e.without_message().to_string()),
    };
    if let Some(problem) = &problem
        && !args.lenient
    {
        bail!("{name}: {problem} (--lenient decodes it anyway)");
    }
    let json = json_value(&unverified.message)?;
    if args.json {
        println!("{}", serde_json::to_string(&json)?);
    } else {
        let crc = &unverified.crc;
        let status = if crc.is_ok() { "ok".to_string() } else { format!("MISMATCH, computed 0x{:08x}", crc.computed) };
        println!("{name} ({what}), crc 0x{:08x} {status}", crc.received);
        print_human(&json);
    }
    if let Some(problem) = problem {
        eprintln!("warning: {problem}");
    }
    Ok(ExitCode::SUCCESS)
}

/// Scalars as `name = value`, nested structs as `name.field = value`, arrays of structs as a
/// table with one row per element.
fn print_human(json: &Value) {
    let Some(object) = json.as_object() else { return };
    for (name, value) in object {
        match value {
            Value::Array(rows) if rows.first().is_some_and(Value::is_object) => {
                let columns: Vec<&String> = rows[0].as_object().map(|o| o.keys().collect()).unwrap_or_default();
                println!("{name}[{}]:", rows.len());
                let header: Vec<String> = columns.iter().map(|c| format!("{c:>12}")).collect();
                println!("  {:>3} {}", "#", header.join(" "));
                for (i, row) in rows.iter().enumerate() {
                    let cells: Vec<String> =
                        columns.iter().map(|c| format!("{:>12}", cell(&row[c.as_str()]))).collect();
                    println!("  {i:>3} {}", cells.join(" "));
                }
            }
            Value::Object(fields) => {
                for (field, v) in fields {
                    println!("{name}.{field} = {}", cell(v));
                }
            }
            other => println!("{name} = {}", cell(other)),
        }
    }
}
