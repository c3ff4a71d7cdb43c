//! Decode round trips of every message, the property the fuzz target (`fuzz/`) and xtask's
//! seed replay check (feature `fuzzing`: internal, not public API).
//!
//! Input layout: byte 0 selects the message (its low 7 bits `%` the number of messages, in the
//! order listed below; [`input`] makes one) and the representation the body is said to be in
//! (top bit set: XCDR2, which every message refuses); the rest is the body. A check panics if decoding
//! panics, if XCDR2 is not refused, or if a decoded body does not re-encode to the same bytes
//! (up to padding, which the encoder zeroes, and at most 7 trailing bytes) that decode again to
//! the same value. Values are compared by their encoding, so that NaN equals itself.
//!
//! Counts are checked against the body before anything is allocated
//! ([`CdrReader::count`](robowire_core::cdr::CdrReader::count)); the fuzz target's memory
//! limit is what catches an allocation sized by a lying count.

use alloc::vec;
use alloc::vec::Vec;
use core::fmt::Debug;

use robowire_core::cdr::{CdrEncoding, CdrError, CdrType};

use crate::builtin::Header;
use crate::diagnostic::DiagnosticArray;
use crate::geometry::{TransformStamped, Twist};
use crate::nav::Odometry;
use crate::rmw_dds_common::{GID_LEN_HUMBLE, GID_LEN_JAZZY, ParticipantEntitiesInfo};
use crate::sensor::{BatteryState, Imu, JointState};
use crate::srv::{AnyTriggerRequest, TriggerRequest, TriggerRequestBody, TriggerResponse, TriggerResponseBody};
use crate::tf::TfMessage;

/// The messages by selector: their Rust type names (two layouts may share a DDS type name), and
/// the check of each.
macro_rules! messages {
    ($($ty:ty),* $(,)?) => {
        const TYPE_NAMES: &[fn() -> &'static str] = &[$(core::any::type_name::<$ty>),*];
        const CHECKS: &[fn(CdrEncoding, &[u8])] = &[$(check::<$ty>),*];
    };
}

messages!(
    Header,
    Twist,
    TransformStamped,
    Odometry,
    TfMessage,
    Imu,
    JointState,
    BatteryState,
    DiagnosticArray,
    TriggerRequest,
    TriggerResponse,
    ParticipantEntitiesInfo<GID_LEN_JAZZY>,
    ParticipantEntitiesInfo<GID_LEN_HUMBLE>,
    TriggerRequestBody,
    TriggerResponseBody,
    AnyTriggerRequest,
);

/// Top bit of the selector: the body is said to be XCDR2.
const XCDR2: u8 = 0x80;

/// The selected message's decoding of the rest of `data`.
pub fn message_decode(data: &[u8]) {
    let Some((&selector, body)) = data.split_first() else { return };
    let encoding = if selector & XCDR2 == 0 { CdrEncoding::Xcdr1 } else { CdrEncoding::Xcdr2 };
    CHECKS[usize::from(selector & !XCDR2) % CHECKS.len()](encoding, body);
}

/// The input that selects `message`'s type, with its XCDR1 body (a seed).
pub fn input<T: CdrType>(message: &T) -> Vec<u8> {
    let selector =
        TYPE_NAMES.iter().position(|name| name() == core::any::type_name::<T>()).expect("a message of this crate");
    let mut input = vec![selector as u8];
    input.extend(encode(message));
    input
}

fn encode<T: CdrType>(message: &T) -> Vec<u8> {
    let mut body = vec![0u8; message.body_len()];
    let n = message.encode_body(&mut body).expect("body_len is the length written");
    assert_eq!(n, body.len(), "body_len is the length written");
    body
}

fn check<T: CdrType<Error = CdrError> + Debug>(encoding: CdrEncoding, body: &[u8]) {
    let decoded = T::decode_body(encoding, body);
    if encoding == CdrEncoding::Xcdr2 {
        assert_eq!(decoded.err(), Some(CdrError::Encoding(CdrEncoding::Xcdr2)), "XCDR2 is refused");
        return;
    }
    let Ok(message) = decoded else { return };
    let first = encode(&message);
    assert!(first.len() <= body.len() && body.len() - first.len() <= 7, "only padding may follow the last field");
    assert!(first.iter().zip(body).all(|(&e, &b)| e == b || e == 0), "every field's bytes are written back");
    let again = T::decode_body(CdrEncoding::Xcdr1, &first).expect("a re-encoded body decodes");
    assert_eq!(encode(&again), first, "decoding the re-encoded body gives the same value");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::Time;

    #[test]
    fn every_message_has_a_selector() {
        assert_eq!(TYPE_NAMES.len(), CHECKS.len());
        let joints = JointState { name: vec!["FR_hip".into()], position: vec![f64::NAN], ..JointState::default() };
        let seed = input(&joints);
        assert_eq!(
            usize::from(seed[0]),
            TYPE_NAMES.iter().position(|n| n() == core::any::type_name::<JointState>()).unwrap()
        );
        message_decode(&seed);
        let mut xcdr2 = seed;
        xcdr2[0] |= XCDR2;
        message_decode(&xcdr2);
        message_decode(&input(&BatteryState::unmeasured(Header { stamp: Time::from_nanos(7), frame_id: "b".into() })));
    }
}
