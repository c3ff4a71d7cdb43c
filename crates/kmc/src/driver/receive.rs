//! The receive side: the serial port as robowire-rt's receive loop drives it. Each frame the
//! chassis sends updates the [`ChassisState`] (and its odometry) and joins the vendor's message
//! queue; a vanished port is a lost link, reopened on the driver's backoff, the new writer handed
//! to the stream thread.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Arc, Condvar, Mutex};

use kmc_proto::{AllState, BatteryVoltage, ChassisFrame, ChassisFrameDecoder};
use robowire_rt::Time;
use robowire_rt::device::{Receive, Received};
use robowire_rt::stats::Counter;
use robowire_serial::{Backoff, LinkCounters, SerialLink};

use super::LinkState;
use super::stream::StreamShared;
use crate::odometry::PlanarOdometry;

/// The chassis as the driver last heard it: the latest of each report, and the odometry.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ChassisState {
    /// The latest `0xB3` speed report, m/s.
    pub speed_mps: Option<f32>,
    /// The latest battery report.
    pub battery: Option<BatteryVoltage>,
    /// The latest all-state report of motors 0 and 1.
    pub motors: [Option<AllState>; 2],
    /// x, y, heading from the speed reports and the commanded curvature, since the driver opened.
    pub odometry: PlanarOdometry,
    /// The report that made this state.
    pub last_frame: Option<ChassisFrame>,
}

impl ChassisState {
    fn on_frame(&mut self, at: Time, frame: ChassisFrame, curvature_per_m: f32) {
        match frame {
            ChassisFrame::VehicleSpeed(speed) => {
                self.speed_mps = Some(speed.speed_mps);
                let t_s = at.as_nanos() as f64 / 1e9;
                self.odometry.on_speed(t_s, speed.speed_mps.into(), curvature_per_m.into());
            }
            ChassisFrame::BatteryVoltage(battery) => self.battery = Some(battery),
            ChassisFrame::AllState(state) => {
                if let Some(slot) = self.motors.get_mut(usize::from(state.motor_id)) {
                    *slot = Some(state);
                }
            }
            ChassisFrame::Af(_) => {}
        }
        self.last_frame = Some(frame);
    }
}

/// The vendor's message queue and the receive side's counters, shared with the user's threads.
/// Counters and the link state are atomics; only the queue has a lock (never the stream
/// thread's).
#[derive(Debug)]
pub(super) struct Inbox {
    queue: Mutex<VecDeque<ChassisFrame>>,
    pub(super) message_ready: Condvar,
    max_queue: usize,
    link_state: AtomicU8,
    pub(super) frames_received: Counter,
    pub(super) queue_dropped: Counter,
    pub(super) disconnects: Counter,
    pub(super) decoded_frames: Counter,
    pub(super) skipped_bytes: Counter,
    pub(super) rejected_candidates: Counter,
    pub(super) bytes_read: Counter,
    pub(super) reopens: Counter,
}

impl Inbox {
    pub(super) fn new(max_queue: usize) -> Self {
        Self {
            queue: Mutex::new(VecDeque::with_capacity(max_queue.min(4096))),
            message_ready: Condvar::new(),
            max_queue,
            link_state: AtomicU8::new(LinkState::Stopped as u8),
            frames_received: Counter::default(),
            queue_dropped: Counter::default(),
            disconnects: Counter::default(),
            decoded_frames: Counter::default(),
            skipped_bytes: Counter::default(),
            rejected_candidates: Counter::default(),
            bytes_read: Counter::default(),
            reopens: Counter::default(),
        }
    }

    pub(super) fn queue(&self) -> std::sync::MutexGuard<'_, VecDeque<ChassisFrame>> {
        robowire_rt::lock(&self.queue)
    }

    pub(super) fn link_state(&self) -> LinkState {
        LinkState::from_u8(self.link_state.load(Ordering::Acquire))
    }

    pub(super) fn set_link_state(&self, state: LinkState) {
        self.link_state.store(state as u8, Ordering::Release);
    }

    /// The read side's counters, copied from the link.
    fn mirror(&self, link: LinkCounters) {
        self.decoded_frames.set(link.decoder.frames);
        self.skipped_bytes.set(link.decoder.skipped_bytes);
        self.rejected_candidates.set(link.decoder.rejected_candidates);
        self.bytes_read.set(link.bytes_read);
        self.reopens.set(link.reopens);
    }

    fn enqueue(&self, frame: ChassisFrame) {
        self.frames_received.add(1);
        let mut queue = self.queue();
        if queue.len() >= self.max_queue {
            queue.pop_front();
            self.queue_dropped.add(1);
        }
        queue.push_back(frame);
        drop(queue);
        self.message_ready.notify_one();
    }
}

/// The port as the receive loop sees it.
pub(super) struct ChassisReceiver {
    pub(super) link: SerialLink<ChassisFrameDecoder>,
    pub(super) reopen: Option<Backoff>,
    pub(super) inbox: Arc<Inbox>,
    pub(super) stream: Arc<StreamShared>,
    pub(super) state: ChassisState,
}

impl Receive for ChassisReceiver {
    type Item = ChassisFrame;
    type State = ChassisState;

    async fn receive(&mut self) -> Received<ChassisFrame> {
        loop {
            if self.link.is_open() {
                let frame = self.link.recv().await;
                self.inbox.mirror(self.link.counters());
                return match frame {
                    Ok(frame) => Received::Item(frame),
                    Err(_) => {
                        if self.inbox.link_state() != LinkState::Disconnected {
                            self.inbox.set_link_state(LinkState::Disconnected);
                            self.inbox.disconnects.add(1);
                        }
                        Received::Lost
                    }
                };
            }
            let Some(backoff) = self.reopen else {
                // Not reopening: the link stays down until the driver closes.
                return std::future::pending().await;
            };
            if self.link.reopen(&backoff).await.is_err() {
                // The backoff gave up: nothing more will arrive.
                return Received::Closed;
            }
            if let Ok(writer) = self.link.sync_writer() {
                *robowire_rt::lock(&self.stream.writer) = Some(writer);
            }
            self.inbox.mirror(self.link.counters());
            self.inbox.set_link_state(LinkState::Connected);
        }
    }

    fn on_item(&mut self, now: Time, frame: ChassisFrame) -> Option<ChassisState> {
        self.inbox.enqueue(frame);
        let curvature = self.stream.command.read().map_or(0.0, |(_, c)| c.curvature_per_m.get());
        self.state.on_frame(now, frame, curvature);
        Some(self.state)
    }
}

impl Drop for ChassisReceiver {
    fn drop(&mut self) {
        // A writer the stream thread never took would keep the port open (and, exclusive, busy).
        robowire_rt::lock(&self.stream.writer).take();
    }
}
