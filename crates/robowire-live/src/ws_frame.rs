//! WebSocket frame headers (RFC 6455 §5.2), read as bytes arrive: what the front needs to pass a
//! viewer's connection through whole messages at a time. It never decodes the Foxglove protocol
//! itself; that is the `foxglove` crate's.

/// A frame's opcode (RFC 6455 §5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Opcode {
    Continuation,
    Text,
    Binary,
    Close,
    Ping,
    Pong,
}

impl Opcode {
    fn from_bits(bits: u8) -> Option<Self> {
        Some(match bits {
            0x0 => Self::Continuation,
            0x1 => Self::Text,
            0x2 => Self::Binary,
            0x8 => Self::Close,
            0x9 => Self::Ping,
            0xA => Self::Pong,
            _ => return None,
        })
    }

    /// A frame of a message (text, binary or their continuation), not a control frame.
    pub(crate) fn is_data(self) -> bool {
        matches!(self, Self::Continuation | Self::Text | Self::Binary)
    }
}

/// One frame's header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct FrameHeader {
    /// The last frame of its message.
    pub(crate) fin: bool,
    pub(crate) opcode: Opcode,
    /// The masking key (every client frame has one, no server frame does).
    pub(crate) mask: Option<[u8; 4]>,
    /// The payload's length, bytes.
    pub(crate) payload_len: u64,
    /// The header's own length, bytes (2 to 14).
    pub(crate) header_len: usize,
}

/// Why bytes are not a frame header.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub(crate) enum FrameError {
    #[error("reserved bits set ({0:#04x})")]
    Reserved(u8),
    #[error("unknown opcode {0:#x}")]
    Opcode(u8),
    #[error("a control frame of {0} bytes, or fragmented (at most 125, whole)")]
    Control(u64),
    #[error("a 64-bit length with its top bit set")]
    Length,
}

impl FrameHeader {
    /// The header at the start of `bytes`; `Ok(None)` until all of it is there.
    pub(crate) fn parse(bytes: &[u8]) -> Result<Option<Self>, FrameError> {
        let [b0, b1, ..] = *bytes else { return Ok(None) };
        if b0 & 0x70 != 0 {
            return Err(FrameError::Reserved(b0));
        }
        let opcode = Opcode::from_bits(b0 & 0x0F).ok_or(FrameError::Opcode(b0 & 0x0F))?;
        let fin = b0 & 0x80 != 0;
        let masked = b1 & 0x80 != 0;
        let (payload_len, mut at) = match b1 & 0x7F {
            126 => match bytes.get(2..4) {
                Some(b) => (u64::from(u16::from_be_bytes([b[0], b[1]])), 4),
                None => return Ok(None),
            },
            127 => match bytes.get(2..10).and_then(|b| <[u8; 8]>::try_from(b).ok()) {
                Some(b) => (u64::from_be_bytes(b), 10),
                None => return Ok(None),
            },
            n => (u64::from(n), 2),
        };
        if payload_len >> 63 != 0 {
            return Err(FrameError::Length);
        }
        if !opcode.is_data() && (payload_len > 125 || !fin) {
            return Err(FrameError::Control(payload_len));
        }
        let mask = if masked {
            let Some(key) = bytes.get(at..at + 4).and_then(|b| <[u8; 4]>::try_from(b).ok()) else { return Ok(None) };
            at += 4;
            Some(key)
        } else {
            None
        };
        Ok(Some(Self { fin, opcode, mask, payload_len, header_len: at }))
    }
}

/// `payload` unmasked in place with `key`.
pub(crate) fn unmask(payload: &mut [u8], key: [u8; 4]) {
    for (i, byte) in payload.iter_mut().enumerate() {
        *byte ^= key[i % 4];
    }
}

/// A server's close frame: `code` (RFC 6455 §7.4) and a short reason (at most 123 bytes of it,
/// cut between characters).
pub(crate) fn close_frame(code: u16, reason: &str) -> Vec<u8> {
    let mut cut = reason.len().min(123);
    while !reason.is_char_boundary(cut) {
        cut -= 1;
    }
    let reason = &reason.as_bytes()[..cut];
    let mut frame = vec![0x88, u8::try_from(2 + reason.len()).unwrap_or(125)];
    frame.extend_from_slice(&code.to_be_bytes());
    frame.extend_from_slice(reason);
    frame
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_of_each_length_form_are_read_once_whole() {
        // A server's binary frame of 5 bytes, unmasked.
        let h = FrameHeader::parse(&[0x82, 5]).unwrap().unwrap();
        assert_eq!((h.fin, h.opcode, h.mask, h.payload_len, h.header_len), (true, Opcode::Binary, None, 5, 2));
        // A client's text frame of 300 bytes, masked: 16-bit length, then the key.
        let bytes = [0x81, 0xFE, 0x01, 0x2C, 1, 2, 3, 4];
        for n in 0..bytes.len() {
            assert_eq!(FrameHeader::parse(&bytes[..n]), Ok(None), "{n} bytes");
        }
        let h = FrameHeader::parse(&bytes).unwrap().unwrap();
        assert_eq!((h.opcode, h.mask, h.payload_len, h.header_len), (Opcode::Text, Some([1, 2, 3, 4]), 300, 8));
        // 64-bit length, a fragment.
        let h = FrameHeader::parse(&[0x02, 127, 0, 0, 0, 1, 0, 0, 0, 0]).unwrap().unwrap();
        assert_eq!((h.fin, h.payload_len, h.header_len), (false, 1 << 32, 10));
    }

    #[test]
    fn bad_headers_are_errors() {
        assert_eq!(FrameHeader::parse(&[0xC2, 0]), Err(FrameError::Reserved(0xC2)));
        assert_eq!(FrameHeader::parse(&[0x83, 0]), Err(FrameError::Opcode(3)));
        assert_eq!(FrameHeader::parse(&[0x89, 126, 0, 200]), Err(FrameError::Control(200)));
        assert_eq!(FrameHeader::parse(&[0x09, 0]), Err(FrameError::Control(0)));
        assert_eq!(FrameHeader::parse(&[0x82, 127, 0x80, 0, 0, 0, 0, 0, 0, 0]), Err(FrameError::Length));
    }

    #[test]
    fn unmasking_twice_gives_the_bytes_back_and_a_close_frame_is_well_formed() {
        let mut payload = *b"{\"op\":\"subscribe\"}";
        unmask(&mut payload, [9, 8, 7, 6]);
        assert_ne!(&payload, b"{\"op\":\"subscribe\"}");
        unmask(&mut payload, [9, 8, 7, 6]);
        assert_eq!(&payload, b"{\"op\":\"subscribe\"}");
        let frame = close_frame(1008, "bad");
        assert_eq!(frame, [0x88, 5, 0x03, 0xF0, b'b', b'a', b'd']);
        let h = FrameHeader::parse(&frame).unwrap().unwrap();
        assert_eq!((h.opcode, h.payload_len), (Opcode::Close, 5));
        assert_eq!(close_frame(1000, &"x".repeat(500)).len(), 2 + 125);
        // 122 bytes, then a 2-byte character across the limit: left out whole.
        let frame = close_frame(1000, &format!("{}é", "x".repeat(122)));
        assert_eq!(frame.len(), 2 + 2 + 122);
        assert!(std::str::from_utf8(&frame[4..]).is_ok());
    }
}
