//! The HighLevel call gate (spec §9.1): which call the vendor's client lets through in which
//! state, as one pure function. The client facade, the Python drop-in (through the facade) and
//! any other caller share it: a call, the robot's latest state, the command being streamed and the
//! model in; the datagram to latch, or the refusal with the vendor's return code, out.
//!
//! ```
//! use zsl_proto::gate::{HighLevelCall, Refusal, gate};
//! use zsl_proto::udp::{ControlMode, HighLevelCommand, HighLevelState, Model};
//!
//! let lying = HighLevelState::default(); // mode 0: what the vendor reads before any state
//! let idle = HighLevelCommand::default();
//! let walk = HighLevelCall::Move { vx_mps: 0.5, vy_mps: 0.0, yaw_rate_radps: 0.0 };
//! assert_eq!(gate(walk, &lying, &idle, Model::Zsl1), Err(Refusal::LyingDown(ControlMode::Passive)));
//! assert_eq!(gate(HighLevelCall::StandUp, &lying, &idle, Model::Zsl1), Ok(HighLevelCommand::stand_up()));
//! ```

use crate::rules::{
    ATTITUDE_RANGES, ArgumentError, TWO_LEG_STAND_RANGES, check_all, is_running, mode_gate_passes, move_ranges,
};
use crate::udp::{Action, ControlMode, HighLevelCommand, HighLevelState, Model, ReturnCode};

/// A HighLevel call with its arguments (m/s, rad/s), as the vendor's client names them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HighLevelCall {
    /// `standUp()`: mode 1.
    StandUp,
    /// `lieDown()`: mode 51.
    LieDown,
    /// `passive()`: mode 0.
    Passive,
    /// `move(vx, vy, yaw_rate)`: mode 18.
    Move {
        /// Forward, m/s.
        vx_mps: f32,
        /// Left, m/s.
        vy_mps: f32,
        /// Yaw rate, rad/s.
        yaw_rate_radps: f32,
    },
    /// `jump()`.
    Jump,
    /// `frontJump()`.
    FrontJump,
    /// `backflip()`.
    Backflip,
    /// `shakeHand()`.
    ShakeHand,
    /// `twoLegStand(vx, yaw_rate)`.
    TwoLegStand {
        /// Forward, m/s.
        vx_mps: f32,
        /// Yaw rate, rad/s.
        yaw_rate_radps: f32,
    },
    /// `cancelTwoLegStand()`: no checks.
    CancelTwoLegStand,
    /// `attitudeControl(roll, pitch, yaw, height)` rates (rad/s, rad/s, rad/s, m/s).
    Attitude {
        /// Roll rate, rad/s.
        roll_radps: f32,
        /// Pitch rate, rad/s.
        pitch_radps: f32,
        /// Yaw rate, rad/s.
        yaw_radps: f32,
        /// Height rate, m/s.
        height_mps: f32,
    },
    /// ZSL-1W `crawl(vx, vy, yaw_rate)`.
    Crawl {
        /// Forward, m/s.
        vx_mps: f32,
        /// Left, m/s.
        vy_mps: f32,
        /// Yaw rate, rad/s.
        yaw_rate_radps: f32,
    },
    /// ZSL-1W `climb(vx, vy, yaw_rate)`.
    Climb {
        /// Forward, m/s.
        vx_mps: f32,
        /// Left, m/s.
        vy_mps: f32,
        /// Yaw rate, rad/s.
        yaw_rate_radps: f32,
    },
    /// ZSL-1W `cancelCrawl()` / `cancelClimb()` (one datagram): no checks.
    CancelCrawlOrClimb,
}

/// When the "robot is running" check refuses a call (spec §9.1 step 4).
#[derive(Clone, Copy)]
enum WhileRunning {
    Allowed,
    RefusedInMode18Or21,
    Refused,
    RefusedUnlessMode21,
}

/// Why the gate refused a call. Nothing is latched or sent.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Refusal {
    /// The robot reports a non-zero error word (self-check failed).
    #[error("the robot reports error {0:?} (self-check failed)")]
    SelfCheck(ReturnCode),
    /// The robot is lying down (mode 0, 10 or 51); it must stand first.
    #[error("refused in mode {0:?}: the robot must stand first")]
    LyingDown(ControlMode),
    /// `move` while a two-leg stand is active; cancel it first.
    #[error("move refused during a two-leg stand (cancel it first)")]
    TwoLegStandActive,
    /// The robot is moving (|vx|, |vy| or |yaw rate| above 0.2).
    #[error("refused while the robot is moving (|vx|, |vy| or |yaw rate| > 0.2) in mode {0:?}")]
    Running(ControlMode),
    /// `attitudeControl` with |roll| above 1.0 rad.
    #[error("attitude refused: |roll| = {0} rad is above 1.0 rad")]
    Unbalanced(f32),
    /// An argument is NaN, infinite or out of range.
    #[error(transparent)]
    Argument(#[from] ArgumentError),
    /// The call is not in this model's API (ZSL-1W `crawl`/`climb` on a ZSL-1).
    #[error("{call} is a {needs:?} call; the robot is a {model:?}")]
    WrongModel {
        /// The call.
        call: &'static str,
        /// The model that has it.
        needs: Model,
        /// The robot's model.
        model: Model,
    },
}

impl Refusal {
    /// The vendor's return code for this refusal.
    pub fn return_code(&self) -> ReturnCode {
        match self {
            Self::SelfCheck(word) => *word,
            Self::Argument(e) => e.return_code(),
            Self::LyingDown(_)
            | Self::TwoLegStandActive
            | Self::Running(_)
            | Self::Unbalanced(_)
            | Self::WrongModel { .. } => ReturnCode::SwitchFailed,
        }
    }
}

impl HighLevelCall {
    /// Calls that keep an acknowledgement counter (spec §9.1 step 7), one slot each.
    pub const ACKNOWLEDGED: usize = 12;

    /// The call's acknowledgement counter, if it keeps one (the cancels do not).
    pub fn ack_slot(&self) -> Option<usize> {
        Some(match self {
            Self::StandUp => 0,
            Self::LieDown => 1,
            Self::Passive => 2,
            Self::Move { .. } => 3,
            Self::Jump => 4,
            Self::FrontJump => 5,
            Self::Backflip => 6,
            Self::ShakeHand => 7,
            Self::TwoLegStand { .. } => 8,
            Self::Attitude { .. } => 9,
            Self::Crawl { .. } => 10,
            Self::Climb { .. } => 11,
            Self::CancelTwoLegStand | Self::CancelCrawlOrClimb => return None,
        })
    }

    /// The vendor's name of the call.
    pub fn name(&self) -> &'static str {
        match self {
            Self::StandUp => "standUp",
            Self::LieDown => "lieDown",
            Self::Passive => "passive",
            Self::Move { .. } => "move",
            Self::Jump => "jump",
            Self::FrontJump => "frontJump",
            Self::Backflip => "backflip",
            Self::ShakeHand => "shakeHand",
            Self::TwoLegStand { .. } => "twoLegStand",
            Self::CancelTwoLegStand => "cancelTwoLegStand",
            Self::Attitude { .. } => "attitudeControl",
            Self::Crawl { .. } => "crawl",
            Self::Climb { .. } => "climb",
            Self::CancelCrawlOrClimb => "cancelCrawl",
        }
    }

    /// The ZSL-1W-only calls.
    fn needs(&self) -> Option<Model> {
        matches!(self, Self::Crawl { .. } | Self::Climb { .. } | Self::CancelCrawlOrClimb).then_some(Model::Zsl1W)
    }

    /// `None` for the calls without checks; else whether the mode gate applies and when a
    /// running robot refuses it.
    fn checks(&self) -> Option<(bool, WhileRunning)> {
        use WhileRunning::*;
        Some(match self {
            Self::StandUp | Self::LieDown => (false, RefusedInMode18Or21),
            Self::Passive => (false, Allowed),
            Self::ShakeHand => (false, Refused),
            Self::Jump | Self::FrontJump | Self::Backflip => (true, Refused),
            Self::TwoLegStand { .. } | Self::Attitude { .. } => (true, RefusedUnlessMode21),
            Self::Move { .. } | Self::Crawl { .. } | Self::Climb { .. } => (true, Allowed),
            Self::CancelTwoLegStand | Self::CancelCrawlOrClimb => return None,
        })
    }

    /// The call's datagram, its arguments checked against `model`'s ranges.
    fn command(&self, model: Model) -> Result<HighLevelCommand, ArgumentError> {
        Ok(match *self {
            Self::StandUp => HighLevelCommand::stand_up(),
            Self::LieDown => HighLevelCommand::lie_down(),
            Self::Passive => HighLevelCommand::passive(),
            Self::Move { vx_mps, vy_mps, yaw_rate_radps } => {
                let [vx, vy, wz] = check_all(&move_ranges(model), [vx_mps, vy_mps, yaw_rate_radps])?;
                HighLevelCommand::move_velocity(vx, vy, wz)
            }
            Self::Jump => HighLevelCommand::jump(),
            Self::FrontJump => HighLevelCommand::front_jump(),
            Self::Backflip => HighLevelCommand::backflip(),
            Self::ShakeHand => HighLevelCommand::shake_hand(),
            Self::TwoLegStand { vx_mps, yaw_rate_radps } => {
                let [vx, wz] = check_all(&TWO_LEG_STAND_RANGES, [vx_mps, yaw_rate_radps])?;
                HighLevelCommand::two_leg_stand(vx, wz)
            }
            Self::CancelTwoLegStand => HighLevelCommand::cancel_two_leg_stand(),
            Self::Attitude { roll_radps, pitch_radps, yaw_radps, height_mps } => {
                let [r, p, y, h] = check_all(&ATTITUDE_RANGES, [roll_radps, pitch_radps, yaw_radps, height_mps])?;
                HighLevelCommand::attitude(r, p, y, h)
            }
            Self::Crawl { vx_mps, vy_mps, yaw_rate_radps } => {
                let [vx, vy, wz] = check_all(&move_ranges(model), [vx_mps, vy_mps, yaw_rate_radps])?;
                HighLevelCommand::crawl(vx, vy, wz)
            }
            Self::Climb { vx_mps, vy_mps, yaw_rate_radps } => {
                let [vx, vy, wz] = check_all(&move_ranges(model), [vx_mps, vy_mps, yaw_rate_radps])?;
                HighLevelCommand::climb(vx, vy, wz)
            }
            Self::CancelCrawlOrClimb => HighLevelCommand::cancel_crawl_or_climb(),
        })
    }
}

/// The vendor client's checks for `call` (spec §9.1, in its order), then the datagram to latch.
/// `state` is the robot's latest state (all zeros before the first, as the vendor reads it);
/// `latched` the command being streamed; `model` the robot's.
pub fn gate(
    call: HighLevelCall,
    state: &HighLevelState,
    latched: &HighLevelCommand,
    model: Model,
) -> Result<HighLevelCommand, Refusal> {
    if let Some(needs) = call.needs()
        && needs != model
    {
        return Err(Refusal::WrongModel { call: call.name(), needs, model });
    }
    let Some((gated, while_running)) = call.checks() else {
        return Ok(call.command(model)?);
    };
    if let Some(error) = state.error() {
        return Err(Refusal::SelfCheck(error));
    }
    let mode = state.mode();
    if gated && !mode_gate_passes(mode) {
        return Err(Refusal::LyingDown(mode));
    }
    if matches!(call, HighLevelCall::Move { .. }) && latched.action_code() == Action::TwoLegStand {
        return Err(Refusal::TwoLegStandActive);
    }
    let running = is_running(state.body_velocity[0].get(), state.body_velocity[1].get(), state.gyro[2].get());
    let refused = match while_running {
        WhileRunning::Allowed => false,
        WhileRunning::RefusedInMode18Or21 => matches!(mode, ControlMode::Move | ControlMode::Action),
        WhileRunning::Refused => true,
        WhileRunning::RefusedUnlessMode21 => mode != ControlMode::Action,
    };
    if running && refused {
        return Err(Refusal::Running(mode));
    }
    if matches!(call, HighLevelCall::Attitude { .. }) && state.rpy[0].get().abs() > 1.0 {
        return Err(Refusal::Unbalanced(state.rpy[0].get()));
    }
    Ok(call.command(model)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(mode: u32, vx: f32, roll: f32) -> HighLevelState {
        let mut s = HighLevelState { control_mode: mode.into(), ..HighLevelState::default() };
        s.body_velocity[0] = vx.into();
        s.rpy[0] = roll.into();
        s
    }

    const WALK: HighLevelCall = HighLevelCall::Move { vx_mps: 0.5, vy_mps: 0.0, yaw_rate_radps: 0.0 };

    #[test]
    fn the_vendors_order_of_checks() {
        let idle = HighLevelCommand::default();
        let standing = state(1, 0.0, 0.0);
        assert_eq!(gate(WALK, &standing, &idle, Model::Zsl1), Ok(HighLevelCommand::move_velocity(0.5, 0.0, 0.0)));
        assert_eq!(gate(WALK, &state(51, 0.0, 0.0), &idle, Model::Zsl1), Err(Refusal::LyingDown(ControlMode::LieDown)));
        let two_legs = HighLevelCommand::two_leg_stand(0.3, 0.0);
        assert_eq!(gate(WALK, &standing, &two_legs, Model::Zsl1), Err(Refusal::TwoLegStandActive));
        let moving = state(18, 0.5, 0.0);
        assert_eq!(gate(HighLevelCall::StandUp, &moving, &idle, Model::Zsl1), Err(Refusal::Running(ControlMode::Move)));
        assert_eq!(gate(HighLevelCall::Jump, &moving, &idle, Model::Zsl1), Err(Refusal::Running(ControlMode::Move)));
        assert!(gate(HighLevelCall::Passive, &moving, &idle, Model::Zsl1).is_ok());
        let tilted = state(21, 0.0, 1.2);
        let attitude = HighLevelCall::Attitude { roll_radps: 0.1, pitch_radps: 0.0, yaw_radps: 0.0, height_mps: 0.0 };
        assert_eq!(gate(attitude, &tilted, &idle, Model::Zsl1), Err(Refusal::Unbalanced(1.2)));
        let fast = HighLevelCall::Move { vx_mps: 3.5, vy_mps: 0.0, yaw_rate_radps: 0.0 };
        let refused = gate(fast, &standing, &idle, Model::Zsl1).unwrap_err();
        assert_eq!(refused.return_code(), ReturnCode::SpeedTooLarge);
        assert!(gate(fast, &standing, &idle, Model::Zsl1W).is_ok(), "ZSL-1W walks up to 3.7 m/s");
    }

    #[test]
    fn the_error_word_refuses_all_but_the_cancels_and_the_model_comes_first() {
        let mut faulty = state(1, 0.0, 0.0);
        faulty.error_word = ReturnCode::SwitchFailed.raw().into();
        let idle = HighLevelCommand::default();
        assert!(matches!(gate(HighLevelCall::Passive, &faulty, &idle, Model::Zsl1), Err(Refusal::SelfCheck(_))));
        assert!(gate(HighLevelCall::CancelTwoLegStand, &faulty, &idle, Model::Zsl1).is_ok());
        let crawl = HighLevelCall::Crawl { vx_mps: 0.5, vy_mps: 0.0, yaw_rate_radps: 0.0 };
        assert_eq!(
            gate(crawl, &faulty, &idle, Model::Zsl1),
            Err(Refusal::WrongModel { call: "crawl", needs: Model::Zsl1W, model: Model::Zsl1 })
        );
        let nan = HighLevelCall::Move { vx_mps: f32::NAN, vy_mps: 0.0, yaw_rate_radps: 0.0 };
        assert!(matches!(gate(nan, &state(1, 0.0, 0.0), &idle, Model::Zsl1), Err(Refusal::Argument(_))));
    }
}
