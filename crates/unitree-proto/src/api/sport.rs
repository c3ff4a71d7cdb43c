/// Service name.
pub const SERVICE: &str = "sport";
/// API version.
pub const API_VERSION: &str = "1.0.0.1";
/// Damp.
pub const DAMP: i64 = 1001;
/// BalanceStand.
pub const BALANCE_STAND: i64 = 1002;
/// StopMove.
pub const STOP_MOVE: i64 = 1003;
/// StandUp.
pub const STAND_UP: i64 = 1004;
/// StandDown (lie down before the sport mode is released).
pub const STAND_DOWN: i64 = 1005;
/// RecoveryStand (stand up from any pose).
pub const RECOVERY_STAND: i64 = 1006;
/// Move: `{"x": vx m/s, "y": vy m/s, "z": yaw rate rad/s}`.
pub const MOVE: i64 = 1008;
