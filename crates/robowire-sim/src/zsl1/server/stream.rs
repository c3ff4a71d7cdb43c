//! The robot's two loops: the receive task (commands in, handed over in arrival order) and the
//! state stream on robowire's runner (the model stepped, state out on absolute deadlines).

use crate::zsl1::model::Zsl1Model;
use robowire_core::schedule::{Periodic, Time};
use robowire_rt::runner::{Job, Waker};
use robowire_rt::stats::micros;
use robowire_udp::{UdpError, UdpReceiver, UdpSender};
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::watch;
use zsl_proto::codec::{HighLevelDogCodec, LowLevelDogCodec};

use super::{Command, Handover, PortCounters, Request, View, send_state};

/// The receive task: counts and hands every valid command to the state stream in arrival order,
/// and wakes the stream for one that differs from the port's previous command, so that a
/// command that changes what the robot does is answered at once (the stream answers it before
/// taking the next). A repeated command is taken at the next tick.
pub(super) struct Receive<'a> {
    pub(super) handover: &'a Handover,
    pub(super) waker: Waker,
    pub(super) period: Duration,
}

impl Receive<'_> {
    pub(super) async fn run(
        self,
        mut high: UdpReceiver<HighLevelDogCodec>,
        mut low: UdpReceiver<LowLevelDogCodec>,
        stop: &mut watch::Receiver<bool>,
    ) {
        // Arrival as the network stack saw it: without the stamps, the intervals are the
        // receiving thread's wake-ups. Best effort.
        let _ = (high.enable_arrival_stamps(), low.enable_arrival_stamps());
        let h = self.handover;
        let (mut high_port, mut low_port) = (Arrivals::default(), Arrivals::default());
        loop {
            tokio::select! {
                _ = stop.changed() => return,
                received = high.recv_stamped() => match received {
                    Ok(((command, model), _, stamp)) => {
                        let changed = high_port.arrived(&h.high_level, self.period, stamp, (command, model));
                        self.hand_over(&h.high_level, Command::High(command, model), changed);
                    }
                    Err(UdpError::Decode(_)) => h.high_level.invalid.add(1),
                    // Socket errors are counted by the link.
                    Err(_) => {}
                },
                received = low.recv_stamped() => match received {
                    Ok(((command, _), _, stamp)) => {
                        let changed = low_port.arrived(&h.low_level, self.period, stamp, command);
                        self.hand_over(&h.low_level, Command::Low(command), changed);
                    }
                    Err(UdpError::Decode(_)) => h.low_level.invalid.add(1),
                    Err(_) => {}
                },
            }
        }
    }

    pub(super) fn hand_over(&self, counters: &PortCounters, command: Command, changed: bool) {
        if self.handover.commands.push(command).is_err() {
            counters.dropped.add(1);
        } else if changed {
            self.waker.wake();
        }
    }
}

/// What the receive task remembers of one port's commands.
#[derive(Debug, Default)]
struct Arrivals<T> {
    /// When the last valid command arrived (the kernel's stamp, or the monotonic clock).
    at: Option<Duration>,
    last: Option<T>,
}

impl<T: PartialEq> Arrivals<T> {
    /// A valid command arrived at `stamp` (the kernel's arrival stamp: the interval on the wire,
    /// whatever the receiving thread's scheduling; without one, now): counted, |interval −
    /// `period`| recorded. Whether it differs from the port's previous one.
    pub(super) fn arrived(
        &mut self,
        counters: &PortCounters,
        period: Duration,
        stamp: Option<Duration>,
        command: T,
    ) -> bool {
        let at = stamp.unwrap_or_else(|| Duration::from_nanos(robowire_rt::monotonic_ns()));
        counters.commands.add(1);
        if let Some(last) = self.at.replace(at) {
            counters.jitter.record(micros(at.saturating_sub(last).abs_diff(period)));
        }
        let previous = self.last.replace(command);
        previous != self.last
    }
}

/// The state stream: owns the robot and the sending halves; applies the API's requests and the
/// commands as they come, answers a command that changed something at once, and steps the robot
/// and sends state on each tick of the grid.
pub(super) struct StateStream {
    pub(super) robot: Zsl1Model,
    pub(super) high: UdpSender<HighLevelDogCodec>,
    pub(super) low: UdpSender<LowLevelDogCodec>,
    pub(super) handover: Arc<Handover>,
    pub(super) grid: Periodic,
    pub(super) last_step: Option<Time>,
}

/// Longest step of the model, s: after a stall the robot does not jump.
const MAX_STEP_S: f32 = 0.05;

impl StateStream {
    pub(super) fn publish(&self) {
        self.handover.view.publish(&View {
            robot: self.robot.clone(),
            high_level_client: self.high.destination(),
            low_level_client: self.low.destination(),
        });
    }

    pub(super) fn send_high_level(&mut self) {
        let robot = &self.robot;
        send_state(&mut self.high, &self.handover.high_level, robot.faults(), || robot.high_level_state());
    }

    pub(super) fn send_low_level(&mut self) {
        let robot = &self.robot;
        send_state(&mut self.low, &self.handover.low_level, robot.faults(), || robot.low_level_state());
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
        while let Some(command) = self.handover.commands.pop() {
            match command {
                Command::High(command, model) => {
                    if self.robot.on_high_level(&command, model) {
                        // Published first: a client that got the answer sees its effect.
                        self.publish();
                        self.send_high_level();
                    }
                }
                Command::Low(command) => {
                    if self.robot.on_low_level(&command) {
                        self.publish();
                        self.send_low_level();
                    }
                }
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
