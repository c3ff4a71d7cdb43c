//! One viewer's WebSocket relayed to the `foxglove` server and back, whole frames at a time.
//! What the server sends waits in two bounded queues of this viewer's: its JSON (advertisements,
//! status) and its data messages. A viewer that does not read loses data messages, whole and
//! counted, never the JSON; only a viewer so far behind that even the JSON queue fills is
//! disconnected, as Foxglove's server does. A viewer that sends what no Foxglove client sends is
//! closed (1002, or 1009 for an oversize frame). A viewer's subscription that the server refuses
//! for an unknown channel is asked again while the viewer holds it ([`crate::resubscribe`]).

use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use tokio::io::{AsyncRead, AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::TcpStream;
use tokio::net::tcp::{OwnedReadHalf, OwnedWriteHalf};
use tokio::sync::mpsc;

use crate::head::read_head;
use crate::resubscribe::Subscriptions;
use crate::ws_frame::{self, FrameHeader, Opcode};

/// Data frames waiting for one viewer, at most.
const DATA_QUEUE_FRAMES: usize = 1024;
/// JSON and control frames waiting for one viewer, at most.
const CONTROL_QUEUE_FRAMES: usize = 1024;
/// The longest frame the server's side may send (a schema-laden `advertise`).
const MAX_SERVER_FRAME: u64 = 64 << 20;
/// The longest frame a viewer may send: Foxglove's clients send small JSON requests.
const MAX_VIEWER_FRAME: u64 = 1 << 20;
/// How long the rest of a closing connection may take (the close handshake, queued frames).
const CLOSING: Duration = Duration::from_secs(1);
/// The requests a Foxglove client may send as text (ws-protocol's client operations).
const VIEWER_OPS: &[&str] = &[
    "subscribe",
    "unsubscribe",
    "advertise",
    "unadvertise",
    "getParameters",
    "setParameters",
    "subscribeParameterUpdates",
    "unsubscribeParameterUpdates",
    "subscribeConnectionGraph",
    "unsubscribeConnectionGraph",
    "fetchAsset",
];

/// What one viewer got and lost.
#[derive(Debug)]
pub(crate) struct ViewerCounters {
    addr: SocketAddr,
    /// Messages passed to it.
    forwarded: AtomicU64,
    /// Data messages dropped because its queue was full.
    dropped: AtomicU64,
}

/// The viewers connected now, and what those gone got and lost.
#[derive(Debug, Default)]
pub(crate) struct Viewers {
    connected: Mutex<Vec<Arc<ViewerCounters>>>,
    gone: Mutex<(u64, u64)>,
}

impl Viewers {
    fn add(&self, addr: SocketAddr) -> Arc<ViewerCounters> {
        let counters = Arc::new(ViewerCounters { addr, forwarded: 0.into(), dropped: 0.into() });
        self.connected.lock().unwrap_or_else(PoisonError::into_inner).push(counters.clone());
        counters
    }

    fn remove(&self, counters: &Arc<ViewerCounters>) {
        self.connected.lock().unwrap_or_else(PoisonError::into_inner).retain(|c| !Arc::ptr_eq(c, counters));
        let mut gone = self.gone.lock().unwrap_or_else(PoisonError::into_inner);
        gone.0 += counters.forwarded.load(Ordering::Relaxed);
        gone.1 += counters.dropped.load(Ordering::Relaxed);
    }

    /// Each connected viewer's address, messages forwarded and dropped.
    pub(crate) fn connected(&self) -> Vec<(SocketAddr, u64, u64)> {
        let viewers = self.connected.lock().unwrap_or_else(PoisonError::into_inner);
        viewers
            .iter()
            .map(|c| (c.addr, c.forwarded.load(Ordering::Relaxed), c.dropped.load(Ordering::Relaxed)))
            .collect()
    }

    /// Messages forwarded and dropped, all viewers ever.
    pub(crate) fn totals(&self) -> (u64, u64) {
        let gone = *self.gone.lock().unwrap_or_else(PoisonError::into_inner);
        self.connected().iter().fold(gone, |(f, d), (_, forwarded, dropped)| (f + forwarded, d + dropped))
    }
}

/// Why a viewer's connection ends.
enum Ended {
    /// Either end closed, or the connection broke.
    Closed,
    /// The viewer broke the protocol: the close code and why.
    Broke(u16, String),
}

/// Relays the viewer's WebSocket (its request `head` already read) to the server at `upstream`
/// until either end closes.
pub(crate) async fn relay(
    viewer_read: BufReader<OwnedReadHalf>,
    mut viewer_write: OwnedWriteHalf,
    head: &[u8],
    upstream: SocketAddr,
    addr: SocketAddr,
    viewers: &Viewers,
) -> std::io::Result<()> {
    let server = TcpStream::connect(upstream).await?;
    let _ = server.set_nodelay(true);
    let (server_read, mut server_write) = server.into_split();
    let mut server_read = BufReader::new(server_read);
    server_write.write_all(head).await?;
    let answer = read_head(&mut server_read).await?;
    viewer_write.write_all(&answer).await?;
    if !answer.starts_with(b"HTTP/1.1 101") {
        // The server's refusal, its body too.
        tokio::io::copy(&mut server_read, &mut viewer_write).await?;
        return Ok(());
    }
    let counters = viewers.add(addr);
    let ended = frames(viewer_read, viewer_write, server_read, server_write, &counters).await;
    viewers.remove(&counters);
    ended
}

async fn frames(
    mut viewer_read: BufReader<OwnedReadHalf>,
    mut viewer_write: OwnedWriteHalf,
    mut server_read: BufReader<OwnedReadHalf>,
    server_write: OwnedWriteHalf,
    counters: &ViewerCounters,
) -> std::io::Result<()> {
    let (control_tx, mut control) = mpsc::channel::<Vec<u8>>(CONTROL_QUEUE_FRAMES);
    let (data_tx, mut data) = mpsc::channel::<Vec<u8>>(DATA_QUEUE_FRAMES);
    // The viewer's frames, and a subscription asked again, go to the server whole, one at a time.
    let server_write = Arc::new(tokio::sync::Mutex::new(server_write));
    let subscriptions = Arc::new(Mutex::new(Subscriptions::default()));
    // Retries waiting to be sent: aborted when this connection ends.
    let mut retries = tokio::task::JoinSet::new();
    // The three directions borrow the halves; they are dropped at this block's end.
    let broke = {
        let (subscriptions, server_write, retries) = (&subscriptions, &server_write, &mut retries);
        let from_server = async move {
            // Whether the rest of the data message being read is dropped.
            let mut dropping = false;
            // Whether the message being read is data (binary), for its continuation frames.
            let mut in_data = false;
            while let Ok((header, frame)) = read_frame(&mut server_read, MAX_SERVER_FRAME).await {
                let data_frame = match header.opcode {
                    Opcode::Binary => true,
                    Opcode::Continuation => in_data,
                    _ => false,
                };
                if header.opcode.is_data() {
                    in_data = data_frame && !header.fin;
                }
                if data_frame {
                    if dropping {
                        dropping = !header.fin;
                        continue;
                    }
                    match data_tx.try_send(frame) {
                        Ok(()) => {
                            if header.fin {
                                counters.forwarded.fetch_add(1, Ordering::Relaxed);
                            }
                        }
                        Err(mpsc::error::TrySendError::Full(_)) => {
                            counters.dropped.fetch_add(1, Ordering::Relaxed);
                            dropping = !header.fin;
                        }
                        Err(mpsc::error::TrySendError::Closed(_)) => return,
                    }
                } else {
                    let last = header.opcode == Opcode::Close;
                    let retry = (header.opcode == Opcode::Text && header.fin)
                        .then(|| lock(subscriptions).retry(&frame[header.header_len..]))
                        .flatten();
                    if let Some(retry) = retry {
                        let (server_write, subscriptions) = (server_write.clone(), subscriptions.clone());
                        retries.spawn(async move {
                            tokio::time::sleep(retry.pause).await;
                            // The viewer's own frames go under this lock, an unsubscribe noted first.
                            let mut server_write = server_write.lock().await;
                            if lock(&subscriptions).holds(retry.channel, retry.subscription) {
                                let _ = server_write.write_all(&retry.frame).await;
                            }
                        });
                        continue;
                    }
                    // Full: this viewer is too far behind for even the server's JSON.
                    if control_tx.try_send(frame).is_err() {
                        return;
                    }
                    if header.fin && header.opcode.is_data() {
                        counters.forwarded.fetch_add(1, Ordering::Relaxed);
                    }
                    if last {
                        return;
                    }
                }
            }
            // The queues' senders go here: the writer sends what is queued, then ends.
        };
        let to_viewer = async {
            loop {
                // The server's JSON first: an advertisement before the data of its channel.
                let frame = tokio::select! {
                    biased;
                    Some(frame) = control.recv() => frame,
                    Some(frame) = data.recv() => frame,
                    else => return Ok::<(), std::io::Error>(()),
                };
                viewer_write.write_all(&frame).await?;
            }
        };
        let from_viewer = async {
            loop {
                let (header, frame) = match read_frame(&mut viewer_read, MAX_VIEWER_FRAME).await {
                    Ok(read) => read,
                    Err(e) if e.kind() == std::io::ErrorKind::FileTooLarge => return Ended::Broke(1009, e.to_string()),
                    Err(e) if e.kind() == std::io::ErrorKind::InvalidData => return Ended::Broke(1002, e.to_string()),
                    Err(_) => return Ended::Closed,
                };
                match check_viewer_frame(&header, &frame) {
                    Ok(Some(request)) => lock(subscriptions).note(&request),
                    Ok(None) if header.opcode == Opcode::Close => lock(subscriptions).clear(),
                    Ok(None) => {}
                    Err(reason) => return Ended::Broke(1002, reason),
                }
                if server_write.lock().await.write_all(&frame).await.is_err() || header.opcode == Opcode::Close {
                    return Ended::Closed;
                }
            }
        };
        tokio::pin!(from_server, to_viewer, from_viewer);
        tokio::select! {
            // The server ended (its close, or a broken link): what is queued still goes.
            () = &mut from_server => {
                let _ = tokio::time::timeout(CLOSING, &mut to_viewer).await;
                None
            }
            _ = &mut to_viewer => None,
            ended = &mut from_viewer => match ended {
                // The viewer closed: the server's answer, and what is queued before it, still go.
                Ended::Closed => {
                    let _ = tokio::time::timeout(CLOSING, async { tokio::join!(&mut from_server, &mut to_viewer) }).await;
                    None
                }
                Ended::Broke(code, reason) => Some((code, reason)),
            },
        }
    };
    if let Some((code, reason)) = broke {
        let close = ws_frame::close_frame(code, &reason);
        let _ = tokio::time::timeout(CLOSING, viewer_write.write_all(&close)).await;
    }
    let _ = viewer_write.shutdown().await;
    Ok(())
}

/// One frame: its header and its bytes, header included. A payload over `max` is refused before
/// it is read (`FileTooLarge`); a bad header is `InvalidData`.
pub(crate) async fn read_frame(
    read: &mut (impl AsyncRead + Unpin),
    max: u64,
) -> std::io::Result<(FrameHeader, Vec<u8>)> {
    let mut head = [0u8; 14];
    read.read_exact(&mut head[..2]).await?;
    let extended = match head[1] & 0x7F {
        126 => 2,
        127 => 8,
        _ => 0,
    };
    let len = 2 + extended + if head[1] & 0x80 != 0 { 4 } else { 0 };
    read.read_exact(&mut head[2..len]).await?;
    let invalid = |e: String| std::io::Error::new(std::io::ErrorKind::InvalidData, e);
    let header = FrameHeader::parse(&head[..len])
        .map_err(|e| invalid(e.to_string()))?
        .ok_or_else(|| invalid("a short frame header".into()))?;
    if header.payload_len > max {
        let too_large = format!("a frame of {} bytes (at most {max})", header.payload_len);
        return Err(std::io::Error::new(std::io::ErrorKind::FileTooLarge, too_large));
    }
    let mut frame = head[..len].to_vec();
    let read_len = (&mut *read).take(header.payload_len).read_to_end(&mut frame).await?;
    if read_len as u64 != header.payload_len {
        return Err(std::io::ErrorKind::UnexpectedEof.into());
    }
    Ok((header, frame))
}

fn lock(subscriptions: &Mutex<Subscriptions>) -> std::sync::MutexGuard<'_, Subscriptions> {
    subscriptions.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A viewer's frame as a Foxglove client sends one: masked; text a whole JSON object whose `op`
/// is a client operation (that request, for a text frame); no binary (this server takes no client
/// data, services or playback).
fn check_viewer_frame(header: &FrameHeader, frame: &[u8]) -> Result<Option<serde_json::Value>, String> {
    let Some(key) = header.mask else { return Err("an unmasked frame".into()) };
    match header.opcode {
        Opcode::Text if header.fin => {
            let mut payload = frame[header.header_len..].to_vec();
            ws_frame::unmask(&mut payload, key);
            let request: serde_json::Value = serde_json::from_slice(&payload).map_err(|_| "not JSON".to_string())?;
            match request.get("op").and_then(|op| op.as_str()) {
                Some(op) if VIEWER_OPS.contains(&op) => Ok(Some(request)),
                Some(op) => Err(format!("unknown op {:?}", op.chars().take(32).collect::<String>())),
                None => Err("no op".into()),
            }
        }
        Opcode::Text | Opcode::Continuation => Err("a fragmented message".into()),
        Opcode::Binary => Err("a binary message (no client data is taken)".into()),
        Opcode::Close | Opcode::Ping | Opcode::Pong => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn masked_text(text: &str) -> (FrameHeader, Vec<u8>) {
        let key = [1, 2, 3, 4];
        let mut payload = text.as_bytes().to_vec();
        ws_frame::unmask(&mut payload, key);
        let mut frame = vec![0x81, 0x80 | u8::try_from(payload.len()).unwrap()];
        frame.extend_from_slice(&key);
        frame.extend_from_slice(&payload);
        (FrameHeader::parse(&frame).unwrap().unwrap(), frame)
    }

    #[test]
    fn a_viewer_may_send_only_what_a_foxglove_client_sends() {
        let check = |text: &str| {
            let (h, f) = masked_text(text);
            check_viewer_frame(&h, &f)
        };
        let subscribe = r#"{"op":"subscribe","subscriptions":[{"id":0,"channelId":1}]}"#;
        assert_eq!(check(subscribe), Ok(Some(serde_json::from_str(subscribe).unwrap())));
        assert_eq!(check("not json"), Err("not JSON".into()));
        assert_eq!(check(r#"{"op":"nope"}"#), Err("unknown op \"nope\"".into()));
        assert_eq!(check("[1]"), Err("no op".into()));
        let binary = [0x82, 0x81, 0, 0, 0, 0, 7];
        assert!(check_viewer_frame(&FrameHeader::parse(&binary).unwrap().unwrap(), &binary).is_err());
        let unmasked = [0x81, 2, b'{', b'}'];
        assert!(check_viewer_frame(&FrameHeader::parse(&unmasked).unwrap().unwrap(), &unmasked).is_err());
    }

    #[tokio::test]
    async fn a_frame_is_read_whole_and_an_oversize_or_cut_one_refused() {
        let (h, frame) = masked_text("{}");
        let mut bytes = frame.clone();
        bytes.extend_from_slice(&[0x82, 127, 0, 0, 0, 0, 2, 0, 0, 0]);
        let mut read = &bytes[..];
        let (header, got) = read_frame(&mut read, 1 << 20).await.unwrap();
        assert_eq!((header, got), (h, frame));
        let err = read_frame(&mut read, 1 << 20).await.unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::FileTooLarge);
        assert!(err.to_string().contains("33554432 bytes"), "{err}");
        let err = read_frame(&mut &[0x82, 5, 1, 2][..], 1 << 20).await.unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::UnexpectedEof);
    }

    #[test]
    fn the_counts_of_viewers_gone_stay_in_the_totals() {
        let viewers = Viewers::default();
        let a = viewers.add("127.0.0.1:1".parse().unwrap());
        let b = viewers.add("127.0.0.1:2".parse().unwrap());
        a.dropped.store(5, Ordering::Relaxed);
        b.forwarded.store(7, Ordering::Relaxed);
        viewers.remove(&a);
        assert_eq!(viewers.connected().len(), 1);
        assert_eq!(viewers.totals(), (7, 5));
    }
}
