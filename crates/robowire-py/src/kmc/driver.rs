//! `robowire.kmc.Driver`: the vendor's start/stop driver over the facade's open/close shape.
//! `start()` opens a `kmc::Driver` with the options given at construction, `stop()` closes it
//! (stop burst); the Python object lives on across runs.

use std::collections::VecDeque;
use std::sync::{Mutex, RwLock, RwLockReadGuard, RwLockWriteGuard};
use std::time::{Duration, Instant};

use kmc::{ChassisFrame, ChassisState, Device, DriverOptions, LinkState, Placement, SerialPortOptions};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use robowire_rt::lock;

use super::{frame_to_py, raise, state_to_py};
use crate::errors::{Kind, chain, error};
use crate::record::{Capture, record_arg};
use crate::runtime::{self, seconds};
use crate::stats::{dict, lateness};

/// Where a `Driver` object is between `start()`, `stop()` and `close()`.
enum Run {
    /// Not streaming; what was still queued when it stopped.
    Stopped(Mutex<VecDeque<ChassisFrame>>),
    /// Open and streaming.
    Running(Box<kmc::Driver>),
    /// Closed for good.
    Closed,
}

/// A vendor-style option that is -1 for "off".
fn optional<T: TryFrom<i64>>(name: &str, value: i64, range: &str) -> PyResult<Option<T>> {
    if value == -1 {
        return Ok(None);
    }
    T::try_from(value).map(Some).map_err(|_| error(Kind::Argument, format!("{name} = {value}: -1 (off) or {range}")))
}

/// The chassis's streaming driver (the vendor's driver with its options and defaults): a
/// stream thread sends the latched command at `control_rate_hz` and polls the speed (and, if
/// asked, the battery and motor states); a receive thread keeps the chassis's state (speed,
/// battery, motors, odometry), queues what the chassis answers and reopens the port after a
/// disconnect. A command older than `command_timeout_ms` is replaced by (0, 0); `stop()` (and
/// the end of a `with` block, an exception included) sends `stop_burst_count` stop frames first.
///
/// ```python
/// with robowire.kmc.Driver("/dev/ttyUSB0") as chassis:
///     for _ in range(100):
///         chassis.set_command(0.5, 0.2)          # m/s, rad/s
///         for frame in chassis.messages(timeout_s=0.05):
///             print(frame)
///     print(chassis.state().odometry)
/// ```
#[pyclass(module = "robowire.kmc", frozen)]
pub(crate) struct Driver {
    run: RwLock<Run>,
    /// The options `start()` opens with (`set_command_timeout` changes them).
    options: Mutex<DriverOptions>,
    port: String,
    /// Finished by `close()`: every run between records into it.
    capture: Capture,
}

impl Driver {
    fn read(&self) -> RwLockReadGuard<'_, Run> {
        robowire_rt::sync::read(&self.run)
    }

    fn write(&self) -> RwLockWriteGuard<'_, Run> {
        robowire_rt::sync::write(&self.run)
    }

    /// `ClosedError` saying why there is no running driver.
    fn not_running(&self, closed: bool) -> PyErr {
        let why = if closed { "is closed" } else { "is stopped: start() opens it" };
        error(Kind::Closed, format!("the driver of {} {why}", self.port))
    }

    /// The running driver, or whether the object is closed (else stopped).
    fn running(run: &Run) -> Result<&kmc::Driver, bool> {
        match run {
            Run::Running(driver) => Ok(driver.as_ref()),
            Run::Stopped(_) => Err(false),
            Run::Closed => Err(true),
        }
    }

    /// A word `f` says of the running driver; `"stopped"` when stopped; `ClosedError` when
    /// closed.
    fn word(&self, f: impl FnOnce(&kmc::Driver) -> &'static str) -> PyResult<&'static str> {
        match Self::running(&self.read()) {
            Ok(driver) => Ok(f(driver)),
            Err(false) => Ok("stopped"),
            Err(true) => Err(self.not_running(true)),
        }
    }

    /// `f` on the running driver; `ClosedError` when stopped or closed.
    fn with<R>(&self, f: impl FnOnce(&kmc::Driver) -> R) -> PyResult<R> {
        Self::running(&self.read()).map(f).map_err(|closed| self.not_running(closed))
    }

    /// The oldest received frame, waiting up to `timeout` (Ctrl-C interrupts); once stopped,
    /// what was still queued, then `None`. The driver is locked one 50 ms slice at a time, so
    /// that `stop()` from another thread is not held up.
    fn wait_frame(&self, py: Python<'_>, timeout: Option<Duration>) -> PyResult<Option<ChassisFrame>> {
        /// What a slice found.
        enum Found {
            Frame(ChassisFrame),
            End,
            Closed,
        }
        let found = runtime::wait_sliced(py, timeout, |slice| match &*self.read() {
            Run::Running(driver) => driver.wait_pop_message(slice).map(Found::Frame),
            Run::Stopped(queued) => Some(lock(queued).pop_front().map_or(Found::End, Found::Frame)),
            Run::Closed => Some(Found::Closed),
        })?;
        match found {
            Some(Found::Frame(frame)) => Ok(Some(frame)),
            Some(Found::End) | None => Ok(None),
            Some(Found::Closed) => Err(self.not_running(true)),
        }
    }
}

#[pymethods]
impl Driver {
    /// A stopped driver for the chassis at `port`; `start()` (or `with`) opens it. Options
    /// are the vendor's, with its defaults; -1 keeps `realtime_priority` (`SCHED_FIFO` 1..99)
    /// and `cpu_affinity` off. Raises `ArgumentError` for an option out of range. `record` (not
    /// the vendor's): a path or a `robowire.Recorder` to record the line into (`kmc/serial`,
    /// and `kmc/serial_skipped`: the bytes the decoder skipped), from every `start()` to
    /// `stop()`; a path's capture is finished by `close()`.
    #[new]
    #[pyo3(signature = (port, *, control_rate_hz = 100.0, vehicle_speed_rate_hz = 50.0, poll_battery = false, poll_allstate = false, command_timeout_ms = 300, stop_burst_count = 3, realtime_priority = -1, cpu_affinity = -1, max_queue = 1024, lock_memory = false, max_speed_mps = 20.0, reopen = true, baud_rate = 115_200, record = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        port: String,
        control_rate_hz: f64,
        vehicle_speed_rate_hz: f64,
        poll_battery: bool,
        poll_allstate: bool,
        command_timeout_ms: u64,
        stop_burst_count: u32,
        realtime_priority: i64,
        cpu_affinity: i64,
        max_queue: usize,
        lock_memory: bool,
        max_speed_mps: f32,
        reopen: bool,
        baud_rate: u32,
        record: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let placement = Placement {
            realtime_priority: optional("realtime_priority", realtime_priority, "1..=99")?,
            cpu: optional("cpu_affinity", cpu_affinity, "a CPU index")?,
            lock_memory,
        };
        placement.validate().map_err(|e| {
            error(
                Kind::Argument,
                format!("realtime_priority = {realtime_priority}, cpu_affinity = {cpu_affinity}: {}", chain(&e)),
            )
        })?;
        let defaults = DriverOptions::default();
        let options = DriverOptions {
            serial: SerialPortOptions { baud_rate, ..defaults.serial.clone() },
            control_rate_hz,
            vehicle_speed_rate_hz,
            poll_battery,
            poll_allstate,
            command_timeout: Duration::from_millis(command_timeout_ms),
            stop_burst_count,
            placement,
            max_queue,
            reopen: if reopen { defaults.reopen } else { None },
            max_speed_mps,
            ..defaults
        };
        options.validate().map_err(raise)?;
        let (links, capture) = record_arg(record, "robowire.kmc.Driver")?;
        let options = DriverOptions {
            taps: links.map(|r| robowire_devices::kmc_taps(&r, &kmc_proto::description::HOST)).unwrap_or_default(),
            ..options
        };
        Ok(Self { run: RwLock::new(Run::Stopped(Mutex::default())), options: Mutex::new(options), port, capture })
    }

    /// The port path.
    #[getter]
    fn port(&self) -> &str {
        &self.port
    }

    /// Opens the port and starts streaming (nothing if it streams already). Raises `PortError`
    /// if the port cannot be opened.
    fn start(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| {
            let mut run = self.write();
            match &*run {
                Run::Running(driver) if driver.is_running() => return Ok(()),
                Run::Closed => return Err(self.not_running(true)),
                Run::Running(_) | Run::Stopped(_) => {}
            }
            // A driver whose thread ended by itself is closed before the port is opened again.
            if let Run::Running(ended) = std::mem::replace(&mut *run, Run::Stopped(Mutex::default())) {
                let _ = ended.close();
            }
            let options = lock(&self.options).clone();
            *run = Run::Running(Box::new(kmc::Driver::open(&self.port, options).map_err(raise)?));
            Ok(())
        })
    }

    /// Sends the stop burst, ends both threads and closes the port. Idempotent; `start()`
    /// opens it again. Raises `PortError` if the burst could not be sent (the chassis then
    /// stops on its own watchdog).
    fn stop(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| {
            let mut run = self.write();
            let Run::Running(driver) = &*run else { return Ok(()) };
            let queued: VecDeque<ChassisFrame> = std::iter::from_fn(|| driver.try_pop_message()).collect();
            match std::mem::replace(&mut *run, Run::Stopped(Mutex::new(queued))) {
                Run::Running(driver) => driver.close().map_err(raise),
                Run::Stopped(_) | Run::Closed => Ok(()),
            }
        })
    }

    /// Whether the threads are running.
    #[getter]
    fn is_running(&self) -> bool {
        matches!(&*self.read(), Run::Running(driver) if driver.is_running())
    }

    /// `"stopped"`, `"connected"` or `"disconnected"` (the port vanished; reopening).
    #[getter]
    fn link_state(&self) -> PyResult<&'static str> {
        self.word(|driver| match driver.link_state() {
            LinkState::Stopped => "stopped",
            LinkState::Connected => "connected",
            LinkState::Disconnected => "disconnected",
        })
    }

    /// `"stopped"`, `"waiting"` (no frame from the chassis yet), `"connected"` or
    /// `"disconnected"` (silent for 500 ms, or the port vanished).
    #[getter]
    fn connection(&self) -> PyResult<&'static str> {
        self.word(|driver| driver.connection().name())
    }

    /// Streams `velocity_mps` forward and `yaw_rate_radps`, as the vendor maps them: curvature
    /// = yaw rate / velocity for |velocity| > 1 mm/s, else 0 (the chassis cannot turn in
    /// place). NaN and infinities raise `ArgumentError`; the previous command stays. Raises
    /// `ClosedError` unless started.
    fn set_command(&self, velocity_mps: f32, yaw_rate_radps: f32) -> PyResult<()> {
        self.with(|d| d.set_command(velocity_mps, yaw_rate_radps))?.map_err(raise)
    }

    /// Streams `velocity_mps` and `curvature_per_m` directly.
    fn set_command_curvature(&self, velocity_mps: f32, curvature_per_m: f32) -> PyResult<()> {
        self.with(|d| d.set_command_curvature(velocity_mps, curvature_per_m))?.map_err(raise)
    }

    /// Sets the command timeout (0.001–3600 s), now and for the next `start()`: a command not
    /// refreshed within it is replaced by (0, 0).
    fn set_command_timeout(&self, timeout_s: f64) -> PyResult<()> {
        let timeout = seconds("timeout_s", timeout_s)?;
        let mut options = lock(&self.options);
        let changed = DriverOptions { command_timeout: timeout, ..options.clone() };
        changed.validate().map_err(raise)?;
        if let Run::Running(driver) = &*self.read() {
            driver.set_command_timeout(timeout).map_err(raise)?;
        }
        *options = changed;
        Ok(())
    }

    /// The chassis as last heard (`ChassisState`: speed, battery, motors, odometry). Raises
    /// `NoStateError` before its first frame.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let latest = self.with(|d| d.latest())?;
        let latest =
            latest.ok_or_else(|| error(Kind::NoState, format!("no frame from the chassis at {} yet", self.port)))?;
        state_to_py(py, &latest.state)
    }

    /// Seconds since the latest frame arrived (`None` before the first).
    #[getter]
    fn state_age_s(&self) -> PyResult<Option<f64>> {
        self.with(|d| d.latest().map(|s| s.age().as_secs_f64()))
    }

    /// The chassis's state, waiting up to `timeout_s` for its first frame; raises
    /// `TimeoutError` if none came. Ctrl-C interrupts.
    #[pyo3(signature = (timeout_s = 3.0))]
    fn wait_state<'py>(&self, py: Python<'py>, timeout_s: f64) -> PyResult<Bound<'py, PyAny>> {
        let timeout = seconds("timeout_s", timeout_s)?;
        let outcome = runtime::wait_sliced(py, Some(timeout), |slice| match Self::running(&self.read()) {
            Ok(driver) => driver.wait_state(slice, |_: &ChassisState| true).map(Ok),
            Err(closed) => Some(Err(closed)),
        })?;
        match outcome {
            Some(Ok(state)) => state_to_py(py, &state),
            Some(Err(closed)) => Err(self.not_running(closed)),
            None => {
                Err(error(Kind::Timeout, format!("no frame from the chassis at {} within {timeout_s} s", self.port)))
            }
        }
    }

    /// The oldest received frame, or `None`.
    fn try_pop_message<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.wait_frame(py, Some(Duration::ZERO))?.map(|f| frame_to_py(py, &f)).transpose()
    }

    /// The oldest received frame, waiting up to `timeout_s` for one (`None` if none came).
    #[pyo3(signature = (timeout_s = 1.0))]
    fn wait_message<'py>(&self, py: Python<'py>, timeout_s: f64) -> PyResult<Option<Bound<'py, PyAny>>> {
        let timeout = seconds("timeout_s", timeout_s)?;
        self.wait_frame(py, Some(timeout))?.map(|f| frame_to_py(py, &f)).transpose()
    }

    /// Received frames as they arrive, for `timeout_s` from now (`None`: until the driver is
    /// stopped or Ctrl-C). Iterate it between two `set_command` calls so that a steady flow of
    /// answers cannot starve the command (which then times out and stops the chassis).
    #[pyo3(signature = (timeout_s = None))]
    fn messages(slf: Py<Self>, timeout_s: Option<f64>) -> PyResult<Messages> {
        let deadline = runtime::timeout("timeout_s", timeout_s)?.map(|t| Instant::now() + t);
        Ok(Messages { driver: slf, deadline })
    }

    /// Sends one battery read to `motor_id` now; the answer arrives as a `BatteryVoltage` and
    /// in the state.
    #[pyo3(signature = (motor_id = 0))]
    fn request_battery_once(&self, motor_id: u8) -> PyResult<()> {
        self.with(|d| d.request_battery_once(motor_id))?.map_err(raise)
    }

    /// Sends one all-state read to `motor_id` now; the answer arrives as a `MotorState` and in
    /// the state.
    #[pyo3(signature = (motor_id = 0))]
    fn request_all_state_once(&self, motor_id: u8) -> PyResult<()> {
        self.with(|d| d.request_all_state_once(motor_id))?.map_err(raise)
    }

    /// Frames sent and received, timeouts, queue drops, disconnects, stream lateness (of the
    /// current run).
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.with(|d| d.stats())?;
        Ok(dict!(py, {
            "control_frames_sent" => s.control_frames_sent,
            "timeout_frames_sent" => s.timeout_frames_sent,
            "command_timeouts" => s.command_timeouts,
            "stop_frames_sent" => s.stop_frames_sent,
            "speed_requests_sent" => s.speed_requests_sent,
            "battery_requests_sent" => s.battery_requests_sent,
            "all_state_requests_sent" => s.all_state_requests_sent,
            "frames_received" => s.frames_received,
            "queue_dropped" => s.queue_dropped,
            "missed_ticks" => s.missed_ticks,
            "write_errors" => s.write_errors,
            "disconnects" => s.disconnects,
            "state_timeouts" => s.state_timeouts,
            "bytes_written" => s.link.bytes_written,
            "bytes_read" => s.link.bytes_read,
            "bytes_skipped" => s.link.decoder.skipped_bytes,
            "rejected_candidates" => s.link.decoder.rejected_candidates,
            "reopens" => s.link.reopens,
            "control_lateness_us" => lateness(py, &s.control_lateness)?,
        }))
    }

    /// Stops (stop burst) and releases the port for good, then finishes the capture of
    /// `record=PATH`.
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        let run = py.detach(|| std::mem::replace(&mut *self.write(), Run::Closed));
        let closed = match run {
            Run::Running(driver) => py.detach(move || driver.close()).map_err(raise),
            Run::Stopped(_) | Run::Closed => Ok(()),
        };
        let finished = self.capture.finish(py);
        closed.and(finished)
    }

    /// Starts the driver unless it runs already.
    fn __enter__(slf: Py<Self>, py: Python<'_>) -> PyResult<Py<Self>> {
        slf.get().start(py)?;
        Ok(slf)
    }

    /// Stops the chassis (stop burst), an exception in the block included.
    #[pyo3(signature = (*_exc))]
    fn __exit__(&self, py: Python<'_>, _exc: &Bound<'_, PyTuple>) -> PyResult<()> {
        self.stop(py)
    }

    fn __repr__(&self) -> String {
        format!("Driver({:?}, running={})", self.port, self.is_running())
    }
}

/// The iterator of `Driver.messages()`.
#[pyclass(module = "robowire.kmc")]
pub(crate) struct Messages {
    driver: Py<Driver>,
    deadline: Option<Instant>,
}

#[pymethods]
impl Messages {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let timeout = self.deadline.map(|d| d.saturating_duration_since(Instant::now()));
        if timeout.is_some_and(|t| t.is_zero()) {
            return Ok(None);
        }
        self.driver.get().wait_frame(py, timeout)?.map(|f| frame_to_py(py, &f)).transpose()
    }
}
