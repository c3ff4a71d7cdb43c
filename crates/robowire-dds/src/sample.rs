//! What readers hand out and writers count: samples with their identity, counters, and the
//! decoding of a received payload (encapsulation header, then the codec's body).

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use robowire_core::cdr::{CdrEncoding, CdrType};

/// What a writer or reader has done.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TopicStats {
    /// Samples written, or received and decoded.
    pub samples: u64,
    /// Writes that failed.
    pub write_errors: u64,
    /// Samples a writer dropped because its history was full of unacknowledged samples, or a
    /// reader replaced before they were taken (keep last).
    pub dropped: u64,
    /// Received samples whose body did not decode (checksum failures not included).
    pub decode_errors: u64,
    /// Received samples whose integrity check (CRC) failed.
    pub checksum_errors: u64,
}

#[derive(Debug, Default)]
pub(crate) struct Counters {
    pub(crate) samples: AtomicU64,
    pub(crate) write_errors: AtomicU64,
    pub(crate) dropped: AtomicU64,
    pub(crate) decode_errors: AtomicU64,
    pub(crate) checksum_errors: AtomicU64,
}

impl Counters {
    pub(crate) fn bump(counter: &AtomicU64) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    pub(crate) fn get(&self) -> TopicStats {
        TopicStats {
            samples: self.samples.load(Ordering::Relaxed),
            write_errors: self.write_errors.load(Ordering::Relaxed),
            dropped: self.dropped.load(Ordering::Relaxed),
            decode_errors: self.decode_errors.load(Ordering::Relaxed),
            checksum_errors: self.checksum_errors.load(Ordering::Relaxed),
        }
    }
}

/// A handle on a writer's or reader's counters, usable from any thread.
#[derive(Debug, Clone)]
pub struct StatsHandle(pub(crate) Arc<Counters>);

impl StatsHandle {
    /// The counters now.
    pub fn get(&self) -> TopicStats {
        self.0.get()
    }
}

/// A sample as received.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample<T> {
    /// The message.
    pub value: T,
    /// The GUID of the writer that sent it (tells two publishers on one topic apart).
    pub writer: [u8; 16],
    /// Its RTPS sequence number at that writer (from 1).
    pub sequence: i64,
    /// The related sample identity its writer sent with it (inline QoS PID 0x0083 or 0x800f),
    /// if any: for a request of rmw_fastrtps, where the reply goes.
    pub related: Option<SampleIdentity>,
}

/// A sample's identity: its writer's GUID and its sequence number there (DDS-RPC's
/// `SampleIdentity`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SampleIdentity {
    /// The writer's GUID in wire order (prefix 12 bytes, entity key 3, entity kind 1); all zero:
    /// unknown.
    pub writer: [u8; 16],
    /// The sequence number; [`SampleIdentity::SEQUENCE_UNKNOWN`]: unknown.
    pub sequence: i64,
}

impl SampleIdentity {
    /// RTPS's unknown sequence number (high −1, low 0), what rmw_fastrtps' clients send in
    /// their requests' related sample identity.
    pub const SEQUENCE_UNKNOWN: i64 = -1 << 32;

    /// Whether the writer GUID is known (not all zero).
    pub fn writer_known(&self) -> bool {
        self.writer != [0; 16]
    }

    pub(crate) fn to_rtps(self) -> rtps_proto::endpoint::SampleIdentity {
        rtps_proto::endpoint::SampleIdentity {
            writer: rtps_proto::Guid::from_bytes(self.writer),
            sequence: rtps_proto::SequenceNumber(self.sequence),
        }
    }

    pub(crate) fn of_rtps(identity: rtps_proto::endpoint::SampleIdentity) -> Self {
        Self { writer: identity.writer.to_bytes(), sequence: identity.sequence.0 }
    }
}

/// A sample of a type robowire has no codec for: its representation and its CDR body.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawSample {
    /// The representation the writer used.
    pub encoding: CdrEncoding,
    /// The body (after the 4-byte encapsulation header).
    pub body: Vec<u8>,
}

impl CdrType for RawSample {
    /// Not used: a raw reader's topic takes the type name it is given.
    const TYPE_NAME: &'static str = "";
    type Error = core::convert::Infallible;
    fn body_len(&self) -> usize {
        self.body.len()
    }
    fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
        let (needed, available) = (self.body.len(), out.len());
        out.get_mut(..needed).ok_or(robowire_core::BufferTooSmall { needed, available })?.copy_from_slice(&self.body);
        Ok(needed)
    }
    fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, Self::Error> {
        Ok(Self { encoding, body: body.to_vec() })
    }
}

/// Why a received payload is not a `T`.
#[derive(Debug, Clone)]
pub(crate) struct DecodeFailure {
    pub(crate) checksum: bool,
    pub(crate) reason: String,
}

/// A received payload (4-byte encapsulation header, body) decoded by `T`'s codec: XCDR1 or
/// XCDR2, little-endian; anything else a failure.
pub(crate) fn decode<T: CdrType>(payload: &[u8]) -> Result<T, DecodeFailure> {
    let header: Option<[u8; 4]> = payload.get(..4).and_then(|h| h.try_into().ok());
    let Some(encoding) = header.and_then(CdrEncoding::from_header) else {
        return Err(DecodeFailure {
            checksum: false,
            reason: format!("unsupported representation {:02x?}", payload.get(..2).unwrap_or(payload)),
        });
    };
    T::decode_body(encoding, &unpadded(payload)[4..])
        .map_err(|e| DecodeFailure { checksum: T::is_checksum_error(&e), reason: e.to_string() })
}

/// A received payload without the padding its encapsulation options' last two bits announce
/// (XTypes 7.6.3.1.2), never shorter than its 4-byte header: what a reader decodes. (Public for
/// the fuzz targets' oracles, not API.)
#[doc(hidden)]
pub fn unpadded(payload: &[u8]) -> &[u8] {
    match payload.get(3) {
        Some(options) => &payload[..payload.len().saturating_sub(usize::from(options & 3)).max(4)],
        None => payload,
    }
}

/// `value`'s payload: `T`'s encapsulation header and its body, padded with zeros to a multiple
/// of 4 bytes as RTPS needs (the padding's length in the options' last two bits, XTypes
/// 7.6.3.1.2), into `out` (grown as needed, so a buffer reused across writes of one type stops
/// allocating).
pub(crate) fn encode<T: CdrType>(value: &T, out: &mut Vec<u8>) -> Result<(), robowire_core::BufferTooSmall> {
    let len = 4 + value.body_len();
    if out.len() < len + 3 {
        out.resize(len + 3, 0);
    }
    out[..4].copy_from_slice(&T::ENCODING.header());
    let n = value.encode_body(&mut out[4..])?;
    let padding = (4 - n % 4) % 4;
    out[4 + n..4 + n + padding].fill(0);
    out[3] = (out[3] & !3) | padding as u8;
    out.truncate(4 + n + padding);
    Ok(())
}

/// The receive path's check for fuzz targets (not public API): `payload` decoded as a reader
/// does. A supported header gives what the codec makes of the body (a message, or a failure
/// whose checksum flag is the codec's); any other is refused (`None`). A message read is
/// written back and reads back the same. Panics otherwise.
#[doc(hidden)]
pub fn fuzz_check_sample<T: CdrType + std::fmt::Debug>(payload: &[u8]) -> Option<Result<T, bool>> {
    let supported = payload.get(..4).and_then(|h| CdrEncoding::from_header(h.try_into().ok()?)).is_some();
    let read = decode::<T>(payload);
    if !supported {
        assert!(read.is_err(), "an unsupported header read as a message");
        return None;
    }
    match read {
        Ok(value) => {
            let mut sent = Vec::new();
            encode(&value, &mut sent).expect("a message read encodes");
            let again =
                decode::<T>(&sent).unwrap_or_else(|e| panic!("{value:?} sent does not read back: {}", e.reason));
            let mut resent = Vec::new();
            encode(&again, &mut resent).expect("a message read encodes");
            assert_eq!(resent, sent, "a message read back is the message sent");
            Some(Ok(value))
        }
        Err(failure) => Some(Err(failure.checksum)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_xcdr2_sample_is_read() {
        use unitree_proto::{LowCmd, Message, MotorCmd};
        let mut command = LowCmd::default();
        command.motor_cmd[0] = MotorCmd::servo(0.5, 0.0, 20.0, 0.5, 0.0);
        let mut payload = vec![0u8; LowCmd::cdr_len(CdrEncoding::Xcdr2)];
        command.encode_cdr(CdrEncoding::Xcdr2, &mut payload).unwrap();
        assert_eq!(decode::<LowCmd>(&payload).unwrap(), command.sealed());
        assert_eq!(fuzz_check_sample::<LowCmd>(&payload), Some(Ok(command.sealed())));
    }

    #[test]
    fn a_body_is_padded_to_four_bytes_and_the_padding_is_said_and_stripped() {
        let sample = RawSample { encoding: CdrEncoding::Xcdr1, body: vec![1, 2, 3, 4, 5] };
        let mut payload = Vec::new();
        encode(&sample, &mut payload).unwrap();
        assert_eq!(payload, [0, 1, 0, 3, 1, 2, 3, 4, 5, 0, 0, 0]);
        assert_eq!(decode::<RawSample>(&payload).unwrap(), sample);
        // A hostile padding count never reaches into the header.
        assert_eq!(decode::<RawSample>(&[0, 1, 0, 3, 9]).unwrap().body, Vec::<u8>::new());
    }

    #[test]
    fn other_representations_are_refused() {
        assert!(decode::<RawSample>(&[0, 2, 0, 0, 1]).is_err());
        assert!(decode::<RawSample>(&[0, 1]).is_err());
        assert_eq!(fuzz_check_sample::<RawSample>(&[0, 3, 0, 0]), None);
    }
}
