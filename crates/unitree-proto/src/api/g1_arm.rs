/// Service name.
pub const SERVICE: &str = "arm";
/// API version.
pub const API_VERSION: &str = "1.0.0.14";
/// ExecuteAction: `{"data": action}` (Unitree's Python SDK; its C++ SDK names the key
/// `action_id`: the robot is sent both).
pub const EXECUTE_ACTION: i64 = 7106;
/// GetActionList: data the action list.
pub const GET_ACTION_LIST: i64 = 7107;
/// ExecuteCustomAction: `{"action_name": name}`.
pub const EXECUTE_CUSTOM_ACTION: i64 = 7108;
/// StopCustomAction.
pub const STOP_CUSTOM_ACTION: i64 = 7113;
/// The action that releases the arms (ends a holding action).
pub const RELEASE_ARM: i64 = 99;

/// Error codes of the service.
pub mod error {
    /// `rt/arm_sdk` is in use: no action runs meanwhile.
    pub const ARM_SDK_OCCUPIED: i32 = 7400;
    /// The arms hold an action: release them (action 99) first.
    pub const HOLDING: i32 = 7401;
    /// No such action.
    pub const INVALID_ACTION_ID: i32 = 7402;
    /// Actions run only in FSM 500, 501 and 801 (the walking controllers).
    pub const INVALID_FSM_ID: i32 = 7404;
}
