//! rustdds's (de)serializer adapters over robowire's codecs: the codec writes and reads the CDR
//! body, rustdds the 4-byte encapsulation header. A body that does not decode is not an error
//! for rustdds: it becomes a [`Decoded::Err`] sample, so that the reader counts it.

use std::marker::PhantomData;

use bytes::Bytes;
use robowire_core::cdr::{CdrEncoding, CdrType};
use rustdds::RepresentationIdentifier;
use rustdds::no_key::{Decode, DefaultDecoder, DeserializerAdapter, SerializerAdapter};

/// A sample as read: the message, or why its body did not decode.
pub(crate) type Decoded<T> = Result<T, DecodeFailure>;

/// Why a sample's body did not decode.
#[derive(Debug, Clone)]
pub(crate) struct DecodeFailure {
    pub(crate) checksum: bool,
    pub(crate) reason: String,
}

/// The adapter for `T`.
pub(crate) struct CdrAdapter<T>(PhantomData<fn(T) -> T>);

/// The encodings robowire reads: XCDR1 (`00 01`) and XCDR2 (`00 07`), little endian. (rustdds's
/// `CDR2_LE` is `00 11`, a value of an older RTPS table that no DDS writes.)
const READ: [RepresentationIdentifier; 2] = [RepresentationIdentifier::CDR_LE, RepresentationIdentifier::XCDR2_LE];

/// Never fails: the codec's error becomes a value.
#[derive(Debug, thiserror::Error)]
#[error("unreachable")]
pub(crate) struct Never;

fn encoding(id: RepresentationIdentifier) -> Option<CdrEncoding> {
    CdrEncoding::from_identifier(id.to_bytes())
}

impl<T: CdrType> SerializerAdapter<T> for CdrAdapter<T> {
    type Error = EncodeError;

    fn output_encoding() -> RepresentationIdentifier {
        let [a, b] = T::ENCODING.identifier();
        RepresentationIdentifier::from_bytes(&[a, b]).unwrap_or(RepresentationIdentifier::CDR_LE)
    }

    /// One allocation per sample: rustdds takes `Bytes`.
    fn to_bytes(value: &T) -> Result<Bytes, EncodeError> {
        let mut body = vec![0u8; value.body_len()];
        let n = value.encode_body(&mut body).map_err(|e| EncodeError(e.to_string()))?;
        body.truncate(n);
        Ok(Bytes::from(body))
    }
}

/// A message the codec could not write (never with robowire's fixed-size messages).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct EncodeError(String);

impl<T: CdrType> DeserializerAdapter<Decoded<T>> for CdrAdapter<T> {
    type Error = Never;
    type Decoded = Decoded<T>;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &READ
    }

    fn transform_decoded(decoded: Decoded<T>) -> Decoded<T> {
        decoded
    }
}

/// The decoder value rustdds hands bytes to.
pub(crate) struct Decoder<T>(PhantomData<fn(T) -> T>);

impl<T> Clone for Decoder<T> {
    fn clone(&self) -> Self {
        Self(PhantomData)
    }
}

impl<'de, T: CdrType> Decode<'de, Decoded<T>> for Decoder<T> {
    type Error = Never;

    fn decode_bytes(self, body: &'de [u8], id: RepresentationIdentifier) -> Result<Decoded<T>, Never> {
        let Some(encoding) = encoding(id) else {
            return Ok(Err(DecodeFailure { checksum: false, reason: format!("unsupported representation {id:?}") }));
        };
        Ok(T::decode_body(encoding, body)
            .map_err(|e| DecodeFailure { checksum: T::is_checksum_error(&e), reason: e.to_string() }))
    }
}

/// A payload as a tapped reader took it, for its tap: the encapsulation header rebuilt from the
/// representation rustdds reports (its 2 option bytes, which rustdds does not hand over, as
/// zero) and the body, copied into room allocated once.
#[derive(Debug)]
pub(crate) struct TakenPayload {
    pub(crate) header: [u8; 4],
    pub(crate) body: Vec<u8>,
    /// Longer than a tap's slot: not copied.
    pub(crate) oversize: bool,
}

impl TakenPayload {
    pub(crate) fn new() -> Self {
        Self { header: [0; 4], body: Vec::with_capacity(robowire_tap::SLOT_BYTES), oversize: false }
    }
}

/// The reader's decoder when a tap listens: keeps a copy of each payload it decodes.
pub(crate) struct TapDecoder<'a, T> {
    pub(crate) taken: &'a std::cell::RefCell<TakenPayload>,
    pub(crate) decoder: PhantomData<fn(T) -> T>,
}

impl<T> Clone for TapDecoder<'_, T> {
    fn clone(&self) -> Self {
        Self { taken: self.taken, decoder: PhantomData }
    }
}

impl<'de, T: CdrType> Decode<'de, Decoded<T>> for TapDecoder<'_, T> {
    type Error = Never;

    fn decode_bytes(self, body: &'de [u8], id: RepresentationIdentifier) -> Result<Decoded<T>, Never> {
        if let Ok(mut taken) = self.taken.try_borrow_mut() {
            let [a, b] = id.to_bytes();
            taken.header = [a, b, 0, 0];
            taken.body.clear();
            taken.oversize = body.len() + 4 > robowire_tap::SLOT_BYTES;
            if !taken.oversize {
                taken.body.extend_from_slice(body);
            }
        }
        Decoder::<T>(PhantomData).decode_bytes(body, id)
    }
}

impl<T: CdrType> DefaultDecoder<Decoded<T>> for CdrAdapter<T> {
    type Decoder = Decoder<T>;
    const DECODER: Decoder<T> = Decoder(PhantomData);
}

/// What a reader makes of a payload: `None` if rustdds refuses it (shorter than the header, or
/// a representation not in `supported_encodings`), else the adapter's sample.
fn receive<T: CdrType>(payload: &[u8]) -> Option<Decoded<T>> {
    let payload = rustdds::SerializedPayload::from_bytes(&Bytes::copy_from_slice(payload)).ok()?;
    let id = CdrAdapter::<T>::supported_encodings().iter().find(|id| **id == payload.representation_identifier)?;
    CdrAdapter::<T>::from_bytes(&payload.value, *id).ok()
}

/// The payload a writer sends for `value`.
fn send<T: CdrType>(value: &T) -> Bytes {
    let body = CdrAdapter::<T>::to_bytes(value).expect("robowire's messages always encode");
    rustdds::SerializedPayload::new_from_bytes(CdrAdapter::<T>::output_encoding(), body).into()
}

/// The receive path's check for fuzz targets (not public API): `payload` (encapsulation header,
/// body) taken apart by rustdds and decoded as a reader does. A supported header gives what the
/// codec makes of the body (a message, or a failure whose checksum flag is the codec's); any
/// other is refused; a message read is written back through the writer's adapter and reads back
/// the same. Panics otherwise. Returns the reader's sample: the message, or whether the failure
/// was a checksum failure.
#[doc(hidden)]
pub fn fuzz_check_sample<T: CdrType + std::fmt::Debug>(payload: &[u8]) -> Option<Result<T, bool>> {
    check_sample::<T>(payload).map(|sample| sample.map_err(|failure| failure.checksum))
}

/// The reader's sample agrees with the codec; a message read is written and read back the same.
fn check_sample<T: CdrType + std::fmt::Debug>(payload: &[u8]) -> Option<Decoded<T>> {
    let sample = receive::<T>(payload);
    let codec = payload
        .get(..4)
        .and_then(|header| CdrEncoding::from_header(header.try_into().ok()?))
        .map(|encoding| T::decode_body(encoding, &payload[4..]));
    match (&sample, codec) {
        (None, None) => {}
        (Some(Ok(value)), Some(Ok(_))) => {
            let sent = send(value);
            let Some(Ok(again)) = receive::<T>(&sent) else { panic!("{value:?} sent does not read back") };
            assert_eq!(send(&again), sent, "a message read back is the message sent");
        }
        (Some(Err(failure)), Some(Err(error))) => {
            assert_eq!(failure.checksum, T::is_checksum_error(&error));
            assert_eq!(failure.reason, error.to_string());
        }
        (sample, codec) => panic!("the reader made {sample:?} of {payload:02x?}, the codec {codec:?}"),
    }
    sample
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_encodings_the_codecs_read() {
        let read: Vec<_> = READ.iter().map(|id| encoding(*id)).collect();
        assert_eq!(read, [Some(CdrEncoding::Xcdr1), Some(CdrEncoding::Xcdr2)]);
    }

    #[test]
    fn an_xcdr2_sample_is_read() {
        use lowcmd_proto::{LowCmd, Message, MotorCmd};
        let mut command = LowCmd::default();
        command.motor_cmd[0] = MotorCmd::servo(0.5, 0.0, 20.0, 0.5, 0.0);
        let mut payload = vec![0u8; LowCmd::cdr_len(CdrEncoding::Xcdr2)];
        command.encode_cdr(CdrEncoding::Xcdr2, &mut payload).unwrap();
        let read = receive::<LowCmd>(&payload).expect("XCDR2 is a supported encoding");
        assert_eq!(read.unwrap(), command.sealed());
        assert_eq!(fuzz_check_sample::<LowCmd>(&payload), Some(Ok(command.sealed())));
    }
}
