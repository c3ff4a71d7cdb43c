use super::*;

#[test]
fn request_layout_by_the_cdr_rules() {
    let request = Request {
        header: RequestHeader { id: 0x0102, api_id: 1001, lease_id: 0, priority: 3, noreply: true },
        parameter: "{}",
        binary: &[9, 8],
    };
    let mut body = [0xAAu8; 64];
    let n = request.encode_body(&mut body).unwrap();
    let expected: &[u8] = &[
        0x02, 0x01, 0, 0, 0, 0, 0, 0, // id
        0xE9, 0x03, 0, 0, 0, 0, 0, 0, // api_id 1001
        0, 0, 0, 0, 0, 0, 0, 0, // lease
        3, 0, 0, 0, // priority
        1, 0, 0, 0, // noreply, then alignment for the string length
        3, 0, 0, 0, b'{', b'}', 0, // "{}" with its NUL
        0, // alignment
        2, 0, 0, 0, 9, 8, // binary
    ];
    assert_eq!(&body[..n], expected);
    assert_eq!(Request::decode_body(expected), Ok(request));
    assert_eq!(request.body_len(), expected.len());
}

#[test]
fn response_round_trip_and_errors() {
    let header = RequestHeader::call(42, motion_switcher::CHECK_MODE);
    let response = Response::to(&header, status::OK, r#"{"form":"0","name":"normal"}"#);
    let mut body = [0u8; 128];
    let n = response.encode_body(&mut body).unwrap();
    assert_eq!(Response::decode_body(&body[..n]), Ok(response));
    // Padding after the last field is fine; more is not.
    assert!(Response::decode_body(&body[..n + 3]).is_ok());
    assert_eq!(Response::decode_body(&body[..n + 8]), Err(ApiError::Trailing { extra: 8 }));
    assert!(matches!(Response::decode_body(&body[..n - 1]), Err(ApiError::Truncated { field: "binary", .. })));
    let mut short = [0u8; 8];
    assert_eq!(response.encode_body(&mut short), Err(BufferTooSmall { needed: n, available: 8 }));
    // A string without its NUL.
    let mut bad = body;
    bad[20 + 4 + response.data.len()] = b'x';
    assert_eq!(Response::decode_body(&bad[..n]), Err(ApiError::NoNul { field: "data" }));
}
