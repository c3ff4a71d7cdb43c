/// Service name: topics `rt/api/motion_switcher/request` and `/response`.
pub const SERVICE: &str = "motion_switcher";
/// API version.
pub const API_VERSION: &str = "1.0.0.1";
/// CheckMode: parameter `{}`; data `{"form":"0","name":"<mode>"}`, name empty when no sport
/// mode owns the motors.
pub const CHECK_MODE: i64 = 1001;
/// SelectMode: parameter `{"name":"<mode>"}`.
pub const SELECT_MODE: i64 = 1002;
/// ReleaseMode: parameter `{}`.
pub const RELEASE_MODE: i64 = 1003;
/// SetSilent.
pub const SET_SILENT: i64 = 1004;
/// GetSilent.
pub const GET_SILENT: i64 = 1005;

pub use super::mode_name;

/// The CheckMode answer's data for `name` (empty: no sport mode owns the motors).
pub fn check_mode_data(name: &str) -> impl core::fmt::Display + '_ {
    CheckModeData(name)
}

struct CheckModeData<'a>(&'a str);

impl core::fmt::Display for CheckModeData<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, r#"{{"form":"0","name":"{}"}}"#, self.0)
    }
}
