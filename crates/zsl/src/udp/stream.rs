//! The stream thread's job: `zsl-proto`'s sans-IO [`CommandStream`] on robowire's runner,
//! sending through the link's non-blocking `send_now`. It takes its inputs (calls, states,
//! disconnects) from seqlocks and an atomic, applied in the order they happened, and never
//! waits for another thread.

use std::sync::Arc;
use std::sync::atomic::Ordering;

use robowire_rt::Time;
use robowire_rt::runner::Job;
use robowire_rt::stats::micros;
use robowire_udp::UdpSender;
use zsl_proto::stream::{Cause, CommandStream};

use super::shared::{Codec, Shared, Wire};

/// Datagrams of the stop burst sent when a client closes.
pub(super) const STOP_BURST: usize = 3;

pub(super) struct StreamJob<I: Wire> {
    stream: CommandStream<I>,
    sender: UdpSender<Codec<I>>,
    shared: Arc<Shared<I>>,
    /// Stamps of the inputs already taken.
    call_seen: Option<Time>,
    state_seen: Option<Time>,
    disconnect_seen: u64,
}

/// An input to the stream from another thread.
pub(super) enum Input<C> {
    /// A call latched this command.
    Call(C),
    /// The watchdog expired.
    Disconnect,
}

/// A call and a disconnect the stream has not taken yet, in the order they happened: a call
/// made before a disconnect is stopped by it, one made after it is not.
pub(super) fn in_order<C>(call: Option<(Time, C)>, disconnect: Option<Time>) -> impl Iterator<Item = Input<C>> {
    let mut inputs = [call.map(|(at, c)| (at, Input::Call(c))), disconnect.map(|at| (at, Input::Disconnect))];
    inputs.sort_by_key(|input| input.as_ref().map(|(at, _)| *at));
    inputs.into_iter().flatten().map(|(_, input)| input)
}

impl<I: Wire> StreamJob<I> {
    pub(super) fn new(stream: CommandStream<I>, sender: UdpSender<Codec<I>>, shared: Arc<Shared<I>>) -> Self {
        Self { stream, sender, shared, call_seen: None, state_seen: None, disconnect_seen: 0 }
    }

    /// The client's last word: the latched command with its motion stopped, [`STOP_BURST`] times
    /// (unless the robot halted the stream). Failed sends are counted by the link.
    pub(super) fn send_stop_burst(&mut self) {
        if self.stream.is_halted() {
            return;
        }
        let mut stop = *self.stream.latched();
        I::stop_motion(&mut stop);
        for _ in 0..STOP_BURST {
            let _ = self.sender.send_now(&stop);
        }
    }

    /// Takes what the other threads handed over since the last run; returns when (anything
    /// handed over later is taken by the next run). A state from before the latest disconnect
    /// is ignored.
    fn take_inputs(&mut self) -> Time {
        let taken_at = robowire_rt::now();
        let shared = &self.shared;
        let call = shared.calls.read_newer(self.call_seen);
        if let Some((at, _)) = call {
            self.call_seen = Some(at);
        }
        let disconnected_at = shared.disconnected_at.load(Ordering::Acquire);
        let disconnect = (disconnected_at != self.disconnect_seen).then_some(Time::from_nanos(disconnected_at));
        self.disconnect_seen = disconnected_at;
        for input in in_order(call, disconnect) {
            match input {
                // Refused once halted; the call sees the halt flag itself.
                Input::Call(command) => drop(self.stream.handle_call(command)),
                Input::Disconnect => self.stream.handle_disconnect(),
            }
        }
        if let Some((at, state)) = shared.states.read_newer(self.state_seen) {
            self.state_seen = Some(at);
            if at.as_nanos() > self.disconnect_seen {
                self.stream.handle_state(&state);
            }
        }
        taken_at
    }
}

impl<I: Wire> Job for StreamJob<I> {
    fn next_run(&mut self) -> Option<Time> {
        self.stream.poll_timeout()
    }

    fn run(&mut self, now: Time) {
        let taken_at = self.take_inputs();
        let shared = &self.shared;
        while let Some(transmit) = self.stream.poll_transmit(now) {
            // A failed send is counted by the link; the next refresh sends again.
            let _ = self.sender.send_now(&transmit.command);
            // Stamped with when the inputs were taken: a call or a disconnect stamped later is
            // still pending for `Session::latched`.
            shared.streamed.write(taken_at, &transmit.command);
            if let Cause::Refresh(tick) = transmit.cause {
                shared.lateness.record(micros(tick.lateness));
            }
        }
        let c = self.stream.counters();
        shared.calls_sent.set(c.calls);
        shared.refreshes_sent.set(c.refreshes);
        shared.missed_ticks.set(c.missed_ticks);
        if self.stream.is_halted() {
            shared.halted.store(true, Ordering::Release);
        }
    }
}
