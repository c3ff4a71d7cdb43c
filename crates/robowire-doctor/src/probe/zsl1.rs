//! The ZSL-1 probe: the local state port listened on, then one idle HighLevel command (what the
//! vendor's client sends first) if nothing came.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::Duration;

use robowire_udp::{Peer, UdpError, UdpLink, UdpReceiver};
use zsl_proto::codec::{HighLevelClientCodec, StateDecoding};
use zsl_proto::udp::{HighLevelCommand, Model};

use crate::zsl1::{MAX_SOURCES, Zsl1Observation};

/// What arrives on `local_port` from `robot` (a HighLevel address) within `timeout`, and after
/// one idle command within another `timeout` when nothing did.
pub(crate) fn listen(
    robot: SocketAddr,
    model: Model,
    local_port: u16,
    our_ip: Option<IpAddr>,
    timeout: Duration,
) -> Zsl1Observation {
    let mut seen = Zsl1Observation {
        robot,
        local: Ok(local_port),
        our_ip,
        seconds: timeout.as_secs_f64(),
        states: 0,
        answered: None,
        undecodable: 0,
        others: Vec::new(),
    };
    let runtime = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(runtime) => runtime,
        Err(e) => {
            seen.local = Err(format!("no runtime: {e}"));
            return seen;
        }
    };
    runtime.block_on(async {
        let local = SocketAddr::new(Ipv4Addr::UNSPECIFIED.into(), local_port);
        let codec = HighLevelClientCodec::new(model, StateDecoding::Strict);
        let (mut sender, mut link) = match UdpLink::bind(local, Peer::Any { reply_to: Some(robot) }, codec).await {
            Ok(link) => link.into_split(),
            Err(e) => {
                seen.local = Err(robowire_devices::error_chain(&e));
                return;
            }
        };
        seen.states = window(&mut link, &mut seen.others, &mut seen.undecodable, robot.ip(), timeout).await;
        if seen.states == 0 {
            let sent = sender.send(&HighLevelCommand::default()).await.is_ok();
            let answered = window(&mut link, &mut seen.others, &mut seen.undecodable, robot.ip(), timeout).await;
            seen.answered = sent.then_some(answered);
        }
    });
    seen
}

/// The HighLevel state datagrams arriving on `local_port` within `timeout`, by source (at most
/// `MAX_SOURCES`), asking nobody; or why the port could not be bound.
pub(crate) fn overhear(local_port: u16, timeout: Duration) -> Result<Vec<(SocketAddr, u64)>, String> {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().map_err(|e| e.to_string())?;
    runtime.block_on(async {
        let local = SocketAddr::new(Ipv4Addr::UNSPECIFIED.into(), local_port);
        let codec = HighLevelClientCodec::new(Model::Zsl1, StateDecoding::Strict);
        let (_, mut link) = UdpLink::bind(local, Peer::Any { reply_to: None }, codec)
            .await
            .map_err(|e| robowire_devices::error_chain(&e))?
            .into_split();
        let (mut heard, mut undecodable) = (Vec::new(), 0);
        // Nothing comes from the unspecified address: every source is counted apart.
        window(&mut link, &mut heard, &mut undecodable, Ipv4Addr::UNSPECIFIED.into(), timeout).await;
        Ok(heard)
    })
}

/// Counts state datagrams from `robot` for `timeout`; the others by source, the undecodable.
async fn window(
    link: &mut UdpReceiver<HighLevelClientCodec>,
    others: &mut Vec<(SocketAddr, u64)>,
    undecodable: &mut u64,
    robot: IpAddr,
    timeout: Duration,
) -> u64 {
    let deadline = tokio::time::Instant::now() + timeout;
    let mut states = 0;
    while let Ok(received) = tokio::time::timeout_at(deadline, link.recv_from()).await {
        match received {
            Ok((_, from)) if from.ip() == robot => states += 1,
            Ok((_, from)) => {
                if let Some((_, n)) = others.iter_mut().find(|(source, _)| *source == from) {
                    *n += 1;
                } else if others.len() < MAX_SOURCES {
                    others.push((from, 1));
                }
            }
            Err(UdpError::Decode(_)) => *undecodable += 1,
            Err(_) => {}
        }
    }
    states
}
