//! The address viewers connect to: plain HTTP gets the built-in page, a WebSocket upgrade is passed
//! to the `foxglove` server on its private port. Per viewer, messages from the server wait in a
//! bounded queue: a viewer that does not read loses whole data messages (counted), never holds
//! the server; a viewer that sends what no Foxglove client sends is closed.

use std::net::SocketAddr;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use tokio::io::{AsyncBufReadExt, AsyncRead, AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::mpsc;

use crate::page;
use crate::ws_frame::{self, FrameHeader, Opcode};

/// Frames waiting for one viewer, at most.
const VIEWER_QUEUE_FRAMES: usize = 1024;
/// The longest frame the server's side may send (a schema-laden `advertise`).
const MAX_SERVER_FRAME: u64 = 64 << 20;
/// The longest frame a viewer may send: Foxglove's clients send small JSON requests.
const MAX_VIEWER_FRAME: u64 = 1 << 20;
/// The longest HTTP request head.
const MAX_HEAD: usize = 16 << 10;
/// How long a viewer has to send its request head.
const HEAD_TIMEOUT: Duration = Duration::from_secs(5);
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
    pub(crate) addr: SocketAddr,
    /// Messages passed to it.
    pub(crate) forwarded: AtomicU64,
    /// Data messages dropped because its queue was full.
    pub(crate) dropped: AtomicU64,
}

/// The viewers connected now.
#[derive(Debug, Default)]
pub(crate) struct Viewers(Mutex<Vec<Arc<ViewerCounters>>>);

impl Viewers {
    fn add(&self, addr: SocketAddr) -> Arc<ViewerCounters> {
        let counters = Arc::new(ViewerCounters { addr, forwarded: 0.into(), dropped: 0.into() });
        self.0.lock().unwrap_or_else(PoisonError::into_inner).push(counters.clone());
        counters
    }

    fn remove(&self, counters: &Arc<ViewerCounters>) {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).retain(|c| !Arc::ptr_eq(c, counters));
    }

    /// Each viewer's address, messages forwarded and dropped.
    pub(crate) fn snapshot(&self) -> Vec<(SocketAddr, u64, u64)> {
        let viewers = self.0.lock().unwrap_or_else(PoisonError::into_inner);
        viewers
            .iter()
            .map(|c| (c.addr, c.forwarded.load(Ordering::Relaxed), c.dropped.load(Ordering::Relaxed)))
            .collect()
    }
}

/// What the front serves besides the WebSocket.
pub(crate) trait Site: Send + Sync + 'static {
    /// `/plots.json`: the plots of every link registered so far.
    fn plots_json(&self) -> Vec<u8>;
}

/// Accepts viewers on `listener` until the runtime stops.
pub(crate) async fn serve(listener: TcpListener, upstream: SocketAddr, site: Arc<dyn Site>, viewers: Arc<Viewers>) {
    while let Ok((stream, addr)) = listener.accept().await {
        let (site, viewers) = (site.clone(), viewers.clone());
        tokio::spawn(async move {
            let _ = stream.set_nodelay(true);
            let _ = handle(stream, addr, upstream, &*site, &viewers).await;
        });
    }
}

async fn handle(
    stream: TcpStream,
    addr: SocketAddr,
    upstream: SocketAddr,
    site: &dyn Site,
    viewers: &Viewers,
) -> std::io::Result<()> {
    let (read, mut write) = stream.into_split();
    let mut read = BufReader::new(read);
    let Ok(Ok(head)) = tokio::time::timeout(HEAD_TIMEOUT, read_head(&mut read)).await else {
        return write.write_all(&response(400, "text/plain", b"bad request\n")).await;
    };
    let text = String::from_utf8_lossy(&head);
    let mut words = text.split_whitespace();
    let (method, path) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
    let upgrade = text.lines().any(|line| {
        line.split_once(':').is_some_and(|(k, v)| {
            k.trim().eq_ignore_ascii_case("upgrade") && v.trim().eq_ignore_ascii_case("websocket")
        })
    });
    if upgrade {
        let counters = viewers.add(addr);
        let result = pass_through(read, write, &head, upstream, &counters).await;
        viewers.remove(&counters);
        return result;
    }
    let reply = match (method, path.split('?').next().unwrap_or("")) {
        ("GET" | "HEAD", "/plots.json") => response(200, "application/json", &site.plots_json()),
        ("GET" | "HEAD", path) => match page::file(path) {
            Some((content_type, body)) => response(200, content_type, body),
            None => response(404, "text/plain", b"not found\n"),
        },
        _ => response(405, "text/plain", b"only GET\n"),
    };
    let reply = if method == "HEAD" { reply[..head_len(&reply)].to_vec() } else { reply };
    write.write_all(&reply).await
}

/// An HTTP/1.1 response that closes the connection.
fn response(status: u16, content_type: &str, body: &[u8]) -> Vec<u8> {
    let reason = match status {
        200 => "OK",
        400 => "Bad Request",
        404 => "Not Found",
        _ => "Method Not Allowed",
    };
    let mut out = format!(
        "HTTP/1.1 {status} {reason}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    )
    .into_bytes();
    out.extend_from_slice(body);
    out
}

fn head_len(reply: &[u8]) -> usize {
    reply.windows(4).position(|w| w == b"\r\n\r\n").map_or(reply.len(), |at| at + 4)
}

/// An HTTP head, through its empty line, at most [`MAX_HEAD`] bytes.
async fn read_head(read: &mut (impl AsyncBufReadExt + Unpin)) -> std::io::Result<Vec<u8>> {
    let mut head = Vec::new();
    loop {
        let before = head.len();
        let n = read.take((MAX_HEAD - before) as u64).read_until(b'\n', &mut head).await?;
        if n == 0 || head.len() >= MAX_HEAD {
            return Err(std::io::ErrorKind::InvalidData.into());
        }
        if head[before..] == *b"\r\n" || head[before..] == *b"\n" {
            return Ok(head);
        }
    }
}

/// One frame: its header and its bytes, header included. A payload over `max` is an error before
/// it is read.
async fn read_frame(read: &mut (impl AsyncRead + Unpin), max: u64) -> std::io::Result<(FrameHeader, Vec<u8>)> {
    let invalid = |e: String| std::io::Error::new(std::io::ErrorKind::InvalidData, e);
    let mut head = [0u8; 14];
    read.read_exact(&mut head[..2]).await?;
    let extended = match head[1] & 0x7F {
        126 => 2,
        127 => 8,
        _ => 0,
    };
    let len = 2 + extended + if head[1] & 0x80 != 0 { 4 } else { 0 };
    read.read_exact(&mut head[2..len]).await?;
    let header = FrameHeader::parse(&head[..len])
        .map_err(|e| invalid(e.to_string()))?
        .ok_or_else(|| invalid("a short frame header".into()))?;
    if header.payload_len > max {
        return Err(invalid(format!("a frame of {} bytes (at most {max})", header.payload_len)));
    }
    let mut frame = head[..len].to_vec();
    frame.resize(len + header.payload_len as usize, 0);
    read.read_exact(&mut frame[len..]).await?;
    Ok((header, frame))
}

/// The viewer's WebSocket passed to the server and back, until either end closes or the viewer
/// breaks the protocol (then it gets a close frame, 1008, and is disconnected).
async fn pass_through(
    mut viewer_read: BufReader<tokio::net::tcp::OwnedReadHalf>,
    mut viewer_write: tokio::net::tcp::OwnedWriteHalf,
    head: &[u8],
    upstream: SocketAddr,
    counters: &ViewerCounters,
) -> std::io::Result<()> {
    let server = TcpStream::connect(upstream).await?;
    let _ = server.set_nodelay(true);
    let (server_read, mut server_write) = server.into_split();
    let mut server_read = BufReader::new(server_read);
    server_write.write_all(head).await?;
    let answer = read_head(&mut server_read).await?;
    viewer_write.write_all(&answer).await?;
    if !answer.starts_with(b"HTTP/1.1 101") {
        return Ok(());
    }
    let (queue, mut queued) = mpsc::channel::<Vec<u8>>(VIEWER_QUEUE_FRAMES);
    // The three directions borrow the halves; they are dropped at this block's end.
    let broken = {
        let from_server = async {
            // Whether the rest of the message being read is dropped.
            let mut dropping = false;
            loop {
                let (header, frame) = read_frame(&mut server_read, MAX_SERVER_FRAME).await?;
                let continues = header.opcode == Opcode::Continuation;
                if continues && dropping {
                    dropping = !header.fin;
                    continue;
                }
                match queue.try_send(frame) {
                    Ok(()) => {
                        if header.fin {
                            counters.forwarded.fetch_add(1, Ordering::Relaxed);
                        }
                    }
                    // Only whole data messages go; the server's JSON (advertisements, status) cannot.
                    Err(mpsc::error::TrySendError::Full(_)) if header.opcode == Opcode::Binary => {
                        counters.dropped.fetch_add(1, Ordering::Relaxed);
                        dropping = !header.fin;
                    }
                    Err(_) => {
                        return Err::<(), _>(std::io::Error::other("the viewer's queue is full of the server's JSON"));
                    }
                }
            }
        };
        let to_viewer = async {
            while let Some(frame) = queued.recv().await {
                viewer_write.write_all(&frame).await?;
            }
            Ok::<(), std::io::Error>(())
        };
        let from_viewer = async {
            loop {
                let (header, frame) = read_frame(&mut viewer_read, MAX_VIEWER_FRAME).await.map_err(|e| {
                    // A bad or oversize header is the viewer's fault; a lost connection is not.
                    if e.kind() == std::io::ErrorKind::InvalidData {
                        Broken::Protocol(e.to_string())
                    } else {
                        Broken::Io(e)
                    }
                })?;
                check_viewer_frame(&header, &frame).map_err(Broken::Protocol)?;
                server_write.write_all(&frame).await.map_err(Broken::Io)?;
                if header.opcode == Opcode::Close {
                    return Ok::<(), Broken>(());
                }
            }
        };
        tokio::select! {
            _ = from_server => None,
            _ = to_viewer => None,
            result = from_viewer => result.err(),
        }
    };
    if let Some(Broken::Protocol(reason)) = broken {
        let close = ws_frame::close_frame(1008, &reason);
        let _ = tokio::time::timeout(Duration::from_secs(1), viewer_write.write_all(&close)).await;
    }
    let _ = viewer_write.shutdown().await;
    Ok(())
}

/// Why a viewer's connection ends.
enum Broken {
    Io(#[allow(dead_code)] std::io::Error),
    Protocol(String),
}

/// A viewer's frame as a Foxglove client sends one: masked; text a whole JSON object whose `op`
/// is a client operation; no binary (this server takes no client data, services or playback).
fn check_viewer_frame(header: &FrameHeader, frame: &[u8]) -> Result<(), String> {
    let Some(key) = header.mask else { return Err("an unmasked frame".into()) };
    match header.opcode {
        Opcode::Text if header.fin => {
            let mut payload = frame[header.header_len..].to_vec();
            ws_frame::unmask(&mut payload, key);
            let request: serde_json::Value = serde_json::from_slice(&payload).map_err(|_| "not JSON".to_string())?;
            match request.get("op").and_then(|op| op.as_str()) {
                Some(op) if VIEWER_OPS.contains(&op) => Ok(()),
                Some(op) => Err(format!("unknown op {:.40}", op)),
                None => Err("no op".into()),
            }
        }
        Opcode::Text | Opcode::Continuation => Err("a fragmented message".into()),
        Opcode::Binary => Err("a binary message (no client data is taken)".into()),
        Opcode::Close | Opcode::Ping | Opcode::Pong => Ok(()),
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
        assert_eq!(check(r#"{"op":"subscribe","subscriptions":[{"id":0,"channelId":1}]}"#), Ok(()));
        assert_eq!(check("not json"), Err("not JSON".into()));
        assert_eq!(check(r#"{"op":"nope"}"#), Err("unknown op nope".into()));
        assert_eq!(check("[1]"), Err("no op".into()));
        let binary = [0x82, 0x81, 0, 0, 0, 0, 7];
        assert!(check_viewer_frame(&FrameHeader::parse(&binary).unwrap().unwrap(), &binary).is_err());
        let unmasked = [0x81, 2, b'{', b'}'];
        assert!(check_viewer_frame(&FrameHeader::parse(&unmasked).unwrap().unwrap(), &unmasked).is_err());
    }

    #[tokio::test]
    async fn a_frame_is_read_whole_and_an_oversize_one_refused_before_its_payload() {
        let (h, frame) = masked_text("{}");
        let mut bytes = frame.clone();
        bytes.extend_from_slice(&[0x82, 127, 0, 0, 0, 0, 2, 0, 0, 0]);
        let mut read = &bytes[..];
        let (header, got) = read_frame(&mut read, 1 << 20).await.unwrap();
        assert_eq!((header, got), (h, frame));
        let err = read_frame(&mut read, 1 << 20).await.unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::InvalidData);
        assert!(err.to_string().contains("33554432 bytes"), "{err}");
    }

    #[tokio::test]
    async fn a_head_ends_at_its_empty_line_and_has_a_limit() {
        let mut read = BufReader::new(&b"GET / HTTP/1.1\r\nHost: x\r\n\r\nrest"[..]);
        assert_eq!(read_head(&mut read).await.unwrap(), b"GET / HTTP/1.1\r\nHost: x\r\n\r\n");
        let long = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(MAX_HEAD));
        assert!(read_head(&mut BufReader::new(long.as_bytes())).await.is_err());
        assert!(read_head(&mut BufReader::new(&b"GET / HTTP/1.1\r\n"[..])).await.is_err());
        assert_eq!(head_len(&response(200, "text/plain", b"body")), response(200, "text/plain", b"").len());
    }
}
