//! `robowire replay --as-device`: the device side of a capture played back to a live client over
//! the same transport, so that a session seen once on a robot can be replayed on a desk. Today:
//! the ZSL-1's UDP links (HighLevel on 43997, LowLevel on 43900).

use std::net::{IpAddr, SocketAddr};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use robowire_record::{LinkDescription, RecordedFrame};
use robowire_udp::{Peer, UdpLink};
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

/// Plays the device frames of `link` (default: the first link that has any) on `bind`.
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
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        if first.protocol.protocol() == LOW_LEVEL.protocol() {
            play(SocketAddr::new(bind, LOW_LEVEL_PORT), LowLevelDogCodec::default(), &link, &states, speed).await
        } else {
            play(SocketAddr::new(bind, HIGH_LEVEL_PORT), HighLevelDogCodec::default(), &link, &states, speed).await
        }
    })
}

async fn play<C>(
    addr: SocketAddr,
    codec: C,
    link: &str,
    states: &[&RecordedFrame],
    speed: Option<f64>,
) -> anyhow::Result<ExitCode>
where
    C: robowire_core::DatagramCodec + Clone + Send + 'static,
    C::Incoming: Send,
    C::Error: std::fmt::Display + Send,
{
    let udp = UdpLink::bind(addr, Peer::Any { reply_to: None }, codec)
        .await
        .map_err(|e| anyhow::anyhow!("binding {addr}: {e}"))?;
    println!("{addr}");
    eprintln!("replay: {} device frames of {link} on {addr}; waiting for a client's first command", states.len());
    let (mut sender, mut receiver) = udp.into_split();
    let client = loop {
        match receiver.recv_from().await {
            Ok((_, from)) => break from,
            Err(e) => eprintln!("replay: ignored a datagram: {e}"),
        }
    };
    let commands = Arc::new(AtomicU64::new(1));
    let counting = tokio::spawn({
        let commands = commands.clone();
        async move {
            while receiver.recv().await.is_ok() {
                commands.fetch_add(1, Ordering::Relaxed);
            }
        }
    });
    eprintln!("replay: client {client}; playing");
    let start = Instant::now();
    let t0 = states[0].unix_ns;
    let mut sent = 0u64;
    for state in states {
        if let Some(speed) = speed {
            let due = Duration::from_nanos(((state.unix_ns - t0) as f64 / speed) as u64);
            tokio::time::sleep_until(tokio::time::Instant::from_std(start + due)).await;
        }
        if sender.send_bytes_now(&state.bytes).is_ok() {
            sent += 1;
        }
    }
    counting.abort();
    eprintln!(
        "replay: sent {sent} of {} device frames to {client}; received {} commands",
        states.len(),
        commands.load(Ordering::Relaxed)
    );
    Ok(ExitCode::SUCCESS)
}
