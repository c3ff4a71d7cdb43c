//! `robowire replay --as-device`: the device side of a capture played back to a live client over
//! the same transport, so that a session seen once on a robot can be replayed on a desk. Today:
//! the ZSL-1's UDP links (HighLevel on 43997, LowLevel on 43900). This picks the device's frames
//! out of the capture; `robowire_sim::replay::DatagramReplay` plays them.

use std::net::{IpAddr, SocketAddr};
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use robowire_record::{LinkDescription, RecordedFrame};
use robowire_sim::replay::{DatagramReplay, Pace};
use zsl_proto::codec::{HighLevelDogCodec, LowLevelDogCodec};
use zsl_proto::description::{DESCRIPTIONS, LOW_LEVEL};
use zsl_proto::udp::{AnyDatagram, HIGH_LEVEL_PORT, LOW_LEVEL_PORT};

/// Which datagrams are the device's: the states of a ZSL-1 link, whichever side recorded them.
fn is_device_frame(frame: &RecordedFrame) -> bool {
    DESCRIPTIONS.iter().any(|d| d.protocol() == frame.protocol.protocol())
        && matches!(
            AnyDatagram::decode(&frame.bytes),
            Ok(AnyDatagram::HighLevelState(_) | AnyDatagram::LowLevelState(_))
        )
}

/// Plays the device frames of `link` (default: the first link that has any) on `bind`, at the
/// recorded pace scaled by `speed` (`None`: as fast as possible).
pub(crate) fn run(
    frames: &[RecordedFrame],
    link: Option<&str>,
    bind: IpAddr,
    speed: Option<f64>,
) -> anyhow::Result<ExitCode> {
    let link = match link {
        Some(link) => link.to_string(),
        None => frames
            .iter()
            .find(|f| is_device_frame(f))
            .map(|f| f.link.clone())
            .context("the capture has no device frames (ZSL-1 states)")?,
    };
    let states: Vec<&RecordedFrame> = frames.iter().filter(|f| f.link == link && is_device_frame(f)).collect();
    let first = states.first().with_context(|| format!("link {link} has no device frames"))?;
    let offsets =
        states.iter().map(|s| (Duration::from_nanos(s.unix_ns.saturating_sub(first.unix_ns)), s.bytes.clone()));
    let pace = speed.map_or(Pace::Fast, |speed| Pace::Recorded { speed });
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        if first.protocol.protocol() == LOW_LEVEL.protocol() {
            play(SocketAddr::new(bind, LOW_LEVEL_PORT), LowLevelDogCodec::default(), offsets, &link, pace).await
        } else {
            play(SocketAddr::new(bind, HIGH_LEVEL_PORT), HighLevelDogCodec::default(), offsets, &link, pace).await
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
