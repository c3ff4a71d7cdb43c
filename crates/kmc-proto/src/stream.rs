//! The host's command stream (spec §4.1), sans-IO: what the vendor's driver sends and when.
//!
//! [`CommandStream`] decides everything a driver's stream thread does, given the time: the
//! `0xA5` command at the control rate (the latched command while it is fresh, (0, 0) once it is
//! older than the command timeout), `0xB3` speed requests, the battery and all-state polls,
//! one-shot requests, and the stop burst. It never reads a clock and never sleeps: ask
//! [`poll_timeout`](CommandStream::poll_timeout) when to come back, then hand `now` to
//! [`poll_transmit`](CommandStream::poll_transmit) until it has nothing more to send. Late
//! ticks follow `robowire-core`'s missed-tick policy: skipped and counted, never caught up.
//!
//! ```
//! use core::time::Duration;
//! use kmc_proto::stream::{CommandStream, Due, StreamConfig};
//! use kmc_proto::{HostFrame, PcControl};
//! use robowire_core::schedule::Time;
//!
//! let t0 = Time::from_nanos(1_000_000_000);
//! let mut stream = CommandStream::new(t0, StreamConfig::default());
//! stream.handle_command(t0, PcControl::from_yaw_rate(0.5, 0.2).unwrap());
//! // At t0: the command and a speed request are due.
//! let first = stream.poll_transmit(t0).unwrap();
//! assert!(matches!(first.due, Due::Control { fresh: true, .. }));
//! assert_eq!(stream.poll_transmit(t0).unwrap().frame, HostFrame::VehicleSpeedRequest);
//! assert!(stream.poll_transmit(t0).is_none());
//! assert_eq!(stream.poll_timeout(), Some(t0 + Duration::from_millis(10)));
//! // 300 ms without a new command: (0, 0).
//! let later = t0 + Duration::from_millis(310);
//! let stale = stream.poll_transmit(later).unwrap();
//! assert_eq!(stale.frame, HostFrame::PcControl(PcControl::STOP));
//! ```

use core::time::Duration;

use robowire_core::schedule::{Periodic, Time, earliest};

use crate::{AfFrame, HostFrame, PcControl};

/// The vendor driver's timing (spec §4.1), as durations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamConfig {
    /// `0xA5` period. Vendor: 10 ms (100 Hz).
    pub control_period: Duration,
    /// `0xB3` request period. Vendor: 20 ms (50 Hz).
    pub speed_period: Duration,
    /// Battery read (motor 0) period, if polled. Vendor: 1 s when `poll_battery`.
    pub battery_period: Option<Duration>,
    /// All-state read (motors 0 and 1) period, if polled. Vendor: 100 ms when `poll_allstate`.
    pub all_state_period: Option<Duration>,
    /// A command older than this is replaced by (0, 0). Vendor: 300 ms.
    pub command_timeout: Duration,
    /// (0, 0) frames of the stop burst (at least 1). Vendor: 3.
    pub stop_burst: u32,
}

/// Battery poll period when enabled (1 Hz).
pub const BATTERY_POLL_PERIOD: Duration = Duration::from_secs(1);
/// All-state poll period when enabled (10 Hz).
pub const ALL_STATE_POLL_PERIOD: Duration = Duration::from_millis(100);

impl Default for StreamConfig {
    /// The vendor's defaults, polls off.
    fn default() -> Self {
        Self {
            control_period: Duration::from_millis(10),
            speed_period: Duration::from_millis(20),
            battery_period: None,
            all_state_period: None,
            command_timeout: Duration::from_millis(300),
            stop_burst: 3,
        }
    }
}

/// Why a frame is sent now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Due {
    /// The `0xA5` tick: the latched command if `fresh`, else (0, 0); `lateness` behind its
    /// deadline, `skipped` slots missed before it.
    Control {
        /// The command was set within the command timeout.
        fresh: bool,
        /// How late the tick is served.
        lateness: Duration,
        /// Slots skipped before this one.
        skipped: u64,
    },
    /// The `0xB3` tick.
    SpeedPoll,
    /// The battery poll tick (motor 0).
    BatteryPoll,
    /// The all-state poll tick (for `motor`).
    AllStatePoll {
        /// Motor 0 or 1.
        motor: u8,
    },
    /// A one-shot request ([`CommandStream::request`]).
    Request,
    /// A frame of the stop burst.
    Stop,
}

/// A frame to send now, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transmit {
    /// The frame.
    pub frame: HostFrame,
    /// Why now.
    pub due: Due,
}

/// What the stream has emitted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StreamCounters {
    /// `0xA5` frames of the control ticks (timeout stops included, the stop burst not).
    pub control_frames: u64,
    /// Of those, (0, 0) because the command was stale.
    pub timeout_frames: u64,
    /// Times the stream went from a fresh command to (0, 0).
    pub command_timeouts: u64,
    /// (0, 0) frames of the stop burst.
    pub stop_frames: u64,
    /// `0xB3` requests.
    pub speed_requests: u64,
    /// Battery reads (polls and one-shots).
    pub battery_requests: u64,
    /// All-state reads (polls and one-shots).
    pub all_state_requests: u64,
    /// Control slots skipped because a tick was served more than a period late.
    pub missed_ticks: u64,
    /// One-shot requests refused because [`MAX_PENDING_REQUESTS`] were already waiting.
    pub requests_refused: u64,
}

/// One-shot requests that can wait for the next [`poll_transmit`](CommandStream::poll_transmit).
pub const MAX_PENDING_REQUESTS: usize = 8;

/// Items due at one instant, in sending order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Slot {
    Control,
    Speed,
    Battery,
    AllState0,
    AllState1,
}

/// The host's command stream; see the [module](self).
#[derive(Debug, Clone)]
pub struct CommandStream {
    config: StreamConfig,
    control: Periodic,
    speed: Periodic,
    battery: Option<Periodic>,
    all_state: Option<Periodic>,
    /// The all-state tick covers two motors: motor 1 follows motor 0 at the same instant.
    all_state_motor_1_due: bool,
    command: PcControl,
    command_at: Option<Time>,
    was_fresh: bool,
    requests: [Option<AfFrame>; MAX_PENDING_REQUESTS],
    /// Stop frames still to send; `Some(0)` once the burst is out (the stream is finished).
    stopping: Option<u32>,
    counters: StreamCounters,
}

impl CommandStream {
    /// A stream whose first ticks are due at `now`; the command is (0, 0) until one is set.
    pub fn new(now: Time, config: StreamConfig) -> Self {
        Self {
            control: Periodic::new(now, config.control_period),
            speed: Periodic::new(now, config.speed_period),
            battery: config.battery_period.map(|p| Periodic::new(now, p)),
            all_state: config.all_state_period.map(|p| Periodic::new(now, p)),
            all_state_motor_1_due: false,
            config: StreamConfig { stop_burst: config.stop_burst.max(1), ..config },
            command: PcControl::STOP,
            command_at: None,
            was_fresh: false,
            requests: [None; MAX_PENDING_REQUESTS],
            stopping: None,
            counters: StreamCounters::default(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &StreamConfig {
        &self.config
    }

    /// Latches `command`, set at `set_at`: streamed from the next control tick on, until it
    /// is older than the command timeout.
    pub fn handle_command(&mut self, set_at: Time, command: PcControl) {
        self.command = command;
        self.command_at = Some(set_at);
    }

    /// Sets the command timeout: a command older than `timeout` is replaced by (0, 0) from the next
    /// control tick on.
    pub fn set_command_timeout(&mut self, timeout: Duration) {
        self.config.command_timeout = timeout;
    }

    /// Whether the latched command is fresh at `now`. A command stamped after `now` (set by
    /// another thread after the stream read its clock) counts as fresh.
    pub fn is_command_fresh(&self, now: Time) -> bool {
        self.command_at.is_some_and(|at| now.saturating_duration_since(at) <= self.config.command_timeout)
    }

    /// Queues a one-shot `0xAF` request, sent at the next [`poll_transmit`](Self::poll_transmit).
    /// Refused (and counted) when [`MAX_PENDING_REQUESTS`] already wait, or once stopping.
    pub fn request(&mut self, frame: AfFrame) -> bool {
        if self.stopping.is_some() {
            return false;
        }
        match self.requests.iter_mut().find(|r| r.is_none()) {
            Some(slot) => {
                *slot = Some(frame);
                true
            }
            None => {
                self.counters.requests_refused += 1;
                false
            }
        }
    }

    /// Begins the stop burst: from now on, [`poll_transmit`](Self::poll_transmit) yields the
    /// (0, 0) frames at once, then nothing; pending requests are dropped.
    pub fn stop(&mut self) {
        if self.stopping.is_none() {
            self.stopping = Some(self.config.stop_burst);
            self.requests = [None; MAX_PENDING_REQUESTS];
        }
    }

    /// Whether the stop burst is out: nothing more will be sent.
    pub fn is_finished(&self) -> bool {
        self.stopping == Some(0)
    }

    /// Starts every grid again at `now` (after a reconnect); the latched command stays.
    pub fn restart(&mut self, now: Time) {
        self.control.restart(now);
        self.speed.restart(now);
        for grid in [&mut self.battery, &mut self.all_state].into_iter().flatten() {
            grid.restart(now);
        }
        self.all_state_motor_1_due = false;
    }

    /// When to call [`poll_transmit`](Self::poll_transmit) next: the earliest deadline, or a
    /// time in the past (the epoch) if something is due at once; `None` once finished.
    pub fn poll_timeout(&self) -> Option<Time> {
        if self.is_finished() {
            return None;
        }
        if self.stopping.is_some() || self.all_state_motor_1_due || self.requests.iter().any(Option::is_some) {
            return Some(Time::ZERO);
        }
        earliest([
            Some(self.control.deadline()),
            Some(self.speed.deadline()),
            self.battery.map(|p| p.deadline()),
            self.all_state.map(|p| p.deadline()),
        ])
    }

    /// The next frame due at `now`, if any; call again until `None`. Stop frames first, then
    /// one-shot requests, then the ticks due in the order control, speed, battery, all-state.
    pub fn poll_transmit(&mut self, now: Time) -> Option<Transmit> {
        if let Some(left) = self.stopping {
            if left == 0 {
                return None;
            }
            self.stopping = Some(left - 1);
            self.counters.stop_frames += 1;
            return Some(Transmit { frame: HostFrame::PcControl(PcControl::STOP), due: Due::Stop });
        }
        if let Some(request) = self.requests.iter_mut().find_map(Option::take) {
            self.count_request(&request);
            return Some(Transmit { frame: HostFrame::Af(request), due: Due::Request });
        }
        let slot = self.due_slot(now)?;
        Some(match slot {
            Slot::Control => self.control_tick(now),
            Slot::Speed => {
                self.speed.poll(now);
                self.counters.speed_requests += 1;
                Transmit { frame: HostFrame::VehicleSpeedRequest, due: Due::SpeedPoll }
            }
            Slot::Battery => {
                if let Some(p) = self.battery.as_mut() {
                    p.poll(now);
                }
                self.counters.battery_requests += 1;
                Transmit { frame: HostFrame::Af(AfFrame::battery_read(0)), due: Due::BatteryPoll }
            }
            Slot::AllState0 => {
                if let Some(p) = self.all_state.as_mut() {
                    p.poll(now);
                }
                self.all_state_motor_1_due = true;
                self.counters.all_state_requests += 1;
                Transmit { frame: HostFrame::Af(AfFrame::all_state_read(0)), due: Due::AllStatePoll { motor: 0 } }
            }
            Slot::AllState1 => {
                self.all_state_motor_1_due = false;
                self.counters.all_state_requests += 1;
                Transmit { frame: HostFrame::Af(AfFrame::all_state_read(1)), due: Due::AllStatePoll { motor: 1 } }
            }
        })
    }

    fn due_slot(&self, now: Time) -> Option<Slot> {
        let due = |p: &Periodic| p.deadline() <= now;
        if due(&self.control) {
            Some(Slot::Control)
        } else if due(&self.speed) {
            Some(Slot::Speed)
        } else if self.battery.as_ref().is_some_and(due) {
            Some(Slot::Battery)
        } else if self.all_state_motor_1_due {
            Some(Slot::AllState1)
        } else if self.all_state.as_ref().is_some_and(due) {
            Some(Slot::AllState0)
        } else {
            None
        }
    }

    fn control_tick(&mut self, now: Time) -> Transmit {
        let tick = self.control.poll(now).unwrap_or(robowire_core::schedule::Tick {
            deadline: now,
            lateness: Duration::ZERO,
            skipped: 0,
        });
        let fresh = self.is_command_fresh(now);
        let c = &mut self.counters;
        c.control_frames += 1;
        c.missed_ticks += tick.skipped;
        if !fresh {
            c.timeout_frames += 1;
            if self.was_fresh {
                c.command_timeouts += 1;
            }
        }
        self.was_fresh = fresh;
        let command = if fresh { self.command } else { PcControl::STOP };
        Transmit {
            frame: HostFrame::PcControl(command),
            due: Due::Control { fresh, lateness: tick.lateness, skipped: tick.skipped },
        }
    }

    fn count_request(&mut self, request: &AfFrame) {
        match request.ids().first() {
            Some(crate::ParamId::BatteryVoltage) => self.counters.battery_requests += 1,
            Some(crate::ParamId::AllState) => self.counters.all_state_requests += 1,
            _ => {}
        }
    }

    /// What the stream has emitted.
    pub fn counters(&self) -> StreamCounters {
        self.counters
    }
}
