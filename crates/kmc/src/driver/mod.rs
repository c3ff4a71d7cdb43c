//! `Driver`: the vendor's streaming host driver on two threads. The stream thread (robowire's
//! runner, optionally `SCHED_FIFO` and pinned) runs `kmc-proto`'s sans-IO command stream and
//! writes its frames on time; the receive thread reads what the chassis sends, queues it, and
//! reopens the port after a disconnect. Commands go in and statistics come out without the
//! stream thread ever waiting on a lock.

mod receive;
mod stream;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc as std_mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

use kmc_proto::stream::{ALL_STATE_POLL_PERIOD, BATTERY_POLL_PERIOD, StreamConfig};
use kmc_proto::{AfFrame, ChassisFrame, ChassisFrameDecoder, PcControl};
use robowire_core::finite;
use robowire_core::timing::LatenessSummary;
use robowire_rt::runner::{Runner, RunnerOptions};
use robowire_serial::{Backoff, LinkCounters, SerialPortOptions};
use tokio::sync::watch;

use self::receive::Inbox;
use self::stream::{Request, StreamJob, StreamShared};
use crate::KmcError;

/// Battery poll rate when [`DriverOptions::poll_battery`] is on, Hz.
pub const BATTERY_POLL_HZ: f64 = 1.0;
/// All-state poll rate (motors 0 and 1) when [`DriverOptions::poll_allstate`] is on, Hz.
pub const ALL_STATE_POLL_HZ: f64 = 10.0;
/// Highest accepted stream rate, Hz: 9-byte frames at 1 kHz fill 78 % of a 115200 8N1 link.
pub const MAX_RATE_HZ: f64 = 1000.0;

/// Every option of the vendor driver (spec §4.1) with the vendor's defaults, plus the serial
/// settings and robowire's reconnect policy.
#[derive(Debug, Clone, PartialEq)]
pub struct DriverOptions {
    /// Serial line settings (115200, RTS/CTS, RTS asserted, 8N1).
    pub serial: SerialPortOptions,
    /// The `0xA5` stream rate, Hz. Default 100 (every 10 ms).
    pub control_rate_hz: f64,
    /// `0xB3` request rate, Hz. Default 50.
    pub vehicle_speed_rate_hz: f64,
    /// Read the battery (ID 0x07, motor 0) at [`BATTERY_POLL_HZ`]. Default off.
    pub poll_battery: bool,
    /// Read all-state (ID 0x06) of motors 0 and 1 at [`ALL_STATE_POLL_HZ`]. Default off.
    pub poll_allstate: bool,
    /// Without a `set_command` for this long the stream sends (0, 0). Default 300 ms.
    pub command_timeout: Duration,
    /// (0, 0) frames sent on [`Driver::stop`]. Default 3; at least 1.
    pub stop_burst_count: u32,
    /// `SCHED_FIFO` priority 1..=99 for the stream thread; `None` (the vendor's -1) keeps normal
    /// scheduling. Default `None`.
    pub realtime_priority: Option<u8>,
    /// CPU to pin the stream thread to; `None` (the vendor's -1) does not pin. Default `None`.
    pub cpu_affinity: Option<usize>,
    /// Lock the process's memory (`mlockall`) when the stream starts. Default off.
    pub lock_memory: bool,
    /// Received frames kept for [`Driver::try_pop_message`]; on overflow the oldest is dropped
    /// and counted. Default 1024.
    pub max_queue: usize,
    /// Reopen the port after a disconnect on this schedule; `None` stays disconnected.
    /// Default: 50 ms doubling to 2 s, forever (robowire addition).
    pub reopen: Option<Backoff>,
    /// Host-side decoder bound for `0xB3` speeds, m/s. Default 20.
    pub max_speed_mps: f32,
}

impl Default for DriverOptions {
    fn default() -> Self {
        Self {
            serial: SerialPortOptions::default(),
            control_rate_hz: 100.0,
            vehicle_speed_rate_hz: 50.0,
            poll_battery: false,
            poll_allstate: false,
            command_timeout: Duration::from_millis(300),
            stop_burst_count: 3,
            realtime_priority: None,
            cpu_affinity: None,
            lock_memory: false,
            max_queue: 1024,
            reopen: Some(Backoff::default()),
            max_speed_mps: kmc_proto::DEFAULT_MAX_SPEED_MPS,
        }
    }
}

impl DriverOptions {
    fn validate(&self) -> Result<(), KmcError> {
        let bad = |name: &'static str, reason: String| Err(KmcError::Option { name, reason });
        for (name, hz) in
            [("control_rate_hz", self.control_rate_hz), ("vehicle_speed_rate_hz", self.vehicle_speed_rate_hz)]
        {
            if !(hz.is_finite() && hz > 0.0 && hz <= MAX_RATE_HZ) {
                return bad(name, format!("{hz} Hz is outside (0, {MAX_RATE_HZ}]"));
            }
        }
        if self.stop_burst_count == 0 {
            return bad("stop_burst_count", "at least one stop frame must be sent on stop".into());
        }
        if self.max_queue == 0 {
            return bad("max_queue", "the queue must hold at least one frame".into());
        }
        if let Some(priority) = self.realtime_priority
            && !(1..=99).contains(&priority)
        {
            return bad("realtime_priority", format!("{priority} is outside SCHED_FIFO's 1..=99"));
        }
        if let Err(e) = ChassisFrameDecoder::new().with_max_speed_mps(self.max_speed_mps) {
            return bad("max_speed_mps", e.to_string());
        }
        Ok(())
    }
}

/// The state of the link to the chassis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkState {
    /// Not started, or stopped.
    Stopped,
    /// Port open; the stream is running.
    Connected,
    /// The port vanished; reopening if [`DriverOptions::reopen`] is set.
    Disconnected,
}

/// What the driver did and saw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DriverStats {
    /// `0xA5` frames sent by the stream (including timeout stops, excluding the stop burst).
    pub control_frames_sent: u64,
    /// Of those, (0, 0) frames sent because the command was stale.
    pub timeout_frames_sent: u64,
    /// Times the stream switched from a fresh command to (0, 0) because of the timeout.
    pub command_timeouts: u64,
    /// (0, 0) frames of stop bursts.
    pub stop_frames_sent: u64,
    /// `0xB3` requests sent.
    pub speed_requests_sent: u64,
    /// Battery reads sent (polls and one-shot requests).
    pub battery_requests_sent: u64,
    /// All-state reads sent (polls and one-shot requests).
    pub all_state_requests_sent: u64,
    /// Frames received from the chassis.
    pub frames_received: u64,
    /// Frames dropped from the full queue (oldest first).
    pub queue_dropped: u64,
    /// Stream ticks skipped because the thread was later than a whole period.
    pub missed_ticks: u64,
    /// Frames the stream thread could not write (the port was gone).
    pub write_errors: u64,
    /// Disconnects seen.
    pub disconnects: u64,
    /// Lateness of `0xA5` sends against their absolute deadlines.
    pub control_lateness: LatenessSummary,
    /// Serial link counters: bytes, frames written, reopens, decoder skipped/rejected.
    pub link: LinkCounters,
}

impl DriverOptions {
    /// The stream's schedule.
    fn stream_config(&self) -> StreamConfig {
        StreamConfig {
            control_period: Duration::from_secs_f64(1.0 / self.control_rate_hz),
            speed_period: Duration::from_secs_f64(1.0 / self.vehicle_speed_rate_hz),
            battery_period: self.poll_battery.then_some(BATTERY_POLL_PERIOD),
            all_state_period: self.poll_allstate.then_some(ALL_STATE_POLL_PERIOD),
            command_timeout: self.command_timeout,
            stop_burst: self.stop_burst_count,
        }
    }

    fn runner_options(&self) -> RunnerOptions {
        RunnerOptions {
            realtime_priority: self.realtime_priority,
            cpu: self.cpu_affinity,
            lock_memory: self.lock_memory,
            ..RunnerOptions::named("kmc-stream")
        }
    }
}

#[derive(Debug)]
struct Running {
    stream: Runner<StreamJob>,
    requests: std_mpsc::Sender<Request>,
    stop_receiving: watch::Sender<bool>,
    receiver: JoinHandle<()>,
}

/// Streams commands to a KMC chassis and collects its responses, like the vendor's host driver.
///
/// [`start`](Self::start) opens the port and starts two threads. The stream thread sends, on
/// absolute deadlines, the current command at `control_rate_hz` (or (0, 0) when no
/// [`set_command`](Self::set_command) came within `command_timeout`), `0xB3` requests at
/// `vehicle_speed_rate_hz`, and the enabled polls; its waits end with a short spin, and it can
/// run `SCHED_FIFO` on a pinned CPU. The receive thread queues the responses for
/// [`try_pop_message`](Self::try_pop_message) and reopens a vanished port. [`stop`](Self::stop)
/// (or dropping the driver) sends the stop burst.
///
/// ```no_run
/// use std::time::Duration;
/// use kmc::{Driver, DriverOptions};
///
/// let mut driver = Driver::new("/dev/ttyUSB0", DriverOptions { poll_battery: true, ..Default::default() })?;
/// driver.start()?;
/// for _ in 0..100 {
///     driver.set_command(0.5, 0.2)?; // 0.5 m/s, 0.2 rad/s: curvature 0.4 1/m
///     while let Some(frame) = driver.try_pop_message() {
///         println!("{frame:?}");
///     }
///     std::thread::sleep(Duration::from_millis(50));
/// }
/// driver.stop()?;
/// # Ok::<(), kmc::KmcError>(())
/// ```
#[derive(Debug)]
pub struct Driver {
    port: PathBuf,
    options: DriverOptions,
    inbox: Arc<Inbox>,
    stream: Arc<StreamShared>,
    running: Option<Running>,
}

impl Driver {
    /// A stopped driver for the chassis at `port`; checks the options.
    pub fn new(port: impl AsRef<Path>, options: DriverOptions) -> Result<Self, KmcError> {
        options.validate()?;
        Ok(Self {
            port: port.as_ref().to_path_buf(),
            inbox: Arc::new(Inbox::new(options.max_queue)),
            stream: Arc::new(StreamShared::default()),
            options,
            running: None,
        })
    }

    /// The options in force.
    pub fn options(&self) -> &DriverOptions {
        &self.options
    }

    /// Opens the port, starts the receive thread and the stream thread (with `cpu_affinity`,
    /// `realtime_priority` and `lock_memory` applied to it). Returns once streaming, or with
    /// the reason it could not start.
    pub fn start(&mut self) -> Result<(), KmcError> {
        if self.is_running() {
            return Err(KmcError::AlreadyRunning);
        }
        if let Some(old) = self.running.take() {
            // A run whose threads ended by themselves: collect them.
            let _ = Self::shut_down(old);
        }
        let (stop_receiving, stop_rx) = watch::channel(false);
        let (started_tx, started) = std_mpsc::sync_channel(1);
        let receiver = std::thread::Builder::new()
            .name("kmc-receive".into())
            .spawn({
                let (port, options, inbox, stream) =
                    (self.port.clone(), self.options.clone(), self.inbox.clone(), self.stream.clone());
                move || receive::run(port, options, inbox, stream, stop_rx, started_tx)
            })
            .map_err(KmcError::Thread)?;
        let opened =
            started.recv().unwrap_or_else(|_| Err(KmcError::Thread(std::io::Error::other("the receive thread died"))));
        if let Err(e) = opened {
            let _ = receiver.join();
            return Err(e);
        }
        let (requests, requests_rx) = std_mpsc::channel();
        let job = StreamJob::new(robowire_rt::now(), self.options.stream_config(), self.stream.clone(), requests_rx);
        let stream = match Runner::spawn(self.options.runner_options(), job) {
            Ok(stream) => stream,
            Err(e) => {
                let _ = stop_receiving.send(true);
                let _ = receiver.join();
                self.inbox.lock().link_state = LinkState::Stopped;
                return Err(e.into());
            }
        };
        self.running = Some(Running { stream, requests, stop_receiving, receiver });
        Ok(())
    }

    /// Sends the stop burst (`stop_burst_count` × (0, 0)) and ends both threads. Idempotent.
    /// Fails with the link error if the burst could not be sent (the chassis then relies on its
    /// own watchdog).
    pub fn stop(&mut self) -> Result<(), KmcError> {
        let Some(running) = self.running.take() else { return Ok(()) };
        let result = Self::shut_down(running);
        self.inbox.lock().link_state = LinkState::Stopped;
        result
    }

    /// Stop burst, then both threads end.
    fn shut_down(running: Running) -> Result<(), KmcError> {
        let asked = running.requests.send(Request::Stop).is_ok();
        running.stream.waker().wake();
        let job = if asked { running.stream.join() } else { running.stream.stop() };
        let _ = running.stop_receiving.send(true);
        let _ = running.receiver.join();
        match job {
            Some(job) => job.stop_result.map_err(KmcError::from),
            None => Err(KmcError::NotRunning),
        }
    }

    /// Are the threads running?
    pub fn is_running(&self) -> bool {
        self.running.as_ref().is_some_and(|r| !r.stream.is_finished() && !r.receiver.is_finished())
    }

    /// The link's state.
    pub fn link_state(&self) -> LinkState {
        self.inbox.lock().link_state
    }

    /// Sets the command streamed from the next tick on: `velocity_mps` forward and
    /// `yaw_rate_radps`, mapped to a curvature as the vendor does (spec §4.2:
    /// `curvature = omega / v` for |v| > 1 mm/s, else 0; the chassis cannot turn in place).
    /// NaN and infinities are refused and the previous command stays.
    pub fn set_command(&self, velocity_mps: f32, yaw_rate_radps: f32) -> Result<(), KmcError> {
        let velocity_mps = finite("velocity_mps", velocity_mps)?;
        let yaw_rate_radps = finite("yaw_rate_radps", yaw_rate_radps)?;
        let command = PcControl::from_yaw_rate(velocity_mps, yaw_rate_radps)?;
        self.latch(command);
        Ok(())
    }

    /// Sets the command as velocity and curvature directly.
    pub fn set_command_curvature(&self, velocity_mps: f32, curvature_per_m: f32) -> Result<(), KmcError> {
        let command = PcControl {
            velocity_mps: finite("velocity_mps", velocity_mps)?,
            curvature_per_m: finite("curvature_per_m", curvature_per_m)?,
        };
        self.latch(command);
        Ok(())
    }

    fn latch(&self, command: PcControl) {
        self.stream.command.write(robowire_rt::now(), &command.into());
    }

    /// The oldest received frame, if any.
    pub fn try_pop_message(&self) -> Option<ChassisFrame> {
        self.inbox.lock().queue.pop_front()
    }

    /// The oldest received frame, waiting up to `timeout` for one.
    pub fn wait_pop_message(&self, timeout: Duration) -> Option<ChassisFrame> {
        let received = self.inbox.lock();
        let (mut received, _) = self
            .inbox
            .message_ready
            .wait_timeout_while(received, timeout, |r| r.queue.is_empty())
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        received.queue.pop_front()
    }

    /// Received frames until `deadline`: each as it arrives, ending at the deadline.
    ///
    /// Use it between two `set_command` calls, so that a steady flow of responses cannot keep
    /// the loop from refreshing the command (which then times out and stops the chassis):
    ///
    /// ```no_run
    /// # use std::time::{Duration, Instant};
    /// # let driver = kmc::Driver::new("/dev/ttyUSB0", Default::default())?;
    /// loop {
    ///     driver.set_command(0.5, 0.0)?;
    ///     for frame in driver.messages_until(Instant::now() + Duration::from_millis(50)) {
    ///         println!("{frame:?}");
    ///     }
    /// }
    /// # Ok::<(), kmc::KmcError>(())
    /// ```
    pub fn messages_until(&self, deadline: std::time::Instant) -> impl Iterator<Item = ChassisFrame> + '_ {
        std::iter::from_fn(move || {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            if left.is_zero() { self.try_pop_message() } else { self.wait_pop_message(left) }
        })
        .take_while(move |_| std::time::Instant::now() <= deadline)
    }

    fn request(&self, frame: AfFrame) -> Result<(), KmcError> {
        match &self.running {
            Some(running) if !running.stream.is_finished() => {
                running.requests.send(Request::Af(frame)).map_err(|_| KmcError::NotRunning)?;
                running.stream.waker().wake();
                Ok(())
            }
            _ => Err(KmcError::NotRunning),
        }
    }

    /// Sends one battery read to `motor_id` now; the answer arrives as a message.
    pub fn request_battery_once(&self, motor_id: u8) -> Result<(), KmcError> {
        self.request(AfFrame::battery_read(motor_id))
    }

    /// Sends one all-state read to `motor_id` now; the answer arrives as a message.
    pub fn request_all_state_once(&self, motor_id: u8) -> Result<(), KmcError> {
        self.request(AfFrame::all_state_read(motor_id))
    }

    /// Counters and the stream's lateness. Never blocks the stream thread: its figures are
    /// atomics, the lateness percentiles are computed here.
    pub fn stats(&self) -> DriverStats {
        let s = &self.stream;
        let received = self.inbox.lock();
        let link = LinkCounters {
            bytes_written: s.bytes_written.get(),
            frames_written: s.frames_written.get(),
            ..received.link
        };
        DriverStats {
            control_frames_sent: s.control_frames.get(),
            timeout_frames_sent: s.timeout_frames.get(),
            command_timeouts: s.command_timeouts.get(),
            stop_frames_sent: s.stop_frames.get(),
            speed_requests_sent: s.speed_requests.get(),
            battery_requests_sent: s.battery_requests.get(),
            all_state_requests_sent: s.all_state_requests.get(),
            frames_received: received.frames_received,
            queue_dropped: received.queue_dropped,
            missed_ticks: s.missed_ticks.get(),
            write_errors: s.write_errors.get(),
            disconnects: received.disconnects,
            control_lateness: s.lateness.summary(),
            link,
        }
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.stop();
    }
}
