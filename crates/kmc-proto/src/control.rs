//! 0xA5 control command and 0xB3 vehicle speed (spec §3.1, §3.2).

use robowire_core::le::{LeWriter, f32_at};

use crate::{DecodeError, EncodeError, FRAME_ID_CONTROL, FRAME_ID_SPEED};

/// Below this |velocity| (m/s) the vendor driver drops the yaw rate: curvature is 0 (spec §4.2).
pub const CURVATURE_VELOCITY_THRESHOLD_MPS: f32 = 1e-3;

/// `0xA5` PC control command, host → chassis, 9 bytes, no response (spec §3.1).
///
/// | offset | type | field |
/// |---:|---|---|
/// | 0 | u8 | `0xA5` |
/// | 1 | f32 | `velocity_mps` |
/// | 5 | f32 | `curvature_per_m` (vendor `curvature_1pm`) |
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PcControl {
    /// Forward velocity, m/s; negative reverses.
    pub velocity_mps: f32,
    /// Path curvature, 1/m (the inverse turning radius); 0 drives straight.
    pub curvature_per_m: f32,
}

impl PcControl {
    /// Frame length in bytes.
    pub const LEN: usize = 9;
    /// Stop: (0, 0), sent after a command timeout and in the stop burst.
    pub const STOP: Self = Self { velocity_mps: 0.0, curvature_per_m: 0.0 };

    /// The vendor driver's `setCommand(v, omega)` mapping (spec §4.2):
    /// `curvature = omega / v` when `|v| > 1e-3` m/s, else 0 (the chassis cannot turn in place).
    ///
    /// Non-finite arguments are refused with the offset their value would have had.
    ///
    /// ```
    /// # use kmc_proto::PcControl;
    /// let c = PcControl::from_yaw_rate(-0.25, 0.5).unwrap();
    /// assert_eq!((c.velocity_mps, c.curvature_per_m), (-0.25, -2.0));
    /// assert_eq!(PcControl::from_yaw_rate(0.0005, 1.0).unwrap().curvature_per_m, 0.0);
    /// assert!(PcControl::from_yaw_rate(f32::NAN, 0.0).is_err());
    /// ```
    pub fn from_yaw_rate(velocity_mps: f32, yaw_rate_radps: f32) -> Result<Self, EncodeError> {
        if !velocity_mps.is_finite() {
            return Err(EncodeError::NonFinite { offset: 1 });
        }
        if !yaw_rate_radps.is_finite() {
            return Err(EncodeError::NonFinite { offset: 5 });
        }
        let curvature_per_m =
            if velocity_mps.abs() > CURVATURE_VELOCITY_THRESHOLD_MPS { yaw_rate_radps / velocity_mps } else { 0.0 };
        let command = Self { velocity_mps, curvature_per_m };
        // |v| > 1e-3 bounds the quotient, but a huge yaw rate can still overflow to infinity.
        match command.non_finite_offset() {
            Some(offset) => Err(EncodeError::NonFinite { offset }),
            None => Ok(command),
        }
    }

    /// The yaw rate this command produces, rad/s (`velocity · curvature`).
    pub fn yaw_rate_radps(&self) -> f32 {
        self.velocity_mps * self.curvature_per_m
    }

    /// Offset of the first non-finite field, if any.
    pub(crate) fn non_finite_offset(&self) -> Option<usize> {
        if !self.velocity_mps.is_finite() {
            Some(1)
        } else if !self.curvature_per_m.is_finite() {
            Some(5)
        } else {
            None
        }
    }

    /// Writes the 9-byte frame; refuses NaN and infinities.
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        if let Some(offset) = self.non_finite_offset() {
            return Err(EncodeError::NonFinite { offset });
        }
        let mut w = LeWriter::new(buf);
        w.put_u8(FRAME_ID_CONTROL)?;
        w.put_f32(self.velocity_mps)?;
        w.put_f32(self.curvature_per_m)?;
        Ok(w.written())
    }

    /// Reads the fields of a frame whose ID byte has been checked; `None` if short.
    pub(crate) fn read(bytes: &[u8]) -> Option<Self> {
        Some(Self { velocity_mps: f32_at(bytes, 1)?, curvature_per_m: f32_at(bytes, 5)? })
    }
}

/// `0xB3` vehicle speed request, host → chassis, the single byte `0xB3` (spec §3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VehicleSpeedRequest;

impl VehicleSpeedRequest {
    /// Frame length in bytes.
    pub const LEN: usize = 1;

    /// Writes the 1-byte frame.
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = LeWriter::new(buf);
        w.put_u8(FRAME_ID_SPEED)?;
        Ok(w.written())
    }
}

/// `0xB3` vehicle speed response, chassis → host, 5 bytes: `0xB3`, then `speed_mps` (f32 at 1).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VehicleSpeed {
    /// Measured vehicle speed, m/s.
    pub speed_mps: f32,
}

impl VehicleSpeed {
    /// Frame length in bytes.
    pub const LEN: usize = 5;

    /// Writes the 5-byte frame; refuses NaN and infinities.
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        if !self.speed_mps.is_finite() {
            return Err(EncodeError::NonFinite { offset: 1 });
        }
        let mut w = LeWriter::new(buf);
        w.put_u8(FRAME_ID_SPEED)?;
        w.put_f32(self.speed_mps)?;
        Ok(w.written())
    }

    /// Reads the speed, checked for finiteness and against `bound_mps` (spec §6.2).
    pub(crate) fn read(bytes: &[u8], bound_mps: f32) -> Option<Result<Self, DecodeError>> {
        let speed_mps = f32_at(bytes, 1)?;
        Some(if !speed_mps.is_finite() {
            Err(DecodeError::NonFinite { offset: 1 })
        } else if speed_mps.abs() >= bound_mps {
            Err(DecodeError::SpeedOutOfBounds { speed_mps, bound_mps })
        } else {
            Ok(Self { speed_mps })
        })
    }
}
