//! HTTP request heads, as the front reads them: through the empty line, bounded; a head's
//! request line and headers.

use tokio::io::{AsyncBufReadExt, AsyncReadExt};

/// The longest HTTP head.
const MAX_HEAD: usize = 16 << 10;

/// A request head: its method, path and headers.
pub(crate) struct Head {
    pub(crate) bytes: Vec<u8>,
}

impl Head {
    fn text(&self) -> std::borrow::Cow<'_, str> {
        String::from_utf8_lossy(&self.bytes)
    }

    pub(crate) fn request_line(&self) -> (String, String) {
        let text = self.text();
        let mut words = text.split_whitespace();
        (words.next().unwrap_or_default().to_owned(), words.next().unwrap_or_default().to_owned())
    }

    /// The value of header `name`, the first if repeated.
    pub(crate) fn header(&self, name: &str) -> Option<String> {
        self.text().lines().skip(1).find_map(|line| {
            let (k, v) = line.split_once(':')?;
            k.trim().eq_ignore_ascii_case(name).then(|| v.trim().to_owned())
        })
    }
}

/// An HTTP head, through its empty line: at most [`MAX_HEAD`] bytes (else `OutOfMemory`), an
/// end before it `InvalidData`.
pub(crate) async fn read_head(read: &mut (impl AsyncBufReadExt + Unpin)) -> std::io::Result<Vec<u8>> {
    let mut head = Vec::new();
    loop {
        let before = head.len();
        let n = read.take((MAX_HEAD - before) as u64).read_until(b'\n', &mut head).await?;
        if head.len() >= MAX_HEAD {
            return Err(std::io::ErrorKind::OutOfMemory.into());
        }
        if n == 0 {
            return Err(std::io::ErrorKind::InvalidData.into());
        }
        if head[before..] == *b"\r\n" || head[before..] == *b"\n" {
            return Ok(head);
        }
    }
}

#[cfg(test)]
mod tests {
    use tokio::io::BufReader;

    use super::*;

    #[tokio::test]
    async fn a_head_ends_at_its_empty_line_and_has_a_limit() {
        let mut read = BufReader::new(&b"GET / HTTP/1.1\r\nHost: x\r\n\r\nrest"[..]);
        assert_eq!(read_head(&mut read).await.unwrap(), b"GET / HTTP/1.1\r\nHost: x\r\n\r\n");
        let long = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(MAX_HEAD));
        let err = read_head(&mut BufReader::new(long.as_bytes())).await.unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::OutOfMemory);
        let err = read_head(&mut BufReader::new(&b"GET / HTTP/1.1\r\n"[..])).await.unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::InvalidData);
    }

    #[test]
    fn headers_are_found_by_name_whatever_their_case() {
        let head = Head { bytes: b"GET /x HTTP/1.1\r\nUpgrade: websocket\r\norigin: http://h:1\r\n\r\n".to_vec() };
        assert_eq!(head.request_line(), ("GET".to_owned(), "/x".to_owned()));
        assert_eq!(head.header("UPGRADE").as_deref(), Some("websocket"));
        assert_eq!(head.header("Origin").as_deref(), Some("http://h:1"));
        assert_eq!(head.header("host"), None);
    }
}
