//! `Driver`: the vendor's streaming host driver in robowire's device shape. The stream thread
//! (robowire's runner, optionally `SCHED_FIFO` and pinned) runs `kmc-proto`'s sans-IO command
//! stream and writes its frames on time; the receive thread (robowire-rt's one
//! receive-with-watchdog loop) reads what the chassis sends, keeps the latest [`ChassisState`]
//! with its odometry, queues the frames for the vendor's API, and reopens the port after a
//! disconnect. Commands go in and statistics come out without the stream thread ever waiting on a
//! lock.

mod receive;
mod stream;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc as std_mpsc;
use std::time::Duration;

use kmc_proto::stream::{ALL_STATE_POLL_PERIOD, BATTERY_POLL_PERIOD, StreamConfig};
use kmc_proto::{AfFrame, ChassisFrame, ChassisFrameDecoder, PcControl};
use robowire_core::DecoderCounters;
use robowire_core::finite;
use robowire_core::schedule::Watchdog;
use robowire_core::timing::LatenessSummary;
use robowire_rt::Placement;
use robowire_rt::device::{Device, Receiving};
use robowire_rt::runner::{Runner, RunnerOptions};
use robowire_serial::{Backoff, LinkCounters, SerialLink, SerialPortOptions, SerialTaps};

pub use self::receive::ChassisState;
use self::receive::{ChassisReceiver, Inbox};
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
    /// Without a `set_command` for this long the stream sends (0, 0). Default 300 ms; changed
    /// while running with [`Driver::set_command_timeout`].
    pub command_timeout: Duration,
    /// (0, 0) frames sent on [`Driver::close`]. Default 3; at least 1.
    pub stop_burst_count: u32,
    /// Where the stream thread runs (the vendor's `realtime_priority` and `cpu_affinity`, -1
    /// being `None`; and `mlockall`). Default: normal scheduling.
    pub placement: Placement,
    /// No frame from the chassis for this long: `Disconnected` (it answers the `0xB3` polls at
    /// the speed rate). Default 500 ms.
    pub state_timeout: Duration,
    /// Received frames kept for [`Driver::try_pop_message`]; on overflow the oldest is dropped
    /// and counted. Default 1024.
    pub max_queue: usize,
    /// Reopen the port after a disconnect on this schedule; `None` stays disconnected.
    /// Default: 50 ms doubling to 2 s, forever (robowire addition).
    pub reopen: Option<Backoff>,
    /// Host-side decoder bound for `0xB3` speeds, m/s. Default 20.
    pub max_speed_mps: f32,
    /// Where the link's frames (a link described by `kmc_proto::description::HOST`) and the
    /// bytes skipped between them go for a recorder. Default: nowhere.
    pub taps: SerialTaps,
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
            placement: Placement::default(),
            state_timeout: Duration::from_millis(500),
            max_queue: 1024,
            reopen: Some(Backoff::default()),
            max_speed_mps: kmc_proto::DEFAULT_MAX_SPEED_MPS,
            taps: SerialTaps::default(),
        }
    }
}

impl DriverOptions {
    /// Refuses an option out of range, as [`Driver::open`] does before it opens anything.
    pub fn validate(&self) -> Result<(), KmcError> {
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
        check_command_timeout(self.command_timeout)?;
        if self.state_timeout < Duration::from_millis(10) {
            return bad("state_timeout", format!("{:?} is shorter than 10 ms", self.state_timeout));
        }
        self.placement.validate()?;
        if let Err(e) = ChassisFrameDecoder::new().with_max_speed_mps(self.max_speed_mps) {
            return bad("max_speed_mps", e.to_string());
        }
        Ok(())
    }
}

/// The state of the serial port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum LinkState {
    /// Closed.
    Stopped,
    /// Port open; the stream is running.
    Connected,
    /// The port vanished; reopening if [`DriverOptions::reopen`] is set.
    Disconnected,
}

impl LinkState {
    fn from_u8(raw: u8) -> Self {
        match raw {
            1 => Self::Connected,
            2 => Self::Disconnected,
            _ => Self::Stopped,
        }
    }
}

/// Longest command timeout (1 h): a chassis never drives on a command older than this.
pub const MAX_COMMAND_TIMEOUT: Duration = Duration::from_secs(3600);

fn check_command_timeout(timeout: Duration) -> Result<(), KmcError> {
    if timeout < Duration::from_millis(1) || timeout > MAX_COMMAND_TIMEOUT {
        return Err(KmcError::Option {
            name: "command_timeout",
            reason: format!("{timeout:?} is outside 1 ms..={MAX_COMMAND_TIMEOUT:?}"),
        });
    }
    Ok(())
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
    /// Port disconnects seen.
    pub disconnects: u64,
    /// Silences longer than the state timeout (and lost ports).
    pub state_timeouts: u64,
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
}

/// Streams commands to a KMC chassis and collects its responses, like the vendor's host driver.
///
/// [`open`](Self::open) opens the port and starts two threads. The stream thread sends, on
/// absolute deadlines, the current command at `control_rate_hz` (or (0, 0) when no
/// [`set_command`](Self::set_command) came within the command timeout), `0xB3` requests at
/// `vehicle_speed_rate_hz`, and the enabled polls; its waits end with a short spin, and it can
/// run `SCHED_FIFO` on a pinned CPU. The receive thread keeps the latest [`ChassisState`] (speed,
/// battery, motors, odometry) with its arrival time, watches for silence, queues the responses for
/// [`try_pop_message`](Self::try_pop_message), and reopens a vanished port.
/// [`close`](Self::close) (or dropping the driver) sends the stop burst.
///
/// ```no_run
/// use std::time::Duration;
/// use kmc::{Device, Driver, DriverOptions};
///
/// let driver = Driver::open("/dev/ttyUSB0", DriverOptions { poll_battery: true, ..Default::default() })?;
/// for _ in 0..100 {
///     driver.set_command(0.5, 0.2)?; // 0.5 m/s, 0.2 rad/s: curvature 0.4 1/m
///     if let Some(chassis) = driver.latest() {
///         println!("{:?} m/s, x {:.2} m", chassis.state.speed_mps, chassis.state.odometry.x_m);
///     }
///     std::thread::sleep(Duration::from_millis(50));
/// }
/// driver.close()?; // the stop burst
/// # Ok::<(), kmc::KmcError>(())
/// ```
#[derive(Debug)]
pub struct Driver {
    port: PathBuf,
    options: DriverOptions,
    inbox: Arc<Inbox>,
    stream: Arc<StreamShared>,
    runner: Option<Runner<StreamJob>>,
    requests: std_mpsc::Sender<Request>,
    /// Dropped after the stop burst: the port closes with it.
    receiving: Receiving<ChassisState>,
}

impl Driver {
    /// Opens the chassis at `port` and starts the receive thread and the stream thread (with the
    /// placement applied to it). Returns once streaming, or with the reason it could not start.
    pub fn open(port: impl AsRef<Path>, options: DriverOptions) -> Result<Self, KmcError> {
        options.validate()?;
        let port = port.as_ref().to_path_buf();
        let inbox = Arc::new(Inbox::new(options.max_queue));
        let stream = Arc::new(StreamShared::default());
        let watchdog = Watchdog::new(robowire_rt::now(), options.state_timeout);
        let (receiving, ()) = Receiving::spawn("kmc-receive", watchdog, {
            let (port, options, inbox, stream) = (port.clone(), options.clone(), inbox.clone(), stream.clone());
            move || async move {
                let decoder = ChassisFrameDecoder::new()
                    .with_max_speed_mps(options.max_speed_mps)
                    .map_err(|e| KmcError::Option { name: "max_speed_mps", reason: e.to_string() })?;
                let mut link = SerialLink::open(&port, &options.serial, decoder)?;
                link.set_taps(options.taps);
                *robowire_rt::lock(&stream.writer) = Some(link.sync_writer()?);
                inbox.set_link_state(LinkState::Connected);
                let state = ChassisState::default();
                Ok::<_, KmcError>((ChassisReceiver { link, reopen: options.reopen, inbox, stream, state }, ()))
            }
        })?;
        let (requests, requests_rx) = std_mpsc::channel();
        let job = StreamJob::new(robowire_rt::now(), options.stream_config(), stream.clone(), requests_rx);
        let runner = Runner::spawn(RunnerOptions::placed("kmc-stream", options.placement), job)?;
        Ok(Self { port, options, inbox, stream, runner: Some(runner), requests, receiving })
    }

    /// The port's path.
    pub fn port(&self) -> &Path {
        &self.port
    }

    /// The options in force.
    pub fn options(&self) -> &DriverOptions {
        &self.options
    }

    /// Sends the stop burst (`stop_burst_count` × (0, 0)) and ends both threads; when this
    /// returns the port is closed. Fails with the link error if the burst could not be sent
    /// (the chassis then relies on its own watchdog). Dropping the driver does the same without
    /// the error.
    pub fn close(mut self) -> Result<(), KmcError> {
        self.shut_down()
    }

    /// Stop burst, then the stream thread ends.
    fn shut_down(&mut self) -> Result<(), KmcError> {
        let Some(runner) = self.runner.take() else { return Ok(()) };
        let asked = self.requests.send(Request::Stop).is_ok();
        runner.waker().wake();
        let job = if asked { runner.join() } else { runner.stop() };
        self.inbox.set_link_state(LinkState::Stopped);
        match job {
            Some(job) => job.stop_result.map_err(KmcError::from),
            None => Err(KmcError::NotRunning),
        }
    }

    /// Whether the stream thread runs (it ends only on close, or if it panicked).
    pub fn is_running(&self) -> bool {
        self.runner.as_ref().is_some_and(|r| !r.is_finished())
    }

    /// The serial port's state.
    pub fn link_state(&self) -> LinkState {
        self.inbox.link_state()
    }

    /// Sets the command streamed from the next tick on: `velocity_mps` forward and
    /// `yaw_rate_radps`, mapped to a curvature as the vendor does (spec §4.2:
    /// `curvature = omega / v` for |v| > 1 mm/s, else 0; the chassis cannot turn in place).
    /// NaN and infinities are refused and the previous command stays.
    pub fn set_command(&self, velocity_mps: f32, yaw_rate_radps: f32) -> Result<(), KmcError> {
        self.latch(Self::command(velocity_mps, yaw_rate_radps)?);
        Ok(())
    }

    /// The frame [`set_command`](Self::set_command) would latch, or why it refuses: to check
    /// arguments before a port is even opened.
    pub fn command(velocity_mps: f32, yaw_rate_radps: f32) -> Result<PcControl, KmcError> {
        let velocity_mps = finite("velocity_mps", velocity_mps)?;
        let yaw_rate_radps = finite("yaw_rate_radps", yaw_rate_radps)?;
        Ok(PcControl::from_yaw_rate(velocity_mps, yaw_rate_radps)?)
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

    /// Sets the command timeout (1 ms..=1 h) from the next tick on: a caller with its own
    /// deadman (a ROS 2 bridge) sets it to the deadman instead of refreshing the command.
    pub fn set_command_timeout(&self, timeout: Duration) -> Result<(), KmcError> {
        check_command_timeout(timeout)?;
        let ns = u64::try_from(timeout.as_nanos()).unwrap_or(u64::MAX);
        self.stream.command_timeout_ns.store(ns, Ordering::Release);
        if let Some(runner) = &self.runner {
            runner.waker().wake();
        }
        Ok(())
    }

    fn latch(&self, command: PcControl) {
        self.stream.command.write(robowire_rt::now(), &command.into());
    }

    /// The oldest received frame, if any.
    pub fn try_pop_message(&self) -> Option<ChassisFrame> {
        self.inbox.queue().pop_front()
    }

    /// The oldest received frame, waiting up to `timeout` for one.
    pub fn wait_pop_message(&self, timeout: Duration) -> Option<ChassisFrame> {
        let queue = self.inbox.queue();
        let mut queue =
            robowire_rt::sync::wait_timeout_while(&self.inbox.message_ready, queue, timeout, |q| q.is_empty());
        queue.pop_front()
    }

    /// Received frames until `deadline`: each as it arrives, ending at the deadline.
    ///
    /// Use it between two `set_command` calls, so that a steady flow of responses cannot keep
    /// the loop from refreshing the command (which then times out and stops the chassis):
    ///
    /// ```no_run
    /// # use std::time::{Duration, Instant};
    /// # let driver = kmc::Driver::open("/dev/ttyUSB0", Default::default())?;
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

    /// Waits up to `timeout` for a chassis state that satisfies `accept` (the latest counts),
    /// blocking the calling thread.
    pub fn wait_state(
        &self,
        timeout: Duration,
        accept: impl Fn(&ChassisState) -> bool + Send + Sync + 'static,
    ) -> Option<ChassisState> {
        self.receiving.wait_for_blocking(timeout, accept).map(|s| s.state)
    }

    fn request(&self, frame: AfFrame) -> Result<(), KmcError> {
        match &self.runner {
            Some(runner) if !runner.is_finished() => {
                self.requests.send(Request::Af(frame)).map_err(|_| KmcError::NotRunning)?;
                runner.waker().wake();
                Ok(())
            }
            _ => Err(KmcError::NotRunning),
        }
    }

    /// Sends one battery read to `motor_id` now; the answer arrives as a message and in the state.
    pub fn request_battery_once(&self, motor_id: u8) -> Result<(), KmcError> {
        self.request(AfFrame::battery_read(motor_id))
    }

    /// Sends one all-state read to `motor_id` now; the answer arrives as a message and in the
    /// state.
    pub fn request_all_state_once(&self, motor_id: u8) -> Result<(), KmcError> {
        self.request(AfFrame::all_state_read(motor_id))
    }
}

impl Device for Driver {
    type State = ChassisState;
    type Stats = DriverStats;
    type Error = KmcError;

    fn receiving(&self) -> &Receiving<ChassisState> {
        &self.receiving
    }

    /// Counters and the stream's lateness, from atomics: never blocks the stream thread.
    fn stats(&self) -> DriverStats {
        let (s, r) = (&self.stream, &self.inbox);
        let link = LinkCounters {
            decoder: DecoderCounters {
                frames: r.decoded_frames.get(),
                skipped_bytes: r.skipped_bytes.get(),
                rejected_candidates: r.rejected_candidates.get(),
            },
            bytes_read: r.bytes_read.get(),
            bytes_written: s.bytes_written.get(),
            frames_written: s.frames_written.get(),
            reopens: r.reopens.get(),
        };
        DriverStats {
            control_frames_sent: s.control_frames.get(),
            timeout_frames_sent: s.timeout_frames.get(),
            command_timeouts: s.command_timeouts.get(),
            stop_frames_sent: s.stop_frames.get(),
            speed_requests_sent: s.speed_requests.get(),
            battery_requests_sent: s.battery_requests.get(),
            all_state_requests_sent: s.all_state_requests.get(),
            frames_received: r.frames_received.get(),
            queue_dropped: r.queue_dropped.get(),
            missed_ticks: s.missed_ticks.get(),
            write_errors: s.write_errors.get(),
            disconnects: r.disconnects.get(),
            state_timeouts: self.receiving.stats().disconnects,
            control_lateness: s.lateness.summary(),
            link,
        }
    }

    fn close(self) -> Result<(), KmcError> {
        Driver::close(self)
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.shut_down();
    }
}
