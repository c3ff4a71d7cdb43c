//! `robowire.kmc`: the KMC chassis's streaming `Driver` and the one-frame-at-a-time
//! `UartClient`, over the `kmc` facade. Frames from the chassis become the dataclasses of
//! `robowire/kmc.py`.

use std::sync::{PoisonError, RwLock, RwLockReadGuard};
use std::time::Duration;

use kmc::{BlockingUartClient, ChassisFrame, DriverOptions, KmcError, LinkState, SerialPortOptions};
use kmc_proto::Rw;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBytes, PyDict, PyTuple};

use crate::errors::{Kind, chain, error};
use crate::owned::{Owned, closeable};
use crate::runtime::{self, seconds};
use crate::stats::{dict, lateness};

/// A `KmcError` as the exception a Python user expects.
fn raise(e: KmcError) -> PyErr {
    let kind = match &e {
        KmcError::Argument(_) | KmcError::Option { .. } => Kind::Argument,
        KmcError::Link(_) => Kind::Port,
        KmcError::NotRunning => Kind::Closed,
        _ => Kind::Error,
    };
    error(kind, chain(&e))
}

static FRAME_CLASSES: PyOnceLock<[Py<PyAny>; 4]> = PyOnceLock::new();

/// A frame from the chassis as `robowire.kmc.VehicleSpeed`, `BatteryVoltage`, `MotorState` or
/// `AfResponse`.
fn frame_to_py<'py>(py: Python<'py>, frame: &ChassisFrame) -> PyResult<Bound<'py, PyAny>> {
    let [speed, battery, motor, af] = FRAME_CLASSES
        .get_or_try_init(py, || -> PyResult<_> {
            let m = py.import("robowire.kmc")?;
            let class = |name: &str| -> PyResult<Py<PyAny>> { Ok(m.getattr(name)?.unbind()) };
            Ok([class("VehicleSpeed")?, class("BatteryVoltage")?, class("MotorState")?, class("AfResponse")?])
        })?
        .each_ref()
        .map(|c| c.bind(py));
    match frame {
        ChassisFrame::VehicleSpeed(v) => speed.call1((f64::from(v.speed_mps),)),
        ChassisFrame::BatteryVoltage(b) => battery.call1((b.motor_id, f64::from(b.volts))),
        ChassisFrame::AllState(s) => motor.call1((
            s.motor_id,
            s.id,
            f64::from(s.position_deg),
            f64::from(s.speed_rpm),
            f64::from(s.current_a),
            f64::from(s.temperature_c),
            s.error_code,
            PyTuple::new(py, s.reserved.map(f64::from))?,
        )),
        ChassisFrame::Af(f) => {
            let ids: Vec<u8> = f.ids().iter().map(|id| id.to_byte()).collect();
            let slots: Vec<Bound<'py, PyBytes>> = f.slots().iter().map(|s| PyBytes::new(py, s)).collect();
            let rw = if f.rw() == Rw::Read { "read" } else { "write" };
            af.call1((f.motor_id(), rw, PyTuple::new(py, ids)?, PyTuple::new(py, slots)?))
        }
    }
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
/// asked, the battery and motor states); a receive thread queues what the chassis answers and
/// reopens the port after a disconnect. A command older than `command_timeout_ms` is replaced
/// by (0, 0); `stop()` (and the end of a `with` block, an exception included) sends
/// `stop_burst_count` stop frames first.
///
/// ```python
/// with robowire.kmc.Driver("/dev/ttyUSB0") as chassis:
///     for _ in range(100):
///         chassis.set_command(0.5, 0.2)          # m/s, rad/s
///         for frame in chassis.messages(timeout_s=0.05):
///             print(frame)
/// ```
#[pyclass(module = "robowire.kmc", frozen)]
pub(crate) struct Driver {
    driver: RwLock<Option<kmc::Driver>>,
    port: String,
}

impl Driver {
    fn read(&self) -> PyResult<RwLockReadGuard<'_, Option<kmc::Driver>>> {
        let guard = self.driver.read().unwrap_or_else(PoisonError::into_inner);
        if guard.is_none() {
            return Err(error(Kind::Closed, format!("the driver of {} is closed", self.port)));
        }
        Ok(guard)
    }

    fn with<R>(&self, f: impl FnOnce(&kmc::Driver) -> R) -> PyResult<R> {
        let guard = self.read()?;
        Ok(f(guard.as_ref().expect("checked by read()")))
    }

    /// The oldest received frame, waiting up to `timeout` (Ctrl-C interrupts).
    fn wait_frame(&self, py: Python<'_>, timeout: Option<Duration>) -> PyResult<Option<ChassisFrame>> {
        let guard = self.read()?;
        let Some(driver) = guard.as_ref() else { return Ok(None) };
        runtime::wait_sliced(py, timeout, |slice| driver.wait_pop_message(slice))
    }
}

#[pymethods]
impl Driver {
    /// A stopped driver for the chassis at `port`; `start()` (or `with`) opens it. Options
    /// are the vendor's, with its defaults; -1 keeps `realtime_priority` (`SCHED_FIFO` 1..99)
    /// and `cpu_affinity` off. Raises `ArgumentError` for an option out of range.
    #[new]
    #[pyo3(signature = (port, *, control_rate_hz = 100.0, vehicle_speed_rate_hz = 50.0, poll_battery = false, poll_allstate = false, command_timeout_ms = 300, stop_burst_count = 3, realtime_priority = -1, cpu_affinity = -1, max_queue = 1024, lock_memory = false, max_speed_mps = 20.0, reopen = true, baud_rate = 115_200))]
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
    ) -> PyResult<Self> {
        let defaults = DriverOptions::default();
        let options = DriverOptions {
            serial: SerialPortOptions { baud_rate, ..defaults.serial.clone() },
            control_rate_hz,
            vehicle_speed_rate_hz,
            poll_battery,
            poll_allstate,
            command_timeout: Duration::from_millis(command_timeout_ms),
            stop_burst_count,
            realtime_priority: optional("realtime_priority", realtime_priority, "1..=99")?,
            cpu_affinity: optional("cpu_affinity", cpu_affinity, "a CPU index")?,
            lock_memory,
            max_queue,
            reopen: if reopen { defaults.reopen } else { None },
            max_speed_mps,
        };
        let driver = kmc::Driver::new(&port, options).map_err(raise)?;
        Ok(Self { driver: RwLock::new(Some(driver)), port })
    }

    /// The port path.
    #[getter]
    fn port(&self) -> &str {
        &self.port
    }

    /// Opens the port and starts streaming. Raises `PortError` if the port cannot be opened.
    fn start(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| {
            let mut guard = self.driver.write().unwrap_or_else(PoisonError::into_inner);
            match guard.as_mut() {
                Some(driver) => driver.start().map_err(raise),
                None => Err(error(Kind::Closed, format!("the driver of {} is closed", self.port))),
            }
        })
    }

    /// Sends the stop burst and ends both threads. Idempotent; `start()` starts again. Raises
    /// `PortError` if the burst could not be sent (the chassis then stops on its own watchdog).
    fn stop(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| {
            let mut guard = self.driver.write().unwrap_or_else(PoisonError::into_inner);
            guard.as_mut().map_or(Ok(()), |d| d.stop().map_err(raise))
        })
    }

    /// Whether the threads are running.
    #[getter]
    fn is_running(&self) -> bool {
        self.with(kmc::Driver::is_running).unwrap_or(false)
    }

    /// `"stopped"`, `"connected"` or `"disconnected"` (reopening).
    #[getter]
    fn link_state(&self) -> PyResult<&'static str> {
        self.with(|d| match d.link_state() {
            LinkState::Stopped => "stopped",
            LinkState::Connected => "connected",
            LinkState::Disconnected => "disconnected",
        })
    }

    /// Streams `velocity_mps` forward and `yaw_rate_radps`, as the vendor maps them: curvature
    /// = yaw rate / velocity for |velocity| > 1 mm/s, else 0 (the chassis cannot turn in
    /// place). NaN and infinities raise `ArgumentError`; the previous command stays.
    fn set_command(&self, velocity_mps: f32, yaw_rate_radps: f32) -> PyResult<()> {
        self.with(|d| d.set_command(velocity_mps, yaw_rate_radps))?.map_err(raise)
    }

    /// Streams `velocity_mps` and `curvature_per_m` directly.
    fn set_command_curvature(&self, velocity_mps: f32, curvature_per_m: f32) -> PyResult<()> {
        self.with(|d| d.set_command_curvature(velocity_mps, curvature_per_m))?.map_err(raise)
    }

    /// The oldest received frame, or `None`.
    fn try_pop_message<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.with(kmc::Driver::try_pop_message)?.map(|f| frame_to_py(py, &f)).transpose()
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
        let deadline = runtime::timeout("timeout_s", timeout_s)?.map(|t| std::time::Instant::now() + t);
        Ok(Messages { driver: slf, deadline })
    }

    /// Sends one battery read to `motor_id` now; the answer arrives as a `BatteryVoltage`.
    #[pyo3(signature = (motor_id = 0))]
    fn request_battery_once(&self, motor_id: u8) -> PyResult<()> {
        self.with(|d| d.request_battery_once(motor_id))?.map_err(raise)
    }

    /// Sends one all-state read to `motor_id` now; the answer arrives as a `MotorState`.
    #[pyo3(signature = (motor_id = 0))]
    fn request_all_state_once(&self, motor_id: u8) -> PyResult<()> {
        self.with(|d| d.request_all_state_once(motor_id))?.map_err(raise)
    }

    /// Frames sent and received, timeouts, queue drops, disconnects, stream lateness.
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.with(kmc::Driver::stats)?;
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
            "bytes_written" => s.link.bytes_written,
            "bytes_read" => s.link.bytes_read,
            "bytes_skipped" => s.link.decoder.skipped_bytes,
            "rejected_candidates" => s.link.decoder.rejected_candidates,
            "reopens" => s.link.reopens,
            "control_lateness_us" => lateness(py, &s.control_lateness)?,
        }))
    }

    /// Stops (stop burst) and releases the port for good.
    fn close(&self, py: Python<'_>) -> PyResult<()> {
        let driver = py.detach(|| self.driver.write().unwrap_or_else(PoisonError::into_inner).take());
        match driver {
            Some(mut driver) => py.detach(move || driver.stop()).map_err(raise),
            None => Ok(()),
        }
    }

    /// Starts the driver unless it runs already.
    fn __enter__(slf: Py<Self>, py: Python<'_>) -> PyResult<Py<Self>> {
        if !slf.get().is_running() {
            slf.get().start(py)?;
        }
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
    deadline: Option<std::time::Instant>,
}

#[pymethods]
impl Messages {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let timeout = self.deadline.map(|d| d.saturating_duration_since(std::time::Instant::now()));
        if timeout.is_some_and(|t| t.is_zero()) {
            return Ok(None);
        }
        let driver = self.driver.get();
        if !driver.is_running() {
            // A stopped driver ends the iteration after what is queued.
            return driver.try_pop_message(py);
        }
        driver.wait_frame(py, timeout)?.map(|f| frame_to_py(py, &f)).transpose()
    }
}

/// One frame at a time over the serial port, no threads: send a frame, poll for one. For the
/// streaming behaviour (command refresh, timeout, stop burst) use `Driver`.
#[pyclass(module = "robowire.kmc", frozen)]
pub(crate) struct UartClient {
    client: Owned<BlockingUartClient>,
    port: String,
}

#[pymethods]
impl UartClient {
    /// Opens `port` (115200 8N1, RTS/CTS). Raises `PortError` if it cannot be opened.
    #[new]
    #[pyo3(signature = (port, *, baud_rate = 115_200))]
    fn new(py: Python<'_>, port: String, baud_rate: u32) -> PyResult<Self> {
        let options = SerialPortOptions { baud_rate, ..SerialPortOptions::default() };
        let client = py.detach(|| BlockingUartClient::open(&port, &options)).map_err(raise)?;
        Ok(Self { client: Owned::new("UART client", client), port })
    }

    /// The port path.
    #[getter]
    fn port(&self) -> &str {
        &self.port
    }

    /// Sends one 0xA5 control frame: `velocity_mps`, `curvature_per_m` (finite).
    fn send_pc_control(&self, py: Python<'_>, velocity_mps: f32, curvature_per_m: f32) -> PyResult<()> {
        py.detach(|| self.client.with(|c| c.send_pc_control(velocity_mps, curvature_per_m)))?.map_err(raise)
    }

    /// Sends a 0xB3 speed request; the answer arrives as a `VehicleSpeed`.
    fn request_vehicle_speed(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| self.client.with(BlockingUartClient::request_vehicle_speed))?.map_err(raise)
    }

    /// Reads the battery of `motor_id`; the answer arrives as a `BatteryVoltage`.
    #[pyo3(signature = (motor_id = 0))]
    fn request_battery_voltage(&self, py: Python<'_>, motor_id: u8) -> PyResult<()> {
        py.detach(|| self.client.with(|c| c.request_battery_voltage(motor_id)))?.map_err(raise)
    }

    /// Reads all state of `motor_id`; the answer arrives as a `MotorState`.
    #[pyo3(signature = (motor_id = 0))]
    fn request_all_state(&self, py: Python<'_>, motor_id: u8) -> PyResult<()> {
        py.detach(|| self.client.with(|c| c.request_all_state(motor_id)))?.map_err(raise)
    }

    /// Writes a speed command to `motor_id`, ERPM.
    fn write_speed_erpm(&self, py: Python<'_>, motor_id: u8, erpm: f32) -> PyResult<()> {
        py.detach(|| self.client.with(|c| c.write_speed_erpm(motor_id, erpm)))?.map_err(raise)
    }

    /// Writes a servo pulse width to `motor_id`, µs.
    fn write_servo_pulse_us(&self, py: Python<'_>, motor_id: u8, pulse_us: f32) -> PyResult<()> {
        py.detach(|| self.client.with(|c| c.write_servo_pulse_us(motor_id, pulse_us)))?.map_err(raise)
    }

    /// Resets `motor_id`'s controller.
    fn system_reset(&self, py: Python<'_>, motor_id: u8) -> PyResult<()> {
        py.detach(|| self.client.with(|c| c.system_reset(motor_id)))?.map_err(raise)
    }

    /// The next frame from the chassis, waiting up to `timeout_s` (`None` if none came).
    #[pyo3(signature = (timeout_s = 1.0))]
    fn poll<'py>(&self, py: Python<'py>, timeout_s: f64) -> PyResult<Option<Bound<'py, PyAny>>> {
        let timeout = seconds("timeout_s", timeout_s)?;
        let frame = runtime::wait_sliced(py, Some(timeout), |slice| match self.client.with(|c| c.poll(slice)) {
            Ok(Ok(None)) => None,
            other => Some(other),
        })?;
        match frame {
            None => Ok(None),
            Some(result) => result?.map_err(raise)?.map(|f| frame_to_py(py, &f)).transpose(),
        }
    }
}

closeable!(UartClient, client, "Closes the port. Idempotent.");

/// Adds the classes to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Driver>()?;
    m.add_class::<Messages>()?;
    m.add_class::<UartClient>()?;
    Ok(())
}
