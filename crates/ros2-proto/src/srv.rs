//! Services: `std_srvs/Trigger` in the two mappings of ROS 2's middlewares.
//!
//! rmw_cyclonedds writes every request and reply sample as `cdds_request_header_t { uint64 guid;
//! int64 seq; }` followed by the request or response struct, in one XCDR1 body
//! ([`TriggerRequest`], [`TriggerResponse`]). The client sets `guid` to an id of its own (its
//! request writer's instance handle) and counts `seq` up from 1; the service copies both into the
//! reply, and a client takes only replies with its `guid`.
//!
//! rmw_fastrtps writes the bare struct ([`TriggerRequestBody`], [`TriggerResponseBody`]): which
//! request a reply answers travels beside the body, as the sample's related sample identity.
//! Both mappings use the same DDS type names.

use alloc::string::String;

use robowire_core::cdr::{CdrEncoding, CdrError, CdrType};

ros_struct! {
    /// The header before every request and reply (rmw_cyclonedds' `cdds_request_header_t`).
    #[derive(Default, Copy, Eq, Hash)]
    pub struct RequestId {
        /// The client's id.
        pub guid: u64,
        /// The request's number at that client, from 1.
        pub seq: i64,
    }
}

ros_struct! {
    /// A `std_srvs/Trigger` request with its header (`Trigger_Request_` has one placeholder
    /// byte, as every empty ROS 2 struct).
    #[derive(Default, Copy, Eq)]
    pub struct TriggerRequest {
        /// Who asks.
        pub id: RequestId,
        /// `structure_needs_at_least_one_member`, 0.
        pub structure_needs_at_least_one_member: u8,
    }
}

ros_struct! {
    /// A `std_srvs/Trigger` response with its header.
    #[derive(Default)]
    pub struct TriggerResponse {
        /// The request answered.
        pub id: RequestId,
        /// Whether the trigger worked.
        pub success: bool,
        /// What happened, e.g. a refusal's reason.
        pub message: String,
    }
}

ros_struct! {
    /// A bare `std_srvs/Trigger` request, as rmw_fastrtps sends it (1 byte).
    #[derive(Default, Copy, Eq)]
    pub struct TriggerRequestBody {
        /// `structure_needs_at_least_one_member`, 0.
        pub structure_needs_at_least_one_member: u8,
    }
}

ros_struct! {
    /// A bare `std_srvs/Trigger` response, as rmw_fastrtps sends it.
    #[derive(Default)]
    pub struct TriggerResponseBody {
        /// Whether the trigger worked.
        pub success: bool,
        /// What happened, e.g. a refusal's reason.
        pub message: String,
    }
}

ros_message! {
    TriggerRequest => "std_srvs::srv::dds_::Trigger_Request_";
    TriggerResponse => "std_srvs::srv::dds_::Trigger_Response_";
    TriggerRequestBody => "std_srvs::srv::dds_::Trigger_Request_";
    TriggerResponseBody => "std_srvs::srv::dds_::Trigger_Response_";
}

/// The header's length before the struct in rmw_cyclonedds' mapping, bytes.
pub const REQUEST_ID_LEN: usize = <RequestId as crate::CdrValue>::MIN_LEN;

/// A `std_srvs/Trigger` message in either mapping, under the one DDS type name of both; decoded
/// by the type's `decode_either`.
macro_rules! either_mapping {
    ($(#[$meta:meta])* $name:ident($with_header:ty, $bare:ty)) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq)]
        pub enum $name {
            /// rmw_cyclonedds': the header, then the struct.
            WithHeader($with_header),
            /// rmw_fastrtps': the struct alone.
            Bare($bare),
        }

        impl robowire_core::cdr::CdrType for $name {
            const TYPE_NAME: &'static str = <$bare as robowire_core::cdr::CdrType>::TYPE_NAME;
            type Error = CdrError;

            fn body_len(&self) -> usize {
                match self {
                    Self::WithHeader(m) => m.body_len(),
                    Self::Bare(m) => m.body_len(),
                }
            }

            fn encode_body(&self, out: &mut [u8]) -> Result<usize, robowire_core::BufferTooSmall> {
                match self {
                    Self::WithHeader(m) => m.encode_body(out),
                    Self::Bare(m) => m.encode_body(out),
                }
            }

            fn decode_body(encoding: CdrEncoding, body: &[u8]) -> Result<Self, CdrError> {
                Self::decode_either(encoding, body)
            }
        }
    };
}

either_mapping!(
    /// A `std_srvs/Trigger` request of either middleware.
    AnyTriggerRequest(TriggerRequest, TriggerRequestBody)
);

impl AnyTriggerRequest {
    /// Told apart by the body's length: longer than [`REQUEST_ID_LEN`] is rmw_cyclonedds' header
    /// and struct (17 bytes and more); else the bare struct (1 byte, at most 8 with padding). A
    /// body of neither shape is an error.
    fn decode_either(encoding: CdrEncoding, body: &[u8]) -> Result<Self, CdrError> {
        if body.len() > REQUEST_ID_LEN {
            TriggerRequest::decode_body(encoding, body).map(Self::WithHeader)
        } else {
            TriggerRequestBody::decode_body(encoding, body).map(Self::Bare)
        }
    }
}

either_mapping!(
    /// A `std_srvs/Trigger` response in either mapping.
    AnyTriggerResponse(TriggerResponse, TriggerResponseBody)
);

impl AnyTriggerResponse {
    /// A response's length does not tell the mappings apart (the message's length varies): a
    /// reader that knows its mapping decodes that mapping's type. This takes the header's shape
    /// when the body decodes as it, else the bare one.
    fn decode_either(encoding: CdrEncoding, body: &[u8]) -> Result<Self, CdrError> {
        TriggerResponse::decode_body(encoding, body)
            .map(Self::WithHeader)
            .or_else(|_| TriggerResponseBody::decode_body(encoding, body).map(Self::Bare))
    }
}
