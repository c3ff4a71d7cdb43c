//! `UartClient`: one call, one frame. The vendor's low-level client, async, plus a blocking
//! wrapper.

use std::path::Path;
use std::time::Duration;

use kmc_proto::{AfFrame, ChassisFrame, ChassisFrameDecoder, HostFrame, MAX_FRAME_LEN, PcControl};
use robowire_serial::{LinkCounters, SerialLink, SerialPortOptions};

use crate::KmcError;
use robowire_core::finite;
use robowire_rt::RtError;

/// Sends single frames to a KMC chassis and receives its responses.
///
/// Requests are fire-and-forget, as on the wire (the protocol has no acknowledgement); responses
/// arrive through [`poll`](Self::poll) in the order the chassis sent them. Float arguments are
/// checked for NaN and infinity before anything is sent.
#[derive(Debug)]
pub struct UartClient {
    link: SerialLink<ChassisFrameDecoder>,
}

impl UartClient {
    /// Opens the serial port. Must be called inside a tokio runtime.
    pub fn open(path: impl AsRef<Path>, options: &SerialPortOptions) -> Result<Self, KmcError> {
        Ok(Self::from_link(SerialLink::open(path, options, ChassisFrameDecoder::new())?))
    }

    /// Wraps an open link (to share one transport configuration).
    pub fn from_link(link: SerialLink<ChassisFrameDecoder>) -> Self {
        Self { link }
    }

    /// The link underneath (counters, [`reopen`](SerialLink::reopen)).
    pub fn link_mut(&mut self) -> &mut SerialLink<ChassisFrameDecoder> {
        &mut self.link
    }

    /// Bytes, frames and decoder counters.
    pub fn counters(&self) -> LinkCounters {
        self.link.counters()
    }

    /// Sends any host frame.
    pub async fn send(&mut self, frame: &HostFrame) -> Result<(), KmcError> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = frame.emit(&mut buf)?;
        Ok(self.link.send(&buf[..len]).await?)
    }

    /// `0xA5`: drive at `velocity_mps` on a path of curvature `curvature_per_m`.
    pub async fn send_pc_control(&mut self, velocity_mps: f32, curvature_per_m: f32) -> Result<(), KmcError> {
        let command = PcControl {
            velocity_mps: finite("velocity_mps", velocity_mps)?,
            curvature_per_m: finite("curvature_per_m", curvature_per_m)?,
        };
        self.send(&HostFrame::PcControl(command)).await
    }

    /// `0xB3`: ask for the vehicle speed; the answer is a [`ChassisFrame::VehicleSpeed`].
    pub async fn request_vehicle_speed(&mut self) -> Result<(), KmcError> {
        self.send(&HostFrame::VehicleSpeedRequest).await
    }

    /// `0xAF` read of ID 0x06; the answer is a [`ChassisFrame::AllState`].
    pub async fn request_all_state(&mut self, motor_id: u8) -> Result<(), KmcError> {
        self.send(&HostFrame::Af(AfFrame::all_state_read(motor_id))).await
    }

    /// `0xAF` read of ID 0x07; the answer is a [`ChassisFrame::BatteryVoltage`].
    pub async fn request_battery_voltage(&mut self, motor_id: u8) -> Result<(), KmcError> {
        self.send(&HostFrame::Af(AfFrame::battery_read(motor_id))).await
    }

    /// `0xAF` write of ID 0x03: motor speed in electrical RPM. No response.
    pub async fn write_speed_erpm(&mut self, motor_id: u8, erpm: f32) -> Result<(), KmcError> {
        let erpm = finite("erpm", erpm)?;
        self.send(&HostFrame::Af(AfFrame::speed_write_erpm(motor_id, erpm))).await
    }

    /// `0xAF` write of ID 0x05: servo pulse width, µs. No response.
    pub async fn write_servo_pulse_us(&mut self, motor_id: u8, pulse_us: f32) -> Result<(), KmcError> {
        let pulse_us = finite("pulse_us", pulse_us)?;
        self.send(&HostFrame::Af(AfFrame::servo_pulse_write_us(motor_id, pulse_us))).await
    }

    /// `0xAF` write of ID 0x00 (value 0.0): reset the motor controller. No response.
    pub async fn system_reset(&mut self, motor_id: u8) -> Result<(), KmcError> {
        self.send(&HostFrame::Af(AfFrame::system_reset(motor_id))).await
    }

    /// The next frame from the chassis, or `None` if none arrived within `timeout`.
    pub async fn poll(&mut self, timeout: Duration) -> Result<Option<ChassisFrame>, KmcError> {
        match tokio::time::timeout(timeout, self.link.recv()).await {
            Ok(frame) => Ok(Some(frame?)),
            Err(_elapsed) => Ok(None),
        }
    }
}

/// [`UartClient`] for code without an async runtime: each call blocks until done.
#[derive(Debug)]
pub struct BlockingUartClient {
    runtime: tokio::runtime::Runtime,
    client: UartClient,
}

impl BlockingUartClient {
    /// Opens the serial port, with a private single-threaded runtime.
    pub fn open(path: impl AsRef<Path>, options: &SerialPortOptions) -> Result<Self, KmcError> {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .map_err(|source| RtError::Thread { name: "kmc-uart".into(), source })?;
        let client = {
            let _entered = runtime.enter();
            UartClient::open(path, options)?
        };
        Ok(Self { runtime, client })
    }

    /// The async client inside.
    pub fn client_mut(&mut self) -> &mut UartClient {
        &mut self.client
    }

    /// See [`UartClient::send_pc_control`].
    pub fn send_pc_control(&mut self, velocity_mps: f32, curvature_per_m: f32) -> Result<(), KmcError> {
        self.runtime.block_on(self.client.send_pc_control(velocity_mps, curvature_per_m))
    }

    /// See [`UartClient::request_vehicle_speed`].
    pub fn request_vehicle_speed(&mut self) -> Result<(), KmcError> {
        self.runtime.block_on(self.client.request_vehicle_speed())
    }

    /// See [`UartClient::request_all_state`].
    pub fn request_all_state(&mut self, motor_id: u8) -> Result<(), KmcError> {
        self.runtime.block_on(self.client.request_all_state(motor_id))
    }

    /// See [`UartClient::request_battery_voltage`].
    pub fn request_battery_voltage(&mut self, motor_id: u8) -> Result<(), KmcError> {
        self.runtime.block_on(self.client.request_battery_voltage(motor_id))
    }

    /// See [`UartClient::write_speed_erpm`].
    pub fn write_speed_erpm(&mut self, motor_id: u8, erpm: f32) -> Result<(), KmcError> {
        self.runtime.block_on(self.client.write_speed_erpm(motor_id, erpm))
    }

    /// See [`UartClient::write_servo_pulse_us`].
    pub fn write_servo_pulse_us(&mut self, motor_id: u8, pulse_us: f32) -> Result<(), KmcError> {
        self.runtime.block_on(self.client.write_servo_pulse_us(motor_id, pulse_us))
    }

    /// See [`UartClient::system_reset`].
    pub fn system_reset(&mut self, motor_id: u8) -> Result<(), KmcError> {
        self.runtime.block_on(self.client.system_reset(motor_id))
    }

    /// See [`UartClient::poll`].
    pub fn poll(&mut self, timeout: Duration) -> Result<Option<ChassisFrame>, KmcError> {
        self.runtime.block_on(self.client.poll(timeout))
    }
}
