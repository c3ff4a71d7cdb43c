//! `robowire dds …`: a small DDS inspector for any robot on the network.

use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::{Args, Subcommand};
use robowire_dds::qos::Qos;
use robowire_dds::{Participant, RawSample, Reader};
use serde::Serialize;
use unitree_proto::api::{REQUEST_TYPE_NAME, RESPONSE_TYPE_NAME, Request, Response};
use unitree_proto::{HgLowCmd, HgLowState, LowCmd, LowState, Message};

use super::dds_args::DdsArgs;
use crate::hex;

#[derive(Debug, Args)]
pub(crate) struct DdsCommandArgs {
    #[command(flatten)]
    dds: DdsArgs,
    #[command(subcommand)]
    command: DdsCommand,
}

#[derive(Debug, Subcommand)]
enum DdsCommand {
    /// List the topics others publish or read, with their type names.
    Topics {
        /// Seconds to listen for discovery.
        #[arg(long, default_value_t = 2.0)]
        wait: f64,
    },
    /// Print the samples of a topic: decoded as JSON where the type is one robowire knows, hex otherwise.
    Echo {
        /// The topic, e.g. rt/lowstate.
        topic: String,
        /// Stop after this many samples (0: until Ctrl-C).
        #[arg(long, default_value_t = 0)]
        count: u64,
        /// Seconds to wait for a writer of the topic to be discovered.
        #[arg(long, default_value_t = 5.0)]
        wait: f64,
    },
}

fn seconds(name: &str, value: f64) -> anyhow::Result<Duration> {
    anyhow::ensure!(value.is_finite() && (0.0..=3600.0).contains(&value), "{name} must be 0–3600 s, got {value}");
    Ok(Duration::from_secs_f64(value))
}

pub(crate) fn run(args: DdsCommandArgs) -> anyhow::Result<ExitCode> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        let participant = Participant::new(args.dds.participant()).context("joining DDS")?;
        match args.command {
            DdsCommand::Topics { wait } => {
                tokio::time::sleep(seconds("--wait", wait)?).await;
                let topics = participant.discovered_topics();
                if topics.is_empty() {
                    eprintln!("no topics discovered in {wait} s on domain {}", args.dds.domain);
                    return Ok(ExitCode::FAILURE);
                }
                for t in topics {
                    println!("{:<40} {:<45} writers {} readers {}", t.name, t.type_name, t.writers, t.readers);
                }
                Ok(ExitCode::SUCCESS)
            }
            DdsCommand::Echo { topic, count, wait } => {
                echo(&participant, &topic, count, seconds("--wait", wait)?).await
            }
        }
    })
}

/// The type name of `topic` as its writers announce it, waiting up to `wait`.
async fn type_of(participant: &Participant, topic: &str, wait: Duration) -> anyhow::Result<String> {
    let deadline = Instant::now() + wait;
    loop {
        if let Some(t) = participant.discovered_topics().into_iter().find(|t| t.name == topic && t.writers > 0) {
            return Ok(t.type_name);
        }
        anyhow::ensure!(
            Instant::now() < deadline,
            "no writer of {topic} discovered within {:.1} s",
            wait.as_secs_f64()
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

async fn echo(participant: &Participant, topic: &str, count: u64, wait: Duration) -> anyhow::Result<ExitCode> {
    let type_name = type_of(participant, topic, wait).await?;
    eprintln!("{topic}: {type_name}");
    let known = |name: &str| type_name == name;
    if known(LowCmd::DDS_TYPE_NAME) {
        print_typed::<LowCmd>(participant, topic, count).await
    } else if known(LowState::DDS_TYPE_NAME) {
        print_typed::<LowState>(participant, topic, count).await
    } else if known(HgLowCmd::DDS_TYPE_NAME) {
        print_typed::<HgLowCmd>(participant, topic, count).await
    } else if known(HgLowState::DDS_TYPE_NAME) {
        print_typed::<HgLowState>(participant, topic, count).await
    } else {
        print_raw(participant.raw_reader(topic, &type_name, Qos::RPC_READER)?, &type_name, count).await
    }
}

/// Prints `count` samples (0: until Ctrl-C) with `print`.
async fn each_sample<T: robowire_core::cdr::CdrType + 'static>(
    reader: &mut Reader<T>,
    count: u64,
    mut print: impl FnMut(T) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let mut printed = 0;
    // One listener for the whole loop: a Ctrl-C between two samples is not lost.
    let ctrl_c = tokio::signal::ctrl_c();
    tokio::pin!(ctrl_c);
    while count == 0 || printed < count {
        tokio::select! {
            signal = &mut ctrl_c => return signal.context("waiting for Ctrl-C"),
            sample = reader.recv() => {
                print(sample?.value)?;
                printed += 1;
            }
        }
    }
    Ok(())
}

async fn print_typed<M>(participant: &Participant, topic: &str, count: u64) -> anyhow::Result<ExitCode>
where
    M: Message + robowire_core::cdr::CdrType + Serialize + 'static,
{
    let mut reader = participant.reader::<M>(topic, Qos::READER)?;
    let result = each_sample(&mut reader, count, |message: M| {
        println!("{}", serde_json::to_string(&crate::cmd::decode::json_value(&message)?)?);
        Ok(())
    })
    .await;
    let s = reader.stats();
    if s.decode_errors + s.checksum_errors > 0 {
        eprintln!(
            "{} samples rejected ({} CRC), last: {}",
            s.decode_errors + s.checksum_errors,
            s.checksum_errors,
            reader.last_error().unwrap_or("-")
        );
    }
    result.map(|()| ExitCode::SUCCESS)
}

async fn print_raw(mut reader: Reader<RawSample>, type_name: &str, count: u64) -> anyhow::Result<ExitCode> {
    let requests = type_name == REQUEST_TYPE_NAME;
    let answers = type_name == RESPONSE_TYPE_NAME;
    each_sample(&mut reader, count, |sample: RawSample| {
        let body = &sample.body;
        let line = if requests {
            Request::decode_body(body).map(|r| format!("{r:?}")).ok()
        } else if answers {
            Response::decode_body(body).map(|r| format!("{r:?}")).ok()
        } else {
            None
        };
        println!("{}", line.unwrap_or_else(|| format!("{:?} {}", sample.encoding, hex::format(body))));
        Ok(())
    })
    .await?;
    Ok(ExitCode::SUCCESS)
}
