//! `Driver`: the vendor's streaming host driver. A thread of its own streams the current
//! command, polls the chassis, and queues what comes back.

use std::collections::VecDeque;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, mpsc as std_mpsc};
use std::thread::JoinHandle;
use std::time::Duration;

use kmc_proto::{AfFrame, ChassisFrame, ChassisFrameDecoder, HostFrame, MAX_FRAME_LEN, PcControl};
use robowire_core::timing::{LatenessRing, LatenessSummary};
use robowire_serial::{Backoff, LinkCounters, SerialError, SerialLink, SerialPortOptions};
use tokio::sync::{mpsc, oneshot};
use tokio::time::Instant;

use crate::KmcError;
use robowire_core::finite;

/// Battery poll rate when [`DriverOptions::poll_battery`] is on, Hz.
pub const BATTERY_POLL_HZ: f64 = 1.0;
/// All-state poll rate (motors 0 and 1) when [`DriverOptions::poll_allstate`] is on, Hz.
pub const ALL_STATE_POLL_HZ: f64 = 10.0;
/// How early the I/O loop wakes through tokio's millisecond timer before a deadline.
const TIMER_SLACK: Duration = Duration::from_micros(1500);
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
    /// `SCHED_FIFO` priority 1..=99 for the driver thread; `None` (the vendor's -1) keeps normal
    /// scheduling. Default `None`.
    pub realtime_priority: Option<u8>,
    /// CPU to pin the driver thread to; `None` (the vendor's -1) does not pin. Default `None`.
    pub cpu_affinity: Option<usize>,
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
    /// Disconnects seen.
    pub disconnects: u64,
    /// Lateness of `0xA5` sends against their absolute deadlines.
    pub control_lateness: LatenessSummary,
    /// Serial link counters: bytes, frames written, reopens, decoder skipped/rejected.
    pub link: LinkCounters,
}

#[derive(Debug)]
struct SharedState {
    command: PcControl,
    command_set_at: Option<Instant>,
    queue: VecDeque<ChassisFrame>,
    link_state: LinkState,
    stats: DriverStats,
    lateness: LatenessRing<4096>,
}

#[derive(Debug)]
struct Shared {
    state: Mutex<SharedState>,
    message_ready: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, SharedState> {
        self.state.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

enum Request {
    Battery(u8),
    AllState(u8),
    Stop(oneshot::Sender<Result<(), SerialError>>),
}

#[derive(Debug)]
struct Running {
    requests: mpsc::UnboundedSender<Request>,
    thread: JoinHandle<()>,
}

/// Streams commands to a KMC chassis and collects its responses, like the vendor's host driver.
///
/// [`start`](Self::start) opens the port and starts an I/O thread that sends, on absolute
/// deadlines, the current command at `control_rate_hz` (or (0, 0) when no
/// [`set_command`](Self::set_command) came within `command_timeout`), `0xB3` requests at
/// `vehicle_speed_rate_hz`, and the enabled polls. Responses queue up for
/// [`try_pop_message`](Self::try_pop_message). [`stop`](Self::stop) (or dropping the driver)
/// sends the stop burst.
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
    shared: Arc<Shared>,
    running: Option<Running>,
}

impl Driver {
    /// A stopped driver for the chassis at `port`; checks the options.
    pub fn new(port: impl AsRef<Path>, options: DriverOptions) -> Result<Self, KmcError> {
        options.validate()?;
        let shared = Arc::new(Shared {
            state: Mutex::new(SharedState {
                command: PcControl::STOP,
                command_set_at: None,
                queue: VecDeque::with_capacity(options.max_queue.min(4096)),
                link_state: LinkState::Stopped,
                stats: DriverStats::default(),
                lateness: LatenessRing::new(),
            }),
            message_ready: Condvar::new(),
        });
        Ok(Self { port: port.as_ref().to_path_buf(), options, shared, running: None })
    }

    /// The options in force.
    pub fn options(&self) -> &DriverOptions {
        &self.options
    }

    /// Opens the port, applies `cpu_affinity` and `realtime_priority` to the I/O thread, and
    /// starts streaming. Returns once the port is open, or with the reason it could not be.
    pub fn start(&mut self) -> Result<(), KmcError> {
        if self.is_running() {
            return Err(KmcError::AlreadyRunning);
        }
        // A previous run that ended on its own (it cannot, but be safe) is joined first.
        if let Some(old) = self.running.take() {
            let _ = old.thread.join();
        }
        let (requests_tx, requests_rx) = mpsc::unbounded_channel();
        let (init_tx, init_rx) = std_mpsc::sync_channel(1);
        let port = self.port.clone();
        let options = self.options.clone();
        let shared = self.shared.clone();
        let thread = std::thread::Builder::new()
            .name("kmc-driver".into())
            .spawn(move || io_thread(port, options, shared, requests_rx, init_tx))
            .map_err(KmcError::Thread)?;
        match init_rx.recv() {
            Ok(Ok(())) => {
                self.running = Some(Running { requests: requests_tx, thread });
                Ok(())
            }
            Ok(Err(e)) => {
                let _ = thread.join();
                Err(e)
            }
            Err(_) => {
                let _ = thread.join();
                Err(KmcError::Thread(std::io::Error::other("driver thread ended during start")))
            }
        }
    }

    /// Sends the stop burst (`stop_burst_count` × (0, 0)) and ends the I/O thread. Idempotent.
    /// Fails with the link error if the burst could not be sent (the chassis then relies on its
    /// own watchdog).
    pub fn stop(&mut self) -> Result<(), KmcError> {
        let Some(running) = self.running.take() else { return Ok(()) };
        let (reply_tx, reply_rx) = oneshot::channel();
        let sent = running.requests.send(Request::Stop(reply_tx)).is_ok();
        let outcome = if sent { reply_rx.blocking_recv().ok() } else { None };
        let _ = running.thread.join();
        self.shared.lock().link_state = LinkState::Stopped;
        match outcome {
            Some(result) => result.map_err(KmcError::from),
            None => Err(KmcError::NotRunning),
        }
    }

    /// Is the I/O thread running?
    pub fn is_running(&self) -> bool {
        self.running.as_ref().is_some_and(|r| !r.thread.is_finished())
    }

    /// The link's state.
    pub fn link_state(&self) -> LinkState {
        self.shared.lock().link_state
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
        let mut state = self.shared.lock();
        state.command = command;
        state.command_set_at = Some(Instant::now());
    }

    /// The oldest received frame, if any.
    pub fn try_pop_message(&self) -> Option<ChassisFrame> {
        self.shared.lock().queue.pop_front()
    }

    /// The oldest received frame, waiting up to `timeout` for one.
    pub fn wait_pop_message(&self, timeout: Duration) -> Option<ChassisFrame> {
        let state = self.shared.lock();
        let (mut state, _) = self
            .shared
            .message_ready
            .wait_timeout_while(state, timeout, |s| s.queue.is_empty())
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        state.queue.pop_front()
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

    fn request(&self, request: Request) -> Result<(), KmcError> {
        match &self.running {
            Some(running) if !running.thread.is_finished() => {
                running.requests.send(request).map_err(|_| KmcError::NotRunning)
            }
            _ => Err(KmcError::NotRunning),
        }
    }

    /// Sends one battery read to `motor_id` now; the answer arrives as a message.
    pub fn request_battery_once(&self, motor_id: u8) -> Result<(), KmcError> {
        self.request(Request::Battery(motor_id))
    }

    /// Sends one all-state read to `motor_id` now; the answer arrives as a message.
    pub fn request_all_state_once(&self, motor_id: u8) -> Result<(), KmcError> {
        self.request(Request::AllState(motor_id))
    }

    /// Counters and the stream's lateness.
    pub fn stats(&self) -> DriverStats {
        let state = self.shared.lock();
        DriverStats { control_lateness: state.lateness.summary(), ..state.stats }
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.stop();
    }
}

fn io_thread(
    port: PathBuf,
    options: DriverOptions,
    shared: Arc<Shared>,
    requests: mpsc::UnboundedReceiver<Request>,
    init: std_mpsc::SyncSender<Result<(), KmcError>>,
) {
    let setup = || -> Result<(tokio::runtime::Runtime, SerialLink<ChassisFrameDecoder>), KmcError> {
        if let Some(cpu) = options.cpu_affinity {
            robowire_rt::pin_current_thread(cpu)?;
        }
        if let Some(priority) = options.realtime_priority {
            robowire_rt::set_realtime_priority(priority)?;
        }
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().map_err(KmcError::Thread)?;
        let decoder = ChassisFrameDecoder::new()
            .with_max_speed_mps(options.max_speed_mps)
            .map_err(|e| KmcError::Option { name: "max_speed_mps", reason: e.to_string() })?;
        let link = {
            let _entered = runtime.enter();
            SerialLink::open(&port, &options.serial, decoder)?
        };
        Ok((runtime, link))
    };
    let (runtime, link) = match setup() {
        Ok(ok) => ok,
        Err(e) => {
            let _ = init.send(Err(e));
            return;
        }
    };
    shared.lock().link_state = LinkState::Connected;
    let _ = init.send(Ok(()));
    runtime.block_on(IoLoop::new(link, options, shared, requests).run());
}

/// An absolute-deadline schedule: tick `k` is due at `start + k · period`.
#[derive(Debug)]
struct Schedule {
    next: Instant,
    period: Duration,
}

impl Schedule {
    fn new(start: Instant, hz: f64) -> Self {
        Self { next: start, period: Duration::from_secs_f64(1.0 / hz) }
    }

    /// Moves past `now`; returns how many whole ticks were skipped.
    fn advance(&mut self, now: Instant) -> u64 {
        self.next += self.period;
        let mut skipped = 0;
        while self.next <= now {
            self.next += self.period;
            skipped += 1;
        }
        skipped
    }
}

struct IoLoop {
    link: SerialLink<ChassisFrameDecoder>,
    options: DriverOptions,
    shared: Arc<Shared>,
    requests: mpsc::UnboundedReceiver<Request>,
    control: Schedule,
    speed: Schedule,
    battery: Option<Schedule>,
    all_state: Option<Schedule>,
    command_was_fresh: bool,
}

impl IoLoop {
    fn new(
        link: SerialLink<ChassisFrameDecoder>,
        options: DriverOptions,
        shared: Arc<Shared>,
        requests: mpsc::UnboundedReceiver<Request>,
    ) -> Self {
        let start = Instant::now();
        Self {
            control: Schedule::new(start, options.control_rate_hz),
            speed: Schedule::new(start, options.vehicle_speed_rate_hz),
            battery: options.poll_battery.then(|| Schedule::new(start, BATTERY_POLL_HZ)),
            all_state: options.poll_allstate.then(|| Schedule::new(start, ALL_STATE_POLL_HZ)),
            link,
            options,
            shared,
            requests,
            command_was_fresh: false,
        }
    }

    fn next_deadline(&self) -> Instant {
        [Some(&self.control), Some(&self.speed), self.battery.as_ref(), self.all_state.as_ref()]
            .into_iter()
            .flatten()
            .map(|s| s.next)
            .min()
            .unwrap_or(self.control.next)
    }

    async fn run(mut self) {
        loop {
            let flow = if self.link.is_open() {
                let deadline = self.next_deadline();
                // tokio's timer rounds up to whole milliseconds: wake early through it, then
                // finish with a precise sleep (this thread has no other task to starve).
                let coarse = deadline.checked_sub(TIMER_SLACK).unwrap_or(deadline);
                tokio::select! {
                    biased;
                    request = self.requests.recv() => self.handle(request).await,
                    () = tokio::time::sleep_until(coarse) => {
                        std::thread::sleep(deadline.saturating_duration_since(Instant::now()));
                        self.tick().await;
                        ControlFlow::Continue(())
                    }
                    frame = self.link.recv() => {
                        match frame {
                            Ok(frame) => self.enqueue(frame),
                            Err(_) => self.on_disconnect(),
                        }
                        ControlFlow::Continue(())
                    }
                }
            } else if let Some(backoff) = self.options.reopen {
                tokio::select! {
                    biased;
                    request = self.requests.recv() => self.handle(request).await,
                    reopened = self.link.reopen(&backoff) => {
                        if reopened.is_ok() {
                            self.on_reconnect();
                        }
                        ControlFlow::Continue(())
                    }
                }
            } else {
                // No reopening: wait for stop.
                let request = self.requests.recv().await;
                self.handle(request).await
            };
            if flow.is_break() {
                return;
            }
        }
    }

    /// A request from the [`Driver`]; `Break` ends the loop.
    async fn handle(&mut self, request: Option<Request>) -> ControlFlow<()> {
        match request {
            Some(Request::Stop(reply)) => {
                let _ = reply.send(self.stop_burst().await);
                ControlFlow::Break(())
            }
            // The Driver went away without stop(): still stop the chassis.
            None => {
                let _ = self.stop_burst().await;
                ControlFlow::Break(())
            }
            Some(Request::Battery(motor)) => {
                self.send_battery(motor).await;
                ControlFlow::Continue(())
            }
            Some(Request::AllState(motor)) => {
                self.send_all_state(motor).await;
                ControlFlow::Continue(())
            }
        }
    }

    async fn send(&mut self, frame: HostFrame) -> bool {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let Ok(len) = frame.emit(&mut buf) else { return false };
        match self.link.send(&buf[..len]).await {
            Ok(()) => true,
            Err(_) => {
                self.on_disconnect();
                false
            }
        }
    }

    async fn tick(&mut self) {
        let now = Instant::now();
        if self.control.next <= now {
            let lateness_us = u32::try_from(now.duration_since(self.control.next).as_micros()).unwrap_or(u32::MAX);
            let (command, fresh) = {
                let state = self.shared.lock();
                let timeout = self.options.command_timeout;
                let fresh = state.command_set_at.is_some_and(|at| now.saturating_duration_since(at) <= timeout);
                (if fresh { state.command } else { PcControl::STOP }, fresh)
            };
            let missed = self.control.advance(now);
            let sent = self.send(HostFrame::PcControl(command)).await;
            let mut state = self.shared.lock();
            state.stats.missed_ticks += missed;
            if sent {
                state.lateness.record(lateness_us);
                state.stats.control_frames_sent += 1;
                if !fresh {
                    state.stats.timeout_frames_sent += 1;
                    if self.command_was_fresh {
                        state.stats.command_timeouts += 1;
                    }
                }
            }
            self.command_was_fresh = fresh;
        }
        if self.speed.next <= now {
            self.speed.advance(now);
            if self.send(HostFrame::VehicleSpeedRequest).await {
                self.shared.lock().stats.speed_requests_sent += 1;
            }
        }
        if self.battery.as_ref().is_some_and(|s| s.next <= now) {
            if let Some(s) = self.battery.as_mut() {
                s.advance(now);
            }
            self.send_battery(0).await;
        }
        if self.all_state.as_ref().is_some_and(|s| s.next <= now) {
            if let Some(s) = self.all_state.as_mut() {
                s.advance(now);
            }
            self.send_all_state(0).await;
            self.send_all_state(1).await;
        }
        self.sync_link_counters();
    }

    async fn send_battery(&mut self, motor: u8) {
        if self.send(HostFrame::Af(AfFrame::battery_read(motor))).await {
            self.shared.lock().stats.battery_requests_sent += 1;
        }
    }

    async fn send_all_state(&mut self, motor: u8) {
        if self.send(HostFrame::Af(AfFrame::all_state_read(motor))).await {
            self.shared.lock().stats.all_state_requests_sent += 1;
        }
    }

    async fn stop_burst(&mut self) -> Result<(), SerialError> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = HostFrame::PcControl(PcControl::STOP).emit(&mut buf).unwrap_or(0);
        let mut result = Ok(());
        for _ in 0..self.options.stop_burst_count {
            match self.link.send(&buf[..len]).await {
                Ok(()) => self.shared.lock().stats.stop_frames_sent += 1,
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        self.sync_link_counters();
        result
    }

    fn enqueue(&mut self, frame: ChassisFrame) {
        let mut state = self.shared.lock();
        state.stats.frames_received += 1;
        if state.queue.len() >= self.options.max_queue {
            state.queue.pop_front();
            state.stats.queue_dropped += 1;
        }
        state.queue.push_back(frame);
        drop(state);
        self.shared.message_ready.notify_one();
    }

    fn sync_link_counters(&self) {
        self.shared.lock().stats.link = self.link.counters();
    }

    fn on_disconnect(&mut self) {
        let mut state = self.shared.lock();
        if state.link_state != LinkState::Disconnected {
            state.link_state = LinkState::Disconnected;
            state.stats.disconnects += 1;
        }
        state.stats.link = self.link.counters();
    }

    fn on_reconnect(&mut self) {
        let start = Instant::now();
        self.control = Schedule::new(start, self.options.control_rate_hz);
        self.speed = Schedule::new(start, self.options.vehicle_speed_rate_hz);
        self.battery = self.options.poll_battery.then(|| Schedule::new(start, BATTERY_POLL_HZ));
        self.all_state = self.options.poll_allstate.then(|| Schedule::new(start, ALL_STATE_POLL_HZ));
        let mut state = self.shared.lock();
        state.link_state = LinkState::Connected;
        state.stats.link = self.link.counters();
    }
}
