//! `robowire encode lowcmd|lowstate|lowcmd-hg|lowstate-hg`: a Unitree message from JSON with its
//! IDL field names, as the struct image (CRC filled in) or a DDS CDR payload.

use std::io::Read;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, Subcommand, ValueEnum};
use serde::de::DeserializeOwned;
use unitree_proto::{CdrEncoding, Message};

use crate::cmd::decode::unitree::{UnitreeMessage, WithMessage};
use crate::hex;

/// `robowire encode …`.
#[derive(Debug, Subcommand)]
pub(crate) enum EncodeCommand {
    /// Unitree Go2 LowCmd from JSON: the struct image (CRC filled in), or a CDR payload.
    Lowcmd(EncodeArgs),
    /// Unitree Go2 LowState from JSON.
    Lowstate(EncodeArgs),
    /// Unitree HG LowCmd from JSON.
    LowcmdHg(EncodeArgs),
    /// Unitree HG LowState from JSON.
    LowstateHg(EncodeArgs),
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

pub(crate) fn run(command: &EncodeCommand) -> anyhow::Result<ExitCode> {
    let (message, args) = match command {
        EncodeCommand::Lowcmd(args) => (UnitreeMessage::LowCmd, args),
        EncodeCommand::Lowstate(args) => (UnitreeMessage::LowState, args),
        EncodeCommand::LowcmdHg(args) => (UnitreeMessage::HgLowCmd, args),
        EncodeCommand::LowstateHg(args) => (UnitreeMessage::HgLowState, args),
    };
    struct Encode<'a>(&'a EncodeArgs);
    impl WithMessage for Encode<'_> {
        type Output = anyhow::Result<ExitCode>;
        fn with<M: Message + serde::Serialize + DeserializeOwned>(self) -> Self::Output {
            encode_as::<M>(self.0)
        }
    }
    message.dispatch(Encode(args))
}

fn encode_as<M: Message + DeserializeOwned>(args: &EncodeArgs) -> anyhow::Result<ExitCode> {
    let text = if args.file.as_os_str() == "-" {
        let mut text = String::new();
        std::io::stdin().read_to_string(&mut text).context("reading JSON from standard input")?;
        text
    } else {
        std::fs::read_to_string(&args.file).with_context(|| format!("reading {}", args.file.display()))?
    };
    let message: M = serde_json::from_str(&text).with_context(|| format!("the JSON is no {}", M::DDS_TYPE_NAME))?;
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
