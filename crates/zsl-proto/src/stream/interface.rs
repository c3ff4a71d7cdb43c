//! What differs between the HighLevel and the LowLevel stream: the datagrams and the vendor
//! sender's per-datagram rules (spec §3.1, decision 6).

use crate::codec::{CommandDatagram, StateDatagram};
use crate::rules::ActionClear;
use crate::udp::{HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState};

/// What distinguishes the HighLevel and the LowLevel interface: their datagrams and the vendor
/// sender's per-datagram rules.
pub trait Interface {
    /// The command datagram.
    type Command: CommandDatagram;
    /// The state datagram.
    type State: StateDatagram;
    /// What the rules need to know of the latest state (copied on every state, so small).
    type Observed: Copy + Default;
    /// Per-stream memory of the rules.
    type Memory: Default;

    /// What the rules need of a state.
    fn observe(state: &Self::State) -> Self::Observed;

    /// Applied to the latched command before every datagram; `false` halts the stream for good.
    fn before_send(latched: &mut Self::Command, memory: &mut Self::Memory, state: Option<&Self::Observed>) -> bool;

    /// Replaces a latched motion with a stop (watchdog timeout, spec decision 6).
    fn stop_motion(latched: &mut Self::Command);
}

/// What the HighLevel rules need of a state: its error word and the SDK-mismatch flag.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HighLevelObserved {
    /// The robot reports a non-zero error word.
    pub error: bool,
    /// The robot raised "SDK mismatch".
    pub sdk_mismatch: bool,
}

/// The HighLevel interface: 40-byte commands, 560-byte state.
#[derive(Debug, Clone, Copy, Default)]
pub struct HighLevelInterface;

impl Interface for HighLevelInterface {
    type Command = HighLevelCommand;
    type State = HighLevelState;
    type Observed = HighLevelObserved;
    type Memory = ActionClear;

    fn observe(state: &HighLevelState) -> HighLevelObserved {
        HighLevelObserved { error: state.error().is_some(), sdk_mismatch: state.has_sdk_mismatch() }
    }

    /// The vendor sender's per-cycle rules (spec §3.1): action auto-clear; a non-zero error word
    /// forces mode 0 (passive); the SDK-mismatch flag ends the stream.
    fn before_send(latched: &mut HighLevelCommand, clear: &mut ActionClear, state: Option<&HighLevelObserved>) -> bool {
        clear.before_send(latched);
        if let Some(state) = state {
            if state.error {
                latched.mode = 0.into();
            }
            if state.sdk_mismatch {
                return false;
            }
        }
        true
    }

    /// Every velocity and rate becomes 0; mode and action stay (spec decision 6).
    fn stop_motion(latched: &mut HighLevelCommand) {
        let zero = 0.0.into();
        latched.vx = zero;
        latched.vy = zero;
        latched.roll_rate = zero;
        latched.pitch_rate = zero;
        latched.yaw_rate = zero;
        latched.height_rate = zero;
    }
}

/// The LowLevel interface: 248-byte motor commands, 272-byte state.
#[derive(Debug, Clone, Copy, Default)]
pub struct LowLevelInterface;

impl Interface for LowLevelInterface {
    type Command = LowLevelCommand;
    type State = LowLevelState;
    type Observed = ();
    type Memory = ();

    fn observe(_: &LowLevelState) {}

    fn before_send(_: &mut LowLevelCommand, (): &mut (), _: Option<&()>) -> bool {
        true
    }

    /// Velocity targets become 0: the PD terms hold the last position, no joint is driven on.
    /// Feed-forward torques stay (they may be holding the body up).
    fn stop_motion(latched: &mut LowLevelCommand) {
        latched.motor.qd_des = [[0.0.into(); 4]; 3];
    }
}
