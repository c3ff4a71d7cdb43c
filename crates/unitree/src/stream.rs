//! The stream thread's job: `unitree-proto`'s sans-IO [`CommandStream`] on robowire's runner,
//! writing through `robowire-dds`. Commands arrive through a seqlock, motions through a
//! one-place queue (and leave through another, to be dropped by the caller), damping requests
//! through an atomic; statistics and where a motion is leave as atomics. The stream thread never
//! waits on the caller, and allocates and frees nothing.

use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use crossbeam_queue::ArrayQueue;
use robowire_dds::Writer;
use robowire_rt::runner::Job;
use robowire_rt::stats::{Counter, SharedLateness, micros};
use robowire_rt::{Latest, Time};
use unitree_proto::robot::{CommandError, Robot};
use unitree_proto::stream::{CommandStream, Motion, MotionState};

/// Damping frames written when the client closes.
pub(crate) const CLOSING_DAMPING_FRAMES: usize = 3;

/// Motions the stream thread has let go and the caller has not dropped yet, at most. The stream
/// takes a new motion only when it can put the one it replaces here; `follow` empties it before
/// it hands a motion over, so that it holds two between two calls (one caller), a few more
/// with callers on several threads.
const RETIRED_MOTIONS: usize = 4;

/// What the stream thread shares with the client.
pub(crate) struct StreamShared<R: Robot> {
    /// The latest command and when it was set (validated by the client).
    pub(crate) commands: Latest<R::Cmd>,
    /// The motion handed over last and when, until the stream takes it (a newer one displaces
    /// it back to the caller).
    pub(crate) motions: ArrayQueue<(Time, Handed<R::Cmd>)>,
    /// Motions the stream let go, for the caller to drop.
    pub(crate) retired: ArrayQueue<Handed<R::Cmd>>,
    /// When damping was last requested, ns on the monotonic clock (0: never).
    pub(crate) damp_at: AtomicU64,
    pub(crate) lateness: SharedLateness<4096>,
    pub(crate) sent: Counter,
    pub(crate) damping: Counter,
    pub(crate) command_timeouts: Counter,
    pub(crate) missed_ticks: Counter,
    pub(crate) write_errors: Counter,
}

impl<R: Robot> Default for StreamShared<R> {
    fn default() -> Self {
        Self {
            commands: Latest::new(),
            motions: ArrayQueue::new(1),
            retired: ArrayQueue::new(RETIRED_MOTIONS),
            damp_at: AtomicU64::new(0),
            lateness: SharedLateness::new(),
            sent: Counter::default(),
            damping: Counter::default(),
            command_timeouts: Counter::default(),
            missed_ticks: Counter::default(),
            write_errors: Counter::default(),
        }
    }
}

/// A motion as the stream holds it: the caller's (boxed on the caller's thread) and the status
/// its [`Following`](crate::Following) handles read.
pub(crate) struct Handed<C> {
    pub(crate) motion: Box<dyn Motion<C> + Send>,
    pub(crate) status: Arc<MotionStatus>,
}

impl<C> Motion<C> for Handed<C> {
    fn command_at(&self, elapsed: Duration) -> Result<C, CommandError> {
        self.motion.command_at(elapsed)
    }

    fn duration(&self) -> Duration {
        self.motion.duration()
    }
}

impl<C> std::fmt::Debug for Handed<C> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Handed").field("duration", &self.motion.duration()).finish_non_exhaustive()
    }
}

/// [`MotionState`] as atomics: written by the stream thread, read by anyone.
#[derive(Debug, Default)]
pub(crate) struct MotionStatus {
    /// Which [`MotionState`] (`PENDING` …).
    state: AtomicU8,
    /// Of `Moving`, ns.
    elapsed_ns: AtomicU64,
    /// The slot of the first step, ns on the monotonic clock (0: not yet).
    began_ns: AtomicU64,
    /// Of `Refused`: set once, before the state says so (a `OnceLock` only this thread sets
    /// never waits).
    refusal: OnceLock<CommandError>,
    /// The client closed (damping went out).
    closed: AtomicBool,
}

const PENDING: u8 = 0;
const MOVING: u8 = 1;
const REACHED: u8 = 2;
const REPLACED: u8 = 3;
const DAMPED: u8 = 4;
const REFUSED: u8 = 5;

impl MotionStatus {
    pub(crate) fn publish(&self, state: MotionState, began: Option<Time>) {
        if let Some(began) = began {
            self.began_ns.store(began.as_nanos(), Ordering::Relaxed);
        }
        let state = match state {
            MotionState::Pending => PENDING,
            MotionState::Moving { elapsed } => {
                self.elapsed_ns.store(u64::try_from(elapsed.as_nanos()).unwrap_or(u64::MAX), Ordering::Relaxed);
                MOVING
            }
            MotionState::Reached => REACHED,
            MotionState::Replaced => REPLACED,
            MotionState::Damped => DAMPED,
            MotionState::Refused(e) => {
                let _ = self.refusal.set(e);
                REFUSED
            }
        };
        self.state.store(state, Ordering::Release);
    }

    pub(crate) fn state(&self) -> MotionState {
        match self.state.load(Ordering::Acquire) {
            PENDING => MotionState::Pending,
            MOVING => MotionState::Moving { elapsed: Duration::from_nanos(self.elapsed_ns.load(Ordering::Relaxed)) },
            REACHED => MotionState::Reached,
            REPLACED => MotionState::Replaced,
            DAMPED => MotionState::Damped,
            _ => self.refusal.get().map_or(MotionState::Damped, |e| MotionState::Refused(*e)),
        }
    }

    pub(crate) fn began(&self) -> Option<Time> {
        let ns = self.began_ns.load(Ordering::Relaxed);
        (ns != 0).then_some(Time::from_nanos(ns))
    }

    /// The client closed: a motion still followed ends in its damping.
    pub(crate) fn close(&self) {
        if self.state().is_followed() && self.state() != MotionState::Reached {
            self.publish(MotionState::Damped, None);
        }
        self.closed.store(true, Ordering::Release);
    }

    pub(crate) fn is_closed(&self) -> bool {
        self.closed.load(Ordering::Acquire)
    }
}

pub(crate) struct StreamJob<R: Robot> {
    stream: CommandStream<R, Handed<R::Cmd>>,
    writer: Writer<R::Cmd>,
    shared: Arc<StreamShared<R>>,
    seen_command: Option<Time>,
    seen_damp: u64,
    /// The stamp of the last input applied: anything older is overtaken.
    applied: u64,
    /// When idle (no command yet), wake this often to look for one (a wake makes it sooner).
    idle: Duration,
}

/// An input for the stream, in the order the caller made them.
enum Input<C> {
    Command(Time, C),
    Motion(Time, Handed<C>),
    Damp(u64),
}

impl<C> Input<C> {
    fn stamp(&self) -> u64 {
        match self {
            Self::Command(at, _) | Self::Motion(at, _) => at.as_nanos(),
            Self::Damp(at) => *at,
        }
    }
}

impl<R: Robot> StreamJob<R> {
    pub(crate) fn new(
        stream: CommandStream<R, Handed<R::Cmd>>,
        writer: Writer<R::Cmd>,
        shared: Arc<StreamShared<R>>,
    ) -> Self {
        Self { stream, writer, shared, seen_command: None, seen_damp: 0, applied: 0, idle: Duration::from_millis(50) }
    }

    /// The new command, motion and damping request, applied in the order they were made.
    fn take_inputs(&mut self, now: Time) {
        let mut inputs: [Option<Input<R::Cmd>>; 3] = [None, None, None];
        if let Some((at, command)) = self.shared.commands.read_newer(self.seen_command) {
            self.seen_command = Some(at);
            inputs[0] = Some(Input::Command(at, command));
        }
        let damp = self.shared.damp_at.load(Ordering::Acquire);
        if damp != self.seen_damp {
            self.seen_damp = damp;
            inputs[1] = Some(Input::Damp(damp));
        }
        // Only when the motion it replaces can be let go: never dropped here.
        if self.shared.retired.len() < self.shared.retired.capacity() {
            inputs[2] = self.shared.motions.pop().map(|(at, motion)| Input::Motion(at, motion));
        }
        inputs.sort_unstable_by_key(|input| input.as_ref().map(Input::stamp));
        for input in inputs.into_iter().flatten() {
            let stamp = input.stamp();
            let overtaken = stamp < self.applied;
            self.applied = self.applied.max(stamp);
            match input {
                Input::Motion(_, motion) if overtaken => self.retire(motion, MotionState::Replaced),
                Input::Motion(at, motion) => {
                    if let Some((replaced, state)) = self.stream.follow(at, motion) {
                        self.retire(replaced, state);
                    }
                }
                Input::Command(at, command) => {
                    // Checked by the client already; a refusal here changes nothing.
                    let _ = self.stream.handle_command(at, command);
                }
                Input::Damp(_) if overtaken => {}
                Input::Damp(_) => self.stream.damp(now),
            }
        }
    }

    fn retire(&self, motion: Handed<R::Cmd>, state: MotionState) {
        motion.status.publish(state, None);
        // Room was made sure of before the motion was taken (only this thread adds).
        let _ = self.shared.retired.push(motion);
    }

    fn write(&self, command: R::Cmd) {
        // The encoder zeroes padding and writes the CRC. Never waits: a full send window (a
        // reader that does not acknowledge) drops this one, counted; the next tick writes again.
        if self.writer.try_write(command).is_err() {
            self.shared.write_errors.add(1);
        }
    }

    /// The closing burst: damping, from the last command (or motion step); a motion still
    /// followed ends.
    pub(crate) fn write_closing_damping(&self, kd: f32) {
        let last = self.stream.latched().map(|(_, c)| *c).unwrap_or_default();
        let damping = R::damping(&last, kd);
        for _ in 0..CLOSING_DAMPING_FRAMES {
            self.write(damping);
        }
    }

    /// The client closed: every motion it handed over is told so.
    pub(crate) fn close_motions(&self) {
        if let Some((motion, _)) = self.stream.motion() {
            motion.status.close();
        }
        while let Some((_, motion)) = self.shared.motions.pop() {
            motion.status.close();
        }
    }

    pub(crate) fn damping_kd(&self) -> f32 {
        self.stream.config().damping_kd
    }
}

impl<R: Robot> Job for StreamJob<R> {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.stream.poll_timeout().unwrap_or_else(|| robowire_rt::now() + self.idle))
    }

    fn run(&mut self, now: Time) {
        self.take_inputs(now);
        while let Some(transmit) = self.stream.poll_transmit(now) {
            self.write(transmit.command);
            self.shared.lateness.record(micros(transmit.tick.lateness));
        }
        if let Some((motion, state)) = self.stream.motion() {
            motion.status.publish(state, self.stream.motion_began());
        }
        let c = self.stream.counters();
        let s = &self.shared;
        s.sent.set(c.sent);
        s.damping.set(c.damping);
        s.command_timeouts.set(c.command_timeouts);
        s.missed_ticks.set(c.missed_ticks);
    }
}
