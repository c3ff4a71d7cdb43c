//! `robowire.kmc.UartClient`: one frame at a time over the serial port, no threads.

use kmc::{BlockingUartClient, SerialPortOptions};
use pyo3::prelude::*;

use super::{frame_to_py, raise};
use crate::owned::{Owned, closeable};
use crate::runtime::{self, seconds};

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
