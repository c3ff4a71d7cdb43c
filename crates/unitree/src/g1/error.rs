//! Why the G1 client could not start, take a command, or get a service to act.

use crate::UnitreeError;
use unitree_proto::robot::CommandError;

/// Why something failed. "The robot said no" (a refusal code, typed where Unitree documents it),
/// "the arguments were bad" (nothing sent) and "the link failed" ([`G1Error::LowLevel`]) are kept
/// apart.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum G1Error {
    /// A command the G1's rules refuse (`unitree_proto::g1::check_low_cmd` / `check_arm_sdk`:
    /// no LowState yet, a `mode_machine` not the robot's, a joint out of range, …); nothing was
    /// sent, the previous command stays.
    #[error(transparent)]
    Command(#[from] CommandError),
    /// The low-level client: DDS, threads, options, a service that does not answer or answers an
    /// undocumented code, a release that did not let go ([`UnitreeError::NotReleased`]).
    #[error(transparent)]
    LowLevel(UnitreeError),
    /// An argument outside robowire's documented bounds (or not finite); nothing was sent.
    #[error("{name} = {value} is outside {min}..={max} (robowire's bound)")]
    Argument {
        /// The argument, with its unit.
        name: &'static str,
        /// Its value.
        value: f64,
        /// Lowest accepted.
        min: f64,
        /// Highest accepted.
        max: f64,
    },
    /// The locomotion service answered 7301 (LocoState not available): high-level control is off
    /// after ReleaseMode, until a mode is selected again ([`G1::select_mode`](crate::g1::G1::select_mode)).
    #[error(
        "sport api {api_id}: the locomotion controller is off (code 7301): high-level control stays off \
         after ReleaseMode until a mode is selected again (G1::select_mode)"
    )]
    LocoStateUnavailable {
        /// The API called.
        api_id: i64,
    },
    /// The locomotion service has no such FSM id (code 7302).
    #[error("the locomotion controller has no FSM id {fsm} (code 7302)")]
    InvalidFsmId {
        /// The id sent.
        fsm: i64,
    },
    /// The locomotion service has no such arm task (code 7303).
    #[error("the locomotion controller has no arm task {task} (code 7303)")]
    InvalidTaskId {
        /// The id sent.
        task: i64,
    },
    /// The arm service refused: `rt/arm_sdk` is in use (code 7400). Ramp the arm stream's weight
    /// to 0 (`set_arm_weight(0.0)`) and let it go idle first.
    #[error("arm action {action} refused (code 7400): rt/arm_sdk is in use; ramp its weight to 0 first")]
    ArmSdkOccupied {
        /// The action sent.
        action: i64,
    },
    /// The arm service refused: the arms hold an action (code 7401). Release them
    /// ([`ArmActions::release_arm`](crate::g1::ArmActions::release_arm), action 99) or send the
    /// held action again.
    #[error("arm action {action} refused (code 7401): the arms hold an action; release them (action 99) first")]
    ArmHolding {
        /// The action sent.
        action: i64,
    },
    /// The arm service has no such action (code 7402).
    #[error("the arm service has no action {action} (code 7402)")]
    InvalidActionId {
        /// The action sent.
        action: i64,
    },
    /// The arm service refused: actions run only in the walking controllers, FSM 500, 501 and
    /// 801 (code 7404).
    #[error("arm action {action} refused (code 7404): actions run only in FSM 500, 501 and 801 (Loco::start)")]
    ArmFsm {
        /// The action sent.
        action: i64,
    },
    /// [`set_arm_weight`](crate::g1::G1::set_arm_weight) before any
    /// [`set_arm_joints`](crate::g1::G1::set_arm_joints): there are no arm targets to blend in.
    #[error("no arm targets yet: set_arm_joints before set_arm_weight")]
    NoArmTargets,
}

impl From<UnitreeError> for G1Error {
    /// A command refusal stays a [`G1Error::Command`]; anything else is [`G1Error::LowLevel`].
    fn from(e: UnitreeError) -> Self {
        match e {
            UnitreeError::Command(e) => Self::Command(e),
            e => Self::LowLevel(e),
        }
    }
}

impl From<robowire_dds::DdsError> for G1Error {
    fn from(e: robowire_dds::DdsError) -> Self {
        Self::LowLevel(UnitreeError::Dds(e))
    }
}

impl From<robowire_rt::RtError> for G1Error {
    fn from(e: robowire_rt::RtError) -> Self {
        Self::LowLevel(UnitreeError::Thread(e))
    }
}

/// `Ok(value)` if `value` is finite and within `min..=max`, else [`G1Error::Argument`].
pub(crate) fn within(name: &'static str, value: f32, min: f32, max: f32) -> Result<f32, G1Error> {
    if value.is_finite() && (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(G1Error::Argument { name, value: f64::from(value), min: f64::from(min), max: f64::from(max) })
    }
}
