//! A ZSL-1 link's states played on UDP by `robowire_sim::replay::DatagramReplay`, on the link's
//! port (HighLevel 43997, LowLevel 43900) of `--bind`, from the client's first command on.

use std::net::{IpAddr, SocketAddr};
use std::process::ExitCode;
use std::time::Duration;

use robowire_record::LinkDescription;
use robowire_sim::replay::{DatagramReplay, Pace};
use zsl_proto::codec::{HighLevelDogCodec, LowLevelDogCodec};
use zsl_proto::description::LOW_LEVEL;
use zsl_proto::udp::{HIGH_LEVEL_PORT, LOW_LEVEL_PORT};

/// Plays `states` (offsets from the first, bytes) of `link`, a link of `protocol`, on `bind`.
pub(super) fn run(
    states: Vec<(Duration, Vec<u8>)>,
    protocol: &str,
    link: &str,
    bind: IpAddr,
    pace: Pace,
) -> anyhow::Result<ExitCode> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        if protocol == LOW_LEVEL.protocol() {
            play(SocketAddr::new(bind, LOW_LEVEL_PORT), LowLevelDogCodec::default(), states, link, pace).await
        } else {
            play(SocketAddr::new(bind, HIGH_LEVEL_PORT), HighLevelDogCodec::default(), states, link, pace).await
        }
    })
}
/// Binds `addr` with the device's `codec`, waits for a client's first command and plays `frames`
/// (offset from the first, bytes) to it.
async fn play<C>(
    addr: SocketAddr,
    codec: C,
    frames: impl IntoIterator<Item = (Duration, Vec<u8>)>,
    link: &str,
    pace: Pace,
) -> anyhow::Result<ExitCode>
where
    C: robowire_core::DatagramCodec + Clone + Send + 'static,
    C::Error: std::fmt::Display,
{
    let mut device =
        DatagramReplay::bind(addr, codec, frames).await.map_err(|e| anyhow::anyhow!("binding {addr}: {e}"))?;
    println!("{addr}");
    eprintln!("replay: {} device frames of {link} on {addr}; waiting for a client's first command", device.frames());
    let client = loop {
        match device.first_command().await {
            Ok(from) => break from,
            Err(e) => eprintln!("replay: ignored a datagram: {e}"),
        }
    };
    eprintln!("replay: client {client}; playing");
    let summary = device.play(pace).await?;
    eprintln!(
        "replay: sent {} of {} device frames to {client}; received {} commands",
        summary.sent, summary.frames, summary.commands
    );
    Ok(ExitCode::SUCCESS)
}
