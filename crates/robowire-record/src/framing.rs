//! The record framing of an MCAP file, checked before the MCAP reader sees it: every record and
//! every length-prefixed field inside the records robowire's reader parses fits where its length
//! says. A corrupt file is refused here with the offset and what was expected, instead of
//! reaching code that would allocate what a corrupt length claims or panic on it.

/// The MCAP magic, at both ends of the file.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

/// Where the framing breaks: the offset and what was expected there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Broken {
    pub(crate) offset: usize,
    pub(crate) expected: String,
}

fn broken(offset: usize, expected: impl Into<String>) -> Broken {
    Broken { offset, expected: expected.into() }
}

/// A cursor over one record's body (`start` is its offset in the file, for errors).
struct Fields<'a> {
    body: &'a [u8],
    at: usize,
    start: usize,
}

impl<'a> Fields<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], Broken> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.body.len());
        let end = end.ok_or_else(|| broken(self.start + self.at, format!("{what} of {n} bytes within the record")))?;
        let bytes = &self.body[self.at..end];
        self.at = end;
        Ok(bytes)
    }

    fn skip(&mut self, n: usize, what: &str) -> Result<(), Broken> {
        self.take(n, what).map(|_| ())
    }

    fn u32(&mut self, what: &str) -> Result<usize, Broken> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    }

    fn u64(&mut self, what: &str) -> Result<u64, Broken> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
    }

    /// A `uint32` length, then that many bytes (strings and byte arrays).
    fn prefixed(&mut self, what: &str) -> Result<&'a [u8], Broken> {
        let len = self.u32(what)?;
        self.take(len, what)
    }

    /// A map or array: a `uint32` byte length, then entries that must fill it exactly.
    fn entries(
        &mut self,
        what: &str,
        mut entry: impl FnMut(&mut Fields<'a>) -> Result<(), Broken>,
    ) -> Result<(), Broken> {
        let start = self.start + self.at + 4;
        let body = self.prefixed(what)?;
        let mut inner = Fields { body, at: 0, start };
        while inner.at < body.len() {
            entry(&mut inner)?;
        }
        Ok(())
    }

    fn string_map(&mut self, what: &str) -> Result<(), Broken> {
        self.entries(what, |f| {
            f.prefixed("a map key")?;
            f.prefixed("a map value").map(|_| ())
        })
    }
}

/// Checks the fields of one record (opcodes of the MCAP spec; others are skipped whole).
fn check_record(opcode: u8, body: &[u8], start: usize) -> Result<(), Broken> {
    let f = &mut Fields { body, at: 0, start };
    match opcode {
        0x01 => {
            f.prefixed("the header's profile")?;
            f.prefixed("the header's library")?;
        }
        0x03 => {
            f.skip(2, "the schema id")?;
            f.prefixed("the schema name")?;
            f.prefixed("the schema encoding")?;
            f.prefixed("the schema data")?;
        }
        0x04 => {
            f.skip(4, "the channel and schema ids")?;
            f.prefixed("the channel topic")?;
            f.prefixed("the message encoding")?;
            f.string_map("the channel metadata")?;
        }
        0x05 => f.skip(22, "the message header")?,
        0x07 => {
            f.skip(2, "the channel id")?;
            f.entries("the message index", |e| e.skip(16, "an index entry"))?;
        }
        0x08 => {
            f.skip(32, "the chunk index offsets")?;
            f.entries("the message index offsets", |e| e.skip(10, "an offset entry"))?;
            f.skip(8, "the message index length")?;
            f.prefixed("the compression")?;
            f.skip(16, "the chunk sizes")?;
        }
        0x09 => {
            f.skip(16, "the attachment times")?;
            f.prefixed("the attachment name")?;
            f.prefixed("the media type")?;
            let len = f.u64("the attachment data length")?;
            f.skip(usize::try_from(len).unwrap_or(usize::MAX), "the attachment data")?;
        }
        0x0A => {
            f.skip(40, "the attachment index")?;
            f.prefixed("the attachment name")?;
            f.prefixed("the media type")?;
        }
        0x0B => {
            f.skip(8 + 2 + 4 * 4 + 16, "the statistics")?;
            f.entries("the channel message counts", |e| e.skip(10, "a count entry"))?;
        }
        0x0C => {
            f.prefixed("the metadata name")?;
            f.string_map("the metadata")?;
        }
        0x0D => {
            f.skip(16, "the metadata index")?;
            f.prefixed("the metadata name")?;
        }
        _ => {}
    }
    Ok(())
}

/// Walks `records` (top level from `start`, or a chunk's records), checking each.
fn walk(bytes: &[u8], mut at: usize, end: usize, in_chunk: bool) -> Result<Option<usize>, Broken> {
    while at < end {
        let header = bytes.get(at..at + 9).filter(|_| at + 9 <= end).ok_or_else(|| broken(at, "a record header"))?;
        let opcode = header[0];
        let len = u64::from_le_bytes(header[1..9].try_into().unwrap_or([0; 8]));
        let body = at + 9;
        let record_end = usize::try_from(len).ok().and_then(|l| body.checked_add(l)).filter(|&e| e <= end);
        let record_end = record_end.ok_or_else(|| broken(at + 1, format!("a record of {len} bytes that fits")))?;
        if opcode == 0x06 && !in_chunk {
            check_chunk(bytes, body, record_end)?;
        } else {
            check_record(opcode, &bytes[body..record_end], body)?;
        }
        at = record_end;
        if opcode == 0x02 && !in_chunk {
            return Ok(Some(at));
        }
    }
    Ok(None)
}

/// The largest chunk a capture may hold, uncompressed: robowire writes chunks of under 1 MiB;
/// a compressed chunk claiming more is refused before anything is allocated for it.
const MAX_CHUNK_BYTES: u64 = 64 << 20;

/// A chunk: times, sizes, crc, compression (none, zstd or lz4), records that fill it (once
/// decompressed, to their uncompressed size exactly).
fn check_chunk(bytes: &[u8], body: usize, end: usize) -> Result<(), Broken> {
    let f = &mut Fields { body: &bytes[body..end], at: 0, start: body };
    f.skip(16, "the chunk's times")?;
    let uncompressed_size = f.u64("the chunk's uncompressed size")?;
    f.skip(4, "the chunk's crc")?;
    let compression = f.prefixed("the chunk's compression")?;
    let records_len = f.u64("the chunk's records length")?;
    let records = body + f.at;
    if usize::try_from(records_len).ok().and_then(|l| records.checked_add(l)) != Some(end) {
        return Err(broken(records - 8, "records that fill the chunk"));
    }
    if compression.is_empty() {
        return walk(bytes, records, end, true).map(|_| ());
    }
    if uncompressed_size > MAX_CHUNK_BYTES {
        return Err(broken(body + 16, format!("a chunk of at most {MAX_CHUNK_BYTES} bytes uncompressed")));
    }
    let packed = &bytes[records..end];
    let size = uncompressed_size as usize;
    let unpacked = match compression {
        b"zstd" => zstd::bulk::decompress(packed, size).ok(),
        b"lz4" => {
            let mut out = Vec::new();
            lz4::Decoder::new(packed)
                .and_then(|d| std::io::Read::read_to_end(&mut std::io::Read::take(d, uncompressed_size + 1), &mut out))
                .ok()
                .map(|_| out)
        }
        _ => return Err(broken(body + 28, "a chunk compressed with zstd or lz4, or not at all")),
    };
    let Some(unpacked) = unpacked.filter(|u| u.len() == size) else {
        return Err(broken(
            records,
            format!("{} chunk records that decompress to {size} bytes", String::from_utf8_lossy(compression)),
        ));
    };
    walk(&unpacked, 0, size, true)
        .map(|_| ())
        .map_err(|b| broken(records, format!("in the decompressed chunk, at byte {}: {}", b.offset, b.expected)))
}

/// The whole file: magic, records up to the footer, magic.
pub(crate) fn check(bytes: &[u8]) -> Result<(), Broken> {
    if bytes.get(..8) != Some(MAGIC.as_slice()) {
        return Err(broken(0, "the MCAP magic (89 4d 43 41 50 30 0d 0a)"));
    }
    let after_footer = walk(bytes, 8, bytes.len(), false)?.ok_or_else(|| broken(bytes.len(), "a footer record"))?;
    if bytes.get(after_footer..) != Some(MAGIC.as_slice()) {
        return Err(broken(after_footer, "the closing MCAP magic"));
    }
    check_summary_start(bytes)
}

/// The MCAP reader takes the footer to be the 29 bytes before the closing magic and reads the
/// summary section from the footer's summary start to the end of the file: that offset must be
/// 0 (no summary) or where one of the records checked above starts.
fn check_summary_start(bytes: &[u8]) -> Result<(), Broken> {
    // Summary start: 20 bytes before the closing magic (then the summary offset start, the CRC).
    let Some(field) = bytes.len().checked_sub(8 + 20) else { return Ok(()) };
    let Some(start) = bytes.get(field..field + 8) else { return Ok(()) };
    let start = u64::from_le_bytes(start.try_into().unwrap_or([0; 8]));
    if start == 0 || usize::try_from(start).is_ok_and(|start| record_starts_at(bytes, start)) {
        Ok(())
    } else {
        Err(broken(field, format!("a summary start on a record, not {start}")))
    }
}

/// Whether a top-level record starts at `offset` (walking the record headers from the start).
pub(crate) fn record_starts_at(bytes: &[u8], offset: usize) -> bool {
    let mut at = MAGIC.len();
    while at < offset {
        let Some(len) = bytes.get(at..).and_then(|record| record.get(1..9)) else { return false };
        let len = u64::from_le_bytes(len.try_into().unwrap_or([0; 8]));
        match usize::try_from(len).ok().and_then(|len| (at + 9).checked_add(len)) {
            Some(next) => at = next,
            None => return false,
        }
    }
    at == offset && offset < bytes.len().saturating_sub(MAGIC.len())
}
