//! The `rt/arm_sdk` stream, sans-IO: the latched arm command sent every
//! [`ARM_SDK_PERIOD`] (20 ms) on absolute deadlines, its weight
//! (slot 29's `q`) moved toward the command's target by at most `weight_rate_per_s` × period per
//! frame ([`WeightRamp`]): blended in and out, never switched.
//!
//! - A command older than `command_timeout` is stale: the weight ramps to 0 (the robot's own
//!   controller takes the arms back) with the last targets.
//! - Once the weight is 0 with a target of 0, that frame is the last: the stream goes idle and
//!   leaves `rt/arm_sdk` free (the arm action service refuses to run while it is in use). The
//!   next command starts it again.
//! - [`close`](ArmSdkStream::close) ramps the weight to 0 at least at
//!   [`ARM_SDK_CLOSE_RATE_PER_S`] (from weight 1: at most 2 s), sends that frame, and is done.
//!
//! ```
//! use core::time::Duration;
//! use unitree_proto::g1::arm_stream::{ArmSdkConfig, ArmSdkStream};
//! use unitree_proto::HgLowCmd;
//! use unitree_proto::g1::slot;
//! use robowire_core::schedule::Time;
//!
//! let t0 = Time::from_nanos(1_000_000_000);
//! let mut stream = ArmSdkStream::new(ArmSdkConfig::default());
//! let mut arms = HgLowCmd::default();
//! arms.motor_cmd[slot::ARM_SDK_WEIGHT].q = 1.0.into(); // the target weight
//! stream.handle_command(t0, arms);
//! let first = stream.poll_transmit(t0).unwrap();
//! assert_eq!(first.weight, 0.01, "0.5/s × 20 ms: blended in, not switched");
//! ```

use core::time::Duration;

use crate::HgLowCmd;
use crate::g1::{ARM_SDK_PERIOD, ARM_SDK_WEIGHT_RATE_PER_S, WeightRamp, slot};
use robowire_core::schedule::{Periodic, Tick, Time};

/// A stale arm command: no update for this long (25 periods at 50 Hz) and the weight ramps to 0.
pub const ARM_SDK_COMMAND_TIMEOUT: Duration = Duration::from_millis(500);

/// The slowest rate at which closing ramps the weight to 0, per second: closing from weight 1
/// takes at most 2 s (plus a period).
pub const ARM_SDK_CLOSE_RATE_PER_S: f32 = 0.5;

/// The fastest weight rate robowire accepts in its options, per second (0 → 1 in 0.2 s).
pub const ARM_SDK_WEIGHT_RATE_MAX_PER_S: f32 = 5.0;

/// The stream's timing and ramp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmSdkConfig {
    /// Frame period. Default [`ARM_SDK_PERIOD`] (20 ms, Unitree's arm examples).
    pub period: Duration,
    /// A command older than this is stale and ramped out. Default [`ARM_SDK_COMMAND_TIMEOUT`].
    pub command_timeout: Duration,
    /// Largest change of the weight per second (per frame: this × period). Default
    /// [`ARM_SDK_WEIGHT_RATE_PER_S`] (0.5/s: 0 → 1 in 2 s).
    pub weight_rate_per_s: f32,
}

impl Default for ArmSdkConfig {
    fn default() -> Self {
        Self {
            period: ARM_SDK_PERIOD,
            command_timeout: ARM_SDK_COMMAND_TIMEOUT,
            weight_rate_per_s: ARM_SDK_WEIGHT_RATE_PER_S,
        }
    }
}

/// A frame to send now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmTransmit {
    /// The latched command with the weight of this frame in slot 29.
    pub command: HgLowCmd,
    /// The weight sent, 0..=1.
    pub weight: f32,
    /// Whether this is the last frame before the stream goes idle (weight 0, target 0).
    pub last: bool,
    /// The tick it is sent for.
    pub tick: Tick,
}

/// What the stream has done.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ArmSdkCounters {
    /// Frames sent.
    pub sent: u64,
    /// Times a command went stale (and its weight was ramped out).
    pub command_timeouts: u64,
    /// Slots skipped because a tick was served more than a period late.
    pub missed_ticks: u64,
}

/// The stream; see the [module](self).
#[derive(Debug, Clone)]
pub struct ArmSdkStream {
    config: ArmSdkConfig,
    /// Runs while frames are due; `None` when idle.
    grid: Option<Periodic>,
    /// The command and when it was set; slot 29's `q` is the target weight.
    latched: Option<(Time, HgLowCmd)>,
    ramp: WeightRamp,
    was_fresh: bool,
    closing: bool,
    done: bool,
    counters: ArmSdkCounters,
}

impl ArmSdkStream {
    /// An idle stream at weight 0.
    pub fn new(config: ArmSdkConfig) -> Self {
        Self {
            config,
            grid: None,
            latched: None,
            ramp: WeightRamp::new(config.weight_rate_per_s),
            was_fresh: false,
            closing: false,
            done: false,
            counters: ArmSdkCounters::default(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &ArmSdkConfig {
        &self.config
    }

    /// Latches `command` (checked by the caller; slot 29's `q` is the target weight, 0..=1), set
    /// at `set_at`. An idle stream starts at `set_at`. Ignored once closing.
    pub fn handle_command(&mut self, set_at: Time, command: HgLowCmd) {
        if self.closing {
            return;
        }
        self.grid.get_or_insert_with(|| Periodic::new(set_at, self.config.period));
        self.latched = Some((set_at, command));
    }

    /// Ramps the weight to 0 (at least at [`ARM_SDK_CLOSE_RATE_PER_S`]) and ends with that frame;
    /// an idle stream is done at once.
    pub fn close(&mut self) {
        self.closing = true;
        self.done |= self.grid.is_none();
    }

    /// Whether closing has finished: the last frame (weight 0) is sent, or nothing was due.
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Whether the latched command is fresh at `now` (set within the command timeout, or after
    /// `now`), and the stream is not closing.
    pub fn is_fresh(&self, now: Time) -> bool {
        !self.closing
            && self
                .latched
                .as_ref()
                .is_some_and(|(at, _)| now.saturating_duration_since(*at) <= self.config.command_timeout)
    }

    /// The weight of the last frame.
    pub fn weight(&self) -> f32 {
        self.ramp.weight()
    }

    /// When to call [`poll_transmit`](Self::poll_transmit) next; `None` when idle.
    pub fn poll_timeout(&self) -> Option<Time> {
        self.grid.as_ref().map(Periodic::deadline)
    }

    /// The frame due at `now`, if one is.
    pub fn poll_transmit(&mut self, now: Time) -> Option<ArmTransmit> {
        let tick = self.grid.as_mut()?.poll(now)?;
        let (_, latched) = self.latched?;
        self.counters.missed_ticks += tick.skipped;
        let fresh = self.is_fresh(now);
        if self.was_fresh && !fresh && !self.closing {
            self.counters.command_timeouts += 1;
        }
        self.was_fresh = fresh;
        let target = if fresh { latched.motor_cmd[slot::ARM_SDK_WEIGHT].q.get() } else { 0.0 };
        self.ramp.set_target(target);
        // One frame's step, however late the frame: the weight never jumps.
        let mut dt_s = self.config.period.as_secs_f32();
        if self.closing {
            dt_s *= (ARM_SDK_CLOSE_RATE_PER_S / self.config.weight_rate_per_s).max(1.0);
        }
        let weight = self.ramp.step(dt_s);
        let last = weight == 0.0 && self.ramp.target() == 0.0;
        if last {
            self.grid = None;
            self.done = self.closing;
        }
        let mut command = latched;
        command.motor_cmd[slot::ARM_SDK_WEIGHT].q = weight.into();
        self.counters.sent += 1;
        Some(ArmTransmit { command, weight, last, tick })
    }

    /// What the stream has done.
    pub fn counters(&self) -> ArmSdkCounters {
        self.counters
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T0: Time = Time::from_nanos(1_000_000_000);
    const PERIOD: Duration = ARM_SDK_PERIOD;

    fn arms(weight: f32) -> HgLowCmd {
        let mut cmd = HgLowCmd::default();
        cmd.motor_cmd[slot::LEFT_ELBOW].q = 0.5.into();
        cmd.motor_cmd[slot::LEFT_ELBOW].kp = 60.0.into();
        cmd.motor_cmd[slot::ARM_SDK_WEIGHT].q = weight.into();
        cmd
    }

    /// Serves every tick from `from` for `frames` periods; the weights sent.
    fn run(stream: &mut ArmSdkStream, from: Time, frames: u32, refresh: bool) -> Vec<f32> {
        let mut weights = Vec::new();
        for i in 0..frames {
            let now = from + PERIOD * i;
            if refresh {
                stream.handle_command(now, arms(1.0));
            }
            if let Some(t) = stream.poll_transmit(now) {
                assert_eq!(t.command.motor_cmd[slot::LEFT_ELBOW].q.get(), 0.5, "the targets go out as set");
                weights.push(t.weight);
            }
        }
        weights
    }

    fn assert_no_jump(weights: &[f32], rate_per_s: f32) {
        let step = rate_per_s * PERIOD.as_secs_f32() + 1e-6;
        for pair in weights.windows(2) {
            assert!((pair[1] - pair[0]).abs() <= step, "a jump {pair:?} (at most {step} per frame)");
        }
    }

    #[test]
    fn the_weight_ramps_up_at_the_rate_and_holds() {
        let mut stream = ArmSdkStream::new(ArmSdkConfig::default());
        assert_eq!(stream.poll_timeout(), None, "idle before the first command");
        let weights = run(&mut stream, T0, 150, true);
        assert_eq!(weights.len(), 150);
        assert_eq!(weights[0], 0.01);
        assert!((weights[49] - 0.5).abs() < 1e-5, "0.5 after 1 s: {}", weights[49]);
        assert!((weights[99] - 1.0).abs() < 1e-5, "1 after 2 s (100 steps of 0.01 in f32): {}", weights[99]);
        assert!(weights[101..].iter().all(|&w| w == 1.0));
        assert_no_jump(&weights, ARM_SDK_WEIGHT_RATE_PER_S);
        assert_eq!(stream.counters().command_timeouts, 0);
    }

    #[test]
    fn a_stale_command_ramps_out_then_the_stream_goes_idle() {
        let mut stream = ArmSdkStream::new(ArmSdkConfig::default());
        let up = run(&mut stream, T0, 120, true);
        let last_set = T0 + PERIOD * 119;
        // No more updates: fresh for the timeout (25 frames), then 2 s of ramp to 0.
        let down = run(&mut stream, last_set + PERIOD, 200, false);
        assert!(down[..25].iter().all(|&w| w == 1.0), "held while fresh (500 ms: 25 frames)");
        assert!(down[25] < 1.0, "then ramped out");
        assert_eq!(*down.last().unwrap(), 0.0, "the last frame has weight 0");
        let ramp = down.len() - 25;
        assert!((100..=101).contains(&ramp), "steps of 0.01 down to 0 (f32 rounding: one more), then idle: {ramp}");
        assert_no_jump(&[up, down].concat(), ARM_SDK_WEIGHT_RATE_PER_S);
        assert_eq!(stream.poll_timeout(), None, "idle: rt/arm_sdk is free");
        assert_eq!(stream.counters().command_timeouts, 1);
        // A new command blends in again from 0.
        let again = run(&mut stream, last_set + Duration::from_secs(10), 3, true);
        assert_eq!(again, [0.01, 0.02, 0.03]);
    }

    #[test]
    fn a_lowered_target_ramps_down_and_late_ticks_do_not_jump() {
        let mut stream = ArmSdkStream::new(ArmSdkConfig::default());
        let mut weights = run(&mut stream, T0, 110, true);
        let t = T0 + PERIOD * 110;
        stream.handle_command(t, arms(0.5));
        // Served 5 periods late: the skipped slots are counted, the weight moves one step.
        let late = stream.poll_transmit(t + PERIOD * 5).unwrap();
        assert_eq!(late.tick.skipped, 5);
        weights.push(late.weight);
        for i in 6..80 {
            let now = t + PERIOD * i;
            stream.handle_command(now, arms(0.5));
            weights.extend(stream.poll_transmit(now).map(|f| f.weight));
        }
        assert_eq!(*weights.last().unwrap(), 0.5);
        assert_no_jump(&weights, ARM_SDK_WEIGHT_RATE_PER_S);
        assert_eq!(stream.counters().missed_ticks, 5);
    }

    #[test]
    fn closing_ramps_down_within_its_bound_and_ends_on_weight_zero() {
        // A slow ramp (0.1/s) is closed at the close rate (0.5/s): at most 2 s from weight 1.
        let config = ArmSdkConfig { weight_rate_per_s: 0.1, ..ArmSdkConfig::default() };
        let mut stream = ArmSdkStream::new(config);
        let up = run(&mut stream, T0, 600, true);
        assert_eq!(*up.last().unwrap(), 1.0);
        stream.close();
        assert!(!stream.is_done());
        stream.handle_command(T0 + PERIOD * 600, arms(1.0)); // ignored once closing
        let down = run(&mut stream, T0 + PERIOD * 600, 200, false);
        assert!((100..=101).contains(&down.len()), "2 s at 0.5/s: {} frames", down.len());
        assert_eq!(*down.last().unwrap(), 0.0);
        assert_no_jump(&down, ARM_SDK_CLOSE_RATE_PER_S);
        assert!(stream.is_done() && stream.poll_timeout().is_none());

        let mut idle = ArmSdkStream::new(ArmSdkConfig::default());
        idle.close();
        assert!(idle.is_done(), "nothing was sent: nothing to ramp");
    }
}
