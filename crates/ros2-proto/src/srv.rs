//! Services: rmw_cyclonedds' request header and `std_srvs/Trigger`.
//!
//! rmw_cyclonedds writes every request and reply sample as `cdds_request_header_t { uint64 guid;
//! int64 seq; }` followed by the request or response struct, in one XCDR1 body. The client sets
//! `guid` to an id of its own (its request writer's instance handle) and counts `seq` up from 1;
//! the service copies both into the reply, and a client takes only replies with its `guid`.

use alloc::string::String;

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

ros_message! {
    TriggerRequest => "std_srvs::srv::dds_::Trigger_Request_";
    TriggerResponse => "std_srvs::srv::dds_::Trigger_Response_";
}
