//! The address viewers connect to: plain HTTP gets the built-in page, a WebSocket upgrade from
//! an allowed origin is relayed to the `foxglove` server on its private port ([`relay`]).
//! Connections are capped; an accept error is waited out, never the end of the front.

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use tokio::io::{AsyncReadExt, AsyncWriteExt, BufReader};
use tokio::net::{TcpListener, TcpStream};

use crate::head::{Head, read_head};
use crate::page;
use crate::relay::{self, Viewers};

/// Connections served at once, at most; more wait to be accepted.
const MAX_CONNECTIONS: usize = 64;
/// How long a connection has to send its request head.
const HEAD_TIMEOUT: Duration = Duration::from_secs(5);
/// What a closing connection may still send, read and dropped, at most.
const DRAIN_BYTES: u64 = 1 << 20;
/// How long a closing connection is read for, at most.
const DRAIN_FOR: Duration = Duration::from_secs(1);
/// How long the front waits after a failed accept (out of file descriptors, say).
const ACCEPT_RETRY: Duration = Duration::from_millis(100);
/// Web pages that may open the WebSocket besides this address's own page: Foxglove's app.
const ALLOWED_ORIGINS: &[&str] = &["https://app.foxglove.dev", "file://", "null"];

/// What the front serves besides the WebSocket.
pub(crate) trait Site: Send + Sync + 'static {
    /// `/plots.json`: the plots of every link registered so far.
    fn plots_json(&self) -> Vec<u8>;
}

/// Accepts connections on `listener` until the runtime stops.
pub(crate) async fn serve(listener: TcpListener, upstream: SocketAddr, site: Arc<dyn Site>, viewers: Arc<Viewers>) {
    let slots = Arc::new(tokio::sync::Semaphore::new(MAX_CONNECTIONS));
    loop {
        let Ok(slot) = slots.clone().acquire_owned().await else { return };
        let (stream, addr) = match listener.accept().await {
            Ok(accepted) => accepted,
            Err(_) => {
                tokio::time::sleep(ACCEPT_RETRY).await;
                continue;
            }
        };
        let (site, viewers) = (site.clone(), viewers.clone());
        tokio::spawn(async move {
            let _ = stream.set_nodelay(true);
            let _ = handle(stream, addr, upstream, &*site, &viewers).await;
            drop(slot);
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
    let (read, write) = stream.into_split();
    let mut read = BufReader::new(read);
    let head = match tokio::time::timeout(HEAD_TIMEOUT, read_head(&mut read)).await {
        Ok(Ok(bytes)) => Head { bytes },
        Ok(Err(e)) if e.kind() == std::io::ErrorKind::OutOfMemory => {
            return reply(&mut read, write, response(431, "text/plain", b"request head too large\n", "")).await;
        }
        _ => return reply(&mut read, write, response(400, "text/plain", b"bad request\n", "")).await,
    };
    let (method, path) = head.request_line();
    if head.header("upgrade").is_some_and(|u| u.eq_ignore_ascii_case("websocket")) {
        if !origin_allowed(head.header("origin").as_deref(), head.header("host").as_deref()) {
            return reply(&mut read, write, response(403, "text/plain", b"origin not allowed\n", "")).await;
        }
        return relay::relay(read, write, &head.bytes, upstream, addr, viewers).await;
    }
    let mut out = match (method.as_str(), path.split('?').next().unwrap_or_default()) {
        ("GET" | "HEAD", "/plots.json") => response(200, "application/json", &site.plots_json(), ""),
        ("GET" | "HEAD", path) => match page::file(path) {
            Some((content_type, body)) => response(200, content_type, body, ""),
            None => response(404, "text/plain", b"not found\n", ""),
        },
        _ => response(405, "text/plain", b"only GET and HEAD\n", "Allow: GET, HEAD\r\n"),
    };
    if method == "HEAD" {
        out.truncate(head_len(&out));
    }
    reply(&mut read, write, out).await
}

/// Writes `out`, then ends the connection: the write side shut, then what the client still
/// sends read and dropped (at most [`DRAIN_BYTES`], for at most [`DRAIN_FOR`]), so that closing
/// with unread bytes does not reset the connection before the client has read the reply.
async fn reply(
    read: &mut BufReader<tokio::net::tcp::OwnedReadHalf>,
    mut write: tokio::net::tcp::OwnedWriteHalf,
    out: Vec<u8>,
) -> std::io::Result<()> {
    write.write_all(&out).await?;
    write.shutdown().await?;
    let (mut rest, mut sink) = (read.take(DRAIN_BYTES), tokio::io::sink());
    let _ = tokio::time::timeout(DRAIN_FOR, tokio::io::copy(&mut rest, &mut sink)).await;
    Ok(())
}

/// Whether a WebSocket may be opened from `origin`: none (not a browser), this address's own
/// page (`http://{host}`), or Foxglove's app. Any other web page the user opens could otherwise
/// read the robot's state from a local port.
fn origin_allowed(origin: Option<&str>, host: Option<&str>) -> bool {
    let Some(origin) = origin else { return true };
    ALLOWED_ORIGINS.contains(&origin) || host.is_some_and(|host| origin == format!("http://{host}"))
}

/// An HTTP/1.1 response that closes the connection, with `extra` headers (each ending `\r\n`).
fn response(status: u16, content_type: &str, body: &[u8], extra: &str) -> Vec<u8> {
    let reason = match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        _ => "Request Header Fields Too Large",
    };
    let mut out = format!(
        "HTTP/1.1 {status} {reason}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nConnection: close\r\n{extra}\r\n",
        body.len()
    )
    .into_bytes();
    out.extend_from_slice(body);
    out
}

fn head_len(reply: &[u8]) -> usize {
    reply.windows(4).position(|w| w == b"\r\n\r\n").map_or(reply.len(), |at| at + 4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_head_response_is_its_get_response_cut_at_the_body() {
        assert_eq!(head_len(&response(200, "text/plain", b"body", "")), response(200, "text/plain", b"", "").len());
    }

    #[test]
    fn only_this_page_foxglove_s_app_and_non_browsers_may_open_the_socket() {
        assert!(origin_allowed(None, Some("127.0.0.1:8765")));
        assert!(origin_allowed(Some("http://127.0.0.1:8765"), Some("127.0.0.1:8765")));
        assert!(origin_allowed(Some("https://app.foxglove.dev"), Some("127.0.0.1:8765")));
        assert!(!origin_allowed(Some("https://evil.example"), Some("127.0.0.1:8765")));
        assert!(!origin_allowed(Some("http://127.0.0.1:9999"), Some("127.0.0.1:8765")));
        assert!(!origin_allowed(Some("http://127.0.0.1:8765"), None));
    }
}
