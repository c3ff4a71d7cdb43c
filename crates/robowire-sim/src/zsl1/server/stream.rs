//! The state stream on robowire's polling runner: commands read from both ports as they arrive,
//! the model stepped and state sent on absolute deadlines.

use crate::zsl1::model::Zsl1Model;
use robowire_core::DatagramCodec;
use robowire_core::schedule::{Periodic, Time};
use robowire_rt::runner::Job;
use robowire_rt::stats::micros;
use robowire_udp::{UdpError, UdpLink, UdpReceiver, UdpSender};
use std::sync::Arc;
use std::time::Duration;
use zsl_proto::codec::{HighLevelDogCodec, LowLevelDogCodec};

use super::{Handover, PortCounters, Request, View, send_state};

/// Datagrams read from one port per run, so that a flood cannot hold off a state tick (what is
/// left unread runs the stream again at once).
const RECEIVE_BURST: usize = 64;

/// One port: its socket's two halves, and when its last valid command arrived.
pub(super) struct Port<C> {
    pub(super) sender: UdpSender<C>,
    pub(super) receiver: UdpReceiver<C>,
    /// The kernel's arrival stamp of the last valid command, or the monotonic clock then.
    last_arrival: Option<Duration>,
}

impl<C: DatagramCodec> Port<C> {
    /// The link's halves; arrival stamps on if the kernel does them.
    pub(super) fn new(link: UdpLink<C>) -> Self {
        let (sender, receiver) = link.into_split();
        // Arrival as the network stack saw it: without the stamps, the intervals are the
        // stream's wake-ups. Best effort.
        let _ = receiver.enable_arrival_stamps();
        Self { sender, receiver, last_arrival: None }
    }

    /// The next valid command waiting, counted, with |interval − `period`| since the one before
    /// recorded; datagrams that do not decode are counted and skipped. `None` when nothing is
    /// waiting or `budget` datagrams were read; never waits.
    fn next(&mut self, counters: &PortCounters, period: Duration, budget: &mut usize) -> Option<C::Incoming> {
        while *budget > 0 {
            *budget -= 1;
            match self.receiver.recv_stamped_now() {
                Ok(Some((command, _, stamp))) => {
                    let at = stamp.unwrap_or_else(|| Duration::from_nanos(robowire_rt::monotonic_ns()));
                    counters.commands.add(1);
                    if let Some(last) = self.last_arrival.replace(at) {
                        counters.jitter.record(micros(at.saturating_sub(last).abs_diff(period)));
                    }
                    return Some(command);
                }
                Ok(None) => return None,
                Err(UdpError::Decode(_)) => counters.invalid.add(1),
                // Socket errors are counted by the link.
                Err(_) => {}
            }
        }
        None
    }
}

/// The state stream: owns the robot and both ports; applies the API's requests and the commands
/// as they arrive, answers a command that changed something at once, and steps the robot and
/// sends state on each tick of the grid.
pub(super) struct StateStream {
    pub(super) robot: Zsl1Model,
    pub(super) high: Port<HighLevelDogCodec>,
    pub(super) low: Port<LowLevelDogCodec>,
    pub(super) handover: Arc<Handover>,
    pub(super) grid: Periodic,
    /// The state period: what the command intervals are compared with.
    pub(super) period: Duration,
    pub(super) last_step: Option<Time>,
}

/// Longest step of the model, s: after a stall the robot does not jump.
const MAX_STEP_S: f32 = 0.05;

impl StateStream {
    pub(super) fn publish(&self) {
        self.handover.view.publish(&View {
            robot: self.robot.clone(),
            high_level_client: self.high.sender.destination(),
            low_level_client: self.low.sender.destination(),
        });
    }

    pub(super) fn send_high_level(&mut self) {
        let robot = &self.robot;
        send_state(&mut self.high.sender, &self.handover.high_level, robot.faults(), || robot.high_level_state());
    }

    pub(super) fn send_low_level(&mut self) {
        let robot = &self.robot;
        send_state(&mut self.low.sender, &self.handover.low_level, robot.faults(), || robot.low_level_state());
    }
}

impl Job for StateStream {
    fn next_run(&mut self) -> Option<Time> {
        Some(self.grid.deadline())
    }

    fn run(&mut self, now: Time) {
        let mut requested = false;
        let taken = self.handover.requests.take(|request| {
            requested = true;
            match request {
                Request::Inject(fault) => self.robot.inject(fault),
                Request::ClearFaults => self.robot.clear_faults(),
                Request::SetBatteryPercent(percent) => self.robot.set_battery_percent(percent),
            }
        });
        let mut budget = RECEIVE_BURST;
        while let Some((command, model)) = self.high.next(&self.handover.high_level, self.period, &mut budget) {
            if self.robot.on_high_level(&command, model) {
                // Published first: a client that got the answer sees its effect.
                self.publish();
                self.send_high_level();
            }
        }
        let mut budget = RECEIVE_BURST;
        while let Some((command, _)) = self.low.next(&self.handover.low_level, self.period, &mut budget) {
            if self.robot.on_low_level(&command) {
                self.publish();
                self.send_low_level();
            }
        }
        if let Some(tick) = self.grid.poll(now) {
            let dt = self.last_step.replace(now).map_or(0.0, |last| now.saturating_duration_since(last).as_secs_f32());
            self.handover.stream.record(&tick, true);
            self.robot.step(dt.min(MAX_STEP_S));
            self.publish();
            self.send_high_level();
            self.send_low_level();
        } else if requested {
            self.publish();
        }
        self.handover.requests.confirm(taken);
    }
}
