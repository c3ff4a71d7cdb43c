//! `robowire decode|encode lowcmd|lowstate|lowcmd-hg|lowstate-hg`: Unitree low-level messages.

use std::io::Read;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use clap::{Args, ValueEnum};
use lowcmd_proto::json::{from_json, to_json};
use lowcmd_proto::{CdrEncoding, HgLowCmd, HgLowState, LowCmd, LowState, Message, Unverified};
use serde_json::Value;

use crate::hex;

/// Which message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    LowCmd,
    LowState,
    HgLowCmd,
    HgLowState,
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

/// CDR representation to encode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum Cdr {
    /// XCDR1 (`00 01 00 00`), what the vendor's publishers write.
    Xcdr1,
    /// XCDR2 (`00 07 00 00`).
    Xcdr2,
}

#[derive(Debug, Args)]
pub(crate) struct EncodeArgs {
    /// A JSON file with the message's IDL fields ('-' for standard input); `crc` is ignored.
    file: PathBuf,
    /// Print the DDS CDR payload in this representation instead of the struct image.
    #[arg(long, value_enum)]
    cdr: Option<Cdr>,
}

pub(crate) fn decode(kind: Kind, args: &DecodeArgs) -> anyhow::Result<ExitCode> {
    match kind {
        Kind::LowCmd => decode_as::<LowCmd>(args),
        Kind::LowState => decode_as::<LowState>(args),
        Kind::HgLowCmd => decode_as::<HgLowCmd>(args),
        Kind::HgLowState => decode_as::<HgLowState>(args),
    }
}

pub(crate) fn encode(kind: Kind, args: &EncodeArgs) -> anyhow::Result<ExitCode> {
    match kind {
        Kind::LowCmd => encode_as::<LowCmd>(args),
        Kind::LowState => encode_as::<LowState>(args),
        Kind::HgLowCmd => encode_as::<HgLowCmd>(args),
        Kind::HgLowState => encode_as::<HgLowState>(args),
    }
}

fn decode_as<M: Message>(args: &DecodeArgs) -> anyhow::Result<ExitCode> {
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
    let json = to_json(&unverified.message);
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

fn encode_as<M: Message>(args: &EncodeArgs) -> anyhow::Result<ExitCode> {
    let text = if args.file.as_os_str() == "-" {
        let mut text = String::new();
        std::io::stdin().read_to_string(&mut text).context("reading JSON from standard input")?;
        text
    } else {
        std::fs::read_to_string(&args.file).with_context(|| format!("reading {}", args.file.display()))?
    };
    let value: Value = serde_json::from_str(&text).context("parsing the JSON")?;
    let message: M = from_json(&value).with_context(|| format!("the JSON is no {}", M::DDS_TYPE_NAME))?;
    let bytes = match args.cdr {
        None => {
            let mut out = vec![0u8; M::IMAGE_LEN];
            message.encode_image(&mut out)?;
            out
        }
        Some(cdr) => {
            let encoding = if cdr == Cdr::Xcdr1 { CdrEncoding::Xcdr1 } else { CdrEncoding::Xcdr2 };
            let mut out = vec![0u8; M::cdr_len(encoding)];
            message.encode_cdr(encoding, &mut out)?;
            out
        }
    };
    println!("{}", hex::format(&bytes));
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
                        columns.iter().map(|c| format!("{:>12}", compact(&row[c.as_str()]))).collect();
                    println!("  {i:>3} {}", cells.join(" "));
                }
            }
            Value::Object(fields) => {
                for (field, v) in fields {
                    println!("{name}.{field} = {}", compact(v));
                }
            }
            other => println!("{name} = {}", compact(other)),
        }
    }
}

/// Floats with at most 7 significant digits, the rest as JSON.
fn compact(value: &Value) -> String {
    match value {
        Value::Number(n) if n.is_f64() => {
            let v = n.as_f64().unwrap_or(f64::NAN) as f32;
            format!("{v}")
        }
        Value::Array(items) => format!("[{}]", items.iter().map(compact).collect::<Vec<_>>().join(", ")),
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}
