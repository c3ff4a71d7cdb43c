//! Decode round trips, the property the fuzz targets (`fuzz/`) and xtask's corpus replay check
//! (feature `fuzzing`: internal, not public API).
//!
//! Input layout: byte 0 selects the message (`% 4`: Go2 LowCmd, Go2 LowState, HG LowCmd, HG
//! LowState; for [`api_decode`] `% 2`: `Request_`, `Response_`); the rest is the struct image,
//! CDR payload or service body. Each check panics if decoding panics, or if a decoded message
//! does not re-encode to bytes that decode, verified, to the same sealed message. Under
//! `cfg(fuzzing)` verification is bypassed so that the parser is reached.

extern crate alloc;

use alloc::vec;
use alloc::vec::Vec;
use core::fmt::Debug;

use crate::api::{ApiRequest, ApiResponse, Request, Response, mode_name};
use crate::{HgLowCmd, HgLowState, LowCmd, LowState, MAX_IMAGE_LEN, Message};

/// Largest CDR payload: HG `LowState_` in XCDR2 (header, body, DHEADER).
const MAX_CDR_LEN: usize = 4 + MAX_IMAGE_LEN + 4;

/// Struct-image decoding of the selected message.
pub fn image_decode(data: &[u8]) {
    let Some((&selector, bytes)) = data.split_first() else { return };
    match selector % 4 {
        0 => check_image::<LowCmd>(bytes),
        1 => check_image::<LowState>(bytes),
        2 => check_image::<HgLowCmd>(bytes),
        _ => check_image::<HgLowState>(bytes),
    }
}

/// CDR decoding of the selected message.
pub fn cdr_decode(data: &[u8]) {
    let Some((&selector, bytes)) = data.split_first() else { return };
    match selector % 4 {
        0 => check_cdr::<LowCmd>(bytes),
        1 => check_cdr::<LowState>(bytes),
        2 => check_cdr::<HgLowCmd>(bytes),
        _ => check_cdr::<HgLowState>(bytes),
    }
}

/// Service body decoding (`Request_` or `Response_`, XCDR1 and XCDR2 alike).
pub fn api_decode(data: &[u8]) {
    let Some((&selector, body)) = data.split_first() else { return };
    if selector % 2 == 0 {
        let Ok(request) = Request::decode_body(body) else { return };
        let first = check_api_body(body, request.body_len(), |out| request.encode_body(out));
        assert_eq!(Request::decode_body(&first), Ok(request));
        assert_eq!(ApiRequest::from(request).view(), request);
        check_mode_name(request.parameter);
    } else {
        let Ok(response) = Response::decode_body(body) else { return };
        let first = check_api_body(body, response.body_len(), |out| response.encode_body(out));
        assert_eq!(Response::decode_body(&first), Ok(response));
        assert_eq!(ApiResponse::from(response).view(), response);
        check_mode_name(response.data);
    }
}

/// The re-encoded body of a decoded `body`: its announced length, the same bytes but padding
/// (zeroed), at most 7 bytes shorter.
fn check_api_body(
    body: &[u8],
    len: usize,
    encode: impl FnOnce(&mut [u8]) -> Result<usize, crate::BufferTooSmall>,
) -> Vec<u8> {
    let mut out = vec![0u8; len];
    assert_eq!(encode(&mut out), Ok(len), "body_len is the length written");
    assert!(len <= body.len() && body.len() - len <= 7, "only padding may follow the last field");
    assert!(out.iter().zip(body).all(|(&e, &b)| e == b || e == 0), "every field's bytes are written back");
    out
}

/// A mode name, if any, is a quote-free part of the text.
fn check_mode_name(json: &str) {
    if let Some(name) = mode_name(json) {
        assert!(json.contains(name) && !name.contains('"'));
    }
}

fn check_image<M: Message + Debug + Eq>(bytes: &[u8]) {
    let strict = M::decode_image(bytes);
    let Ok(unverified) = M::decode_image_unverified(bytes) else {
        assert!(strict.is_err(), "strict decoding accepted what unverified decoding refused");
        return;
    };
    assert_eq!(strict.is_ok(), cfg!(fuzzing) || (unverified.crc.is_ok() && unverified.padding.is_none()));
    let mut out = [0u8; MAX_IMAGE_LEN];
    let n = unverified.message.encode_image(&mut out).expect("buffer is large enough");
    assert_eq!(n, bytes.len());
    // Everything but padding and CRC is carried over unchanged.
    assert_eq!(&out[..n - 4], &unverified.message.as_bytes()[..n - 4]);
    let again = M::decode_image(&out[..n]).expect("a sealed image verifies");
    assert_eq!(again, unverified.message.sealed());
}

fn check_cdr<M: Message + Debug + Eq>(bytes: &[u8]) {
    let strict = M::decode_cdr(bytes);
    let Ok((unverified, encoding)) = M::decode_cdr_unverified(bytes) else {
        assert!(strict.is_err(), "strict decoding accepted what unverified decoding refused");
        return;
    };
    assert_eq!(strict.is_ok(), cfg!(fuzzing) || unverified.crc.is_ok());
    let mut out = [0u8; MAX_CDR_LEN];
    let n = unverified.message.encode_cdr(encoding, &mut out).expect("buffer is large enough");
    assert_eq!(n, bytes.len());
    let (again, again_encoding) = M::decode_cdr(&out[..n]).expect("a sealed payload verifies");
    assert_eq!(again, unverified.message.sealed());
    assert_eq!(again_encoding, encoding);
}
