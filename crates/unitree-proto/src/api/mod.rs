//! The robot's services (spec `unitree-dds.md`): `unitree_api::msg::dds_::Request_` and
//! `Response_` on `rt/api/<service>/request` and `/response`, and the API ids of the services
//! robowire speaks (`motion_switcher`, the Go2's `sport`, the G1's `sport` and `arm`).
//!
//! ```text
//! Request_  { header { identity { int64 id; int64 api_id; }  lease { int64 id; }
//!                      policy { int32 priority; boolean noreply; } }
//!             string parameter; sequence<uint8> binary; }
//! Response_ { header { identity { int64 id; int64 api_id; }  status { int32 code; } }
//!             string data; sequence<uint8> binary; }
//! ```
//!
//! Both are `@final`: their XCDR1 and XCDR2 bodies are the same bytes (the int64 fields sit at
//! body offsets 0, 8 and 16, aligned either way; a primitive sequence has no DHEADER). Strings
//! carry their NUL, counted in their length. The views here borrow; with the `alloc` feature,
//! [`ApiRequest`] and [`ApiResponse`] own their strings and are `CdrType`s.
//!
//! ```
//! use unitree_proto::api::{self, Request, RequestHeader};
//!
//! let request = Request { header: RequestHeader::call(7, api::motion_switcher::CHECK_MODE), parameter: "{}", binary: &[] };
//! let mut body = [0u8; 64];
//! let n = request.encode_body(&mut body).unwrap();
//! assert_eq!(n, request.body_len());
//! assert_eq!(Request::decode_body(&body[..n]), Ok(request));
//! ```

use robowire_core::BufferTooSmall;
use robowire_core::cdr::{CdrEncoding, CdrError, CdrReader, CdrWriter};

/// Service names and API ids of `motion_switcher` (API version "1.0.0.1").
pub mod motion_switcher;

/// The mode name in a CheckMode answer (`{"form":"0","name":"normal"}`) or a SelectMode
/// parameter (`{"name":"ai"}`): the string value of `"name"` in a flat JSON object (no
/// escapes, as Unitree's services write it). `None` if there is none.
///
/// ```
/// use unitree_proto::api::motion_switcher::mode_name;
/// assert_eq!(mode_name(r#"{"form":"0","name":"normal"}"#), Some("normal"));
/// assert_eq!(mode_name(r#"{"form": "0", "name": ""}"#), Some(""));
/// assert_eq!(mode_name("{}"), None);
/// ```
pub fn mode_name(json: &str) -> Option<&str> {
    let rest = &json[json.find("\"name\"")? + 6..];
    let rest = rest.trim_start().strip_prefix(':')?.trim_start().strip_prefix('"')?;
    Some(&rest[..rest.find('"')?])
}

/// Service name and the API ids of `sport` that robowire uses (API version "1.0.0.1").
pub mod sport;

/// The G1's locomotion service (Unitree's `LocoClient`): service `sport` like the Go2's, but
/// its own API (version "1.0.0.0") and ids. Parameters and data are JSON, `{"data": …}` unless
/// said otherwise.
pub mod g1_loco;

/// The G1's arm action service (Unitree's `G1ArmActionClient`): service `arm`, API version
/// "1.0.0.14".
pub mod g1_arm;

/// The internal API every service answers: its API version.
pub const API_VERSION_ID: i64 = 1;

/// Status codes of the RPC layer (unitree_sdk2's `rpc/internal`).
pub mod status {
    /// Success.
    pub const OK: i32 = 0;
    /// The server has no such API.
    pub const SERVER_API_NOT_IMPLEMENTED: i32 = 3203;
    /// The server refused the parameter.
    pub const SERVER_API_PARAMETER: i32 = 3204;
    /// The server failed internally.
    pub const SERVER_INTERNAL: i32 = 3202;
}

/// DDS type name of [`Request`].
pub const REQUEST_TYPE_NAME: &str = "unitree_api::msg::dds_::Request_";
/// DDS type name of [`Response`].
pub const RESPONSE_TYPE_NAME: &str = "unitree_api::msg::dds_::Response_";

/// The request topic of `service` (`rt/api/<service>/request`).
pub fn request_topic(service: &str) -> impl core::fmt::Display + '_ {
    Topic { service, suffix: "request" }
}

/// The response topic of `service` (`rt/api/<service>/response`).
pub fn response_topic(service: &str) -> impl core::fmt::Display + '_ {
    Topic { service, suffix: "response" }
}

struct Topic<'a> {
    service: &'a str,
    suffix: &'static str,
}

impl core::fmt::Display for Topic<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "rt/api/{}/{}", self.service, self.suffix)
    }
}

/// `RequestHeader_`, flattened.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RequestHeader {
    /// `identity.id`: the caller's request id, echoed by the answer (Unitree's SDKs use the
    /// monotonic clock in ns).
    pub id: i64,
    /// `identity.api_id`.
    pub api_id: i64,
    /// `lease.id` (0 without a lease).
    pub lease_id: i64,
    /// `policy.priority`.
    pub priority: i32,
    /// `policy.noreply`: the server sends no answer.
    pub noreply: bool,
}

impl RequestHeader {
    /// A call that wants an answer: no lease, priority 0.
    pub const fn call(id: i64, api_id: i64) -> Self {
        Self { id, api_id, lease_id: 0, priority: 0, noreply: false }
    }
}

/// `Request_`, borrowing its string and bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Request<'a> {
    /// The header.
    pub header: RequestHeader,
    /// `parameter`, JSON by convention.
    pub parameter: &'a str,
    /// `binary`.
    pub binary: &'a [u8],
}

/// `Response_`, borrowing its string and bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Response<'a> {
    /// `identity.id`: the request's.
    pub id: i64,
    /// `identity.api_id`: the request's.
    pub api_id: i64,
    /// `status.code`: 0 on success.
    pub code: i32,
    /// `data`, JSON by convention.
    pub data: &'a str,
    /// `binary`.
    pub binary: &'a [u8],
}

/// Why a body is not a `Request_` or `Response_`.
pub type ApiError = CdrError;

impl<'a> Request<'a> {
    /// Body length, bytes.
    pub fn body_len(&self) -> usize {
        let mut w = CdrWriter::measure(CdrEncoding::Xcdr1);
        self.write(&mut w);
        w.position()
    }

    fn write(&self, w: &mut CdrWriter<'_>) {
        let h = &self.header;
        w.bytes(8, &h.id.to_le_bytes());
        w.bytes(8, &h.api_id.to_le_bytes());
        w.bytes(8, &h.lease_id.to_le_bytes());
        w.bytes(4, &h.priority.to_le_bytes());
        w.bytes(1, &[u8::from(h.noreply)]);
        w.string(self.parameter);
        w.octets(self.binary);
    }

    /// Writes the body into `out`; its length.
    pub fn encode_body(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let mut w = CdrWriter::new(CdrEncoding::Xcdr1, out);
        self.write(&mut w);
        w.finish()
    }

    /// Reads a body (XCDR1 or XCDR2: the same bytes).
    pub fn decode_body(body: &'a [u8]) -> Result<Self, ApiError> {
        let mut r = CdrReader::new(CdrEncoding::Xcdr1, body);
        let header = RequestHeader {
            id: r.i64("header.identity.id")?,
            api_id: r.i64("header.identity.api_id")?,
            lease_id: r.i64("header.lease.id")?,
            priority: r.i32("header.policy.priority")?,
            noreply: r.bool("header.policy.noreply")?,
        };
        let request = Self { header, parameter: r.string("parameter")?, binary: r.octets("binary")? };
        r.finish()?;
        Ok(request)
    }
}

impl<'a> Response<'a> {
    /// The answer to `request` with `code` and `data`.
    pub fn to(request: &RequestHeader, code: i32, data: &'a str) -> Self {
        Self { id: request.id, api_id: request.api_id, code, data, binary: &[] }
    }

    /// Body length, bytes.
    pub fn body_len(&self) -> usize {
        let mut w = CdrWriter::measure(CdrEncoding::Xcdr1);
        self.write(&mut w);
        w.position()
    }

    fn write(&self, w: &mut CdrWriter<'_>) {
        w.bytes(8, &self.id.to_le_bytes());
        w.bytes(8, &self.api_id.to_le_bytes());
        w.bytes(4, &self.code.to_le_bytes());
        w.string(self.data);
        w.octets(self.binary);
    }

    /// Writes the body into `out`; its length.
    pub fn encode_body(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
        let mut w = CdrWriter::new(CdrEncoding::Xcdr1, out);
        self.write(&mut w);
        w.finish()
    }

    /// Reads a body (XCDR1 or XCDR2: the same bytes).
    pub fn decode_body(body: &'a [u8]) -> Result<Self, ApiError> {
        let mut r = CdrReader::new(CdrEncoding::Xcdr1, body);
        let response = Self {
            id: r.i64("header.identity.id")?,
            api_id: r.i64("header.identity.api_id")?,
            code: r.i32("header.status.code")?,
            data: r.string("data")?,
            binary: r.octets("binary")?,
        };
        r.finish()?;
        Ok(response)
    }
}

#[cfg(feature = "alloc")]
mod owned {
    extern crate alloc;
    use alloc::string::String;
    use alloc::vec::Vec;

    use robowire_core::BufferTooSmall;
    use robowire_core::cdr::{CdrEncoding, CdrType};

    use super::{ApiError, REQUEST_TYPE_NAME, RESPONSE_TYPE_NAME, Request, RequestHeader, Response};

    /// `Request_`, owning its string and bytes: what a DDS topic carries.
    #[derive(Debug, Clone, PartialEq, Eq, Default)]
    pub struct ApiRequest {
        /// The header.
        pub header: RequestHeader,
        /// `parameter`.
        pub parameter: String,
        /// `binary`.
        pub binary: Vec<u8>,
    }

    impl ApiRequest {
        /// The borrowed view.
        pub fn view(&self) -> Request<'_> {
            Request { header: self.header, parameter: &self.parameter, binary: &self.binary }
        }
    }

    impl From<Request<'_>> for ApiRequest {
        fn from(r: Request<'_>) -> Self {
            Self { header: r.header, parameter: r.parameter.into(), binary: r.binary.into() }
        }
    }

    /// `Response_`, owning its string and bytes.
    #[derive(Debug, Clone, PartialEq, Eq, Default)]
    pub struct ApiResponse {
        /// `identity.id`.
        pub id: i64,
        /// `identity.api_id`.
        pub api_id: i64,
        /// `status.code`.
        pub code: i32,
        /// `data`.
        pub data: String,
        /// `binary`.
        pub binary: Vec<u8>,
    }

    impl ApiResponse {
        /// The borrowed view.
        pub fn view(&self) -> Response<'_> {
            Response { id: self.id, api_id: self.api_id, code: self.code, data: &self.data, binary: &self.binary }
        }
    }

    impl From<Response<'_>> for ApiResponse {
        fn from(r: Response<'_>) -> Self {
            Self { id: r.id, api_id: r.api_id, code: r.code, data: r.data.into(), binary: r.binary.into() }
        }
    }

    /// `CdrType` for an owned message through its borrowed view.
    macro_rules! cdr_type {
        ($owned:ty, $view:ident, $name:expr) => {
            impl CdrType for $owned {
                const TYPE_NAME: &'static str = $name;
                type Error = ApiError;
                fn body_len(&self) -> usize {
                    self.view().body_len()
                }
                fn encode_body(&self, out: &mut [u8]) -> Result<usize, BufferTooSmall> {
                    self.view().encode_body(out)
                }
                fn decode_body(_: CdrEncoding, body: &[u8]) -> Result<Self, ApiError> {
                    $view::decode_body(body).map(Self::from)
                }
            }
        };
    }

    cdr_type!(ApiRequest, Request, REQUEST_TYPE_NAME);
    cdr_type!(ApiResponse, Response, RESPONSE_TYPE_NAME);
}

#[cfg(feature = "alloc")]
pub use owned::{ApiRequest, ApiResponse};

#[cfg(test)]
mod tests;
