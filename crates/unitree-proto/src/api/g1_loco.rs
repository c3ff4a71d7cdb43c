/// Service name (the same topics as the Go2's `sport`).
pub const SERVICE: &str = "sport";
/// API version.
pub const API_VERSION: &str = "1.0.0.0";
/// GetFsmId: data `{"data": id}`.
pub const GET_FSM_ID: i64 = 7001;
/// GetFsmMode: data `{"data": mode}`.
pub const GET_FSM_MODE: i64 = 7002;
/// GetBalanceMode: data `{"data": mode}`.
pub const GET_BALANCE_MODE: i64 = 7003;
/// GetSwingHeight: data `{"data": m}`.
pub const GET_SWING_HEIGHT: i64 = 7004;
/// GetStandHeight: data `{"data": m}`.
pub const GET_STAND_HEIGHT: i64 = 7005;
/// GetPhase (deprecated by Unitree).
pub const GET_PHASE: i64 = 7006;
/// SetFsmId: parameter `{"data": id}` (see [`fsm`]).
pub const SET_FSM_ID: i64 = 7101;
/// SetBalanceMode: `{"data": 0}` balance stand, `1` continuous gait.
pub const SET_BALANCE_MODE: i64 = 7102;
/// SetSwingHeight: `{"data": m}`.
pub const SET_SWING_HEIGHT: i64 = 7103;
/// SetStandHeight: `{"data": m}`.
pub const SET_STAND_HEIGHT: i64 = 7104;
/// SetVelocity: `{"velocity": [vx m/s, vy m/s, yaw rad/s], "duration": s}`.
pub const SET_VELOCITY: i64 = 7105;
/// SetArmTask: `{"data": task}` (wave hand 0, turning wave 1, shake hand 2 and 3).
pub const SET_ARM_TASK: i64 = 7106;
/// SetSpeedMode: `{"data": mode}`.
pub const SET_SPEED_MODE: i64 = 7107;
/// SwitchToUserCtrl: `{"data": bool}`.
pub const SWITCH_TO_USER_CTRL: i64 = 7110;
/// SwitchToInternalCtrl: `{"data": 0}` last, `1` passive, `2` walk/run.
pub const SWITCH_TO_INTERNAL_CTRL: i64 = 7111;

/// Error codes of the service.
pub mod error {
    /// The locomotion state is not available (no mode selected: after ReleaseMode).
    pub const LOCO_STATE_UNAVAILABLE: i32 = 7301;
    /// An FSM id the controller does not have.
    pub const INVALID_FSM_ID: i32 = 7302;
    /// A task id the controller does not have.
    pub const INVALID_TASK_ID: i32 = 7303;
}

/// FSM ids of `SetFsmId` (Unitree's C++ `LocoClient`).
pub mod fsm {
    /// Zero torque.
    pub const ZERO_TORQUE: i64 = 0;
    /// Damping.
    pub const DAMP: i64 = 1;
    /// Squat.
    pub const SQUAT: i64 = 2;
    /// Sit.
    pub const SIT: i64 = 3;
    /// Stand up (locked standing).
    pub const STAND_UP: i64 = 4;
    /// The walking controller ("Start"); `rt/arm_sdk` is blended in 500, 501 and 801.
    pub const START: i64 = 500;
}
