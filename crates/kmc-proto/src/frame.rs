//! Every frame of each direction, as one enum per direction.

use crate::af::Scan;
use crate::{
    AfFrame, AfRequest, AfResponse, AllState, BatteryVoltage, DEFAULT_MAX_SPEED_MPS, DecodeError, EncodeError,
    FRAME_ID_AF, FRAME_ID_CONTROL, FRAME_ID_SPEED, ParamId, PcControl, Rw, VehicleSpeed, VehicleSpeedRequest,
};

/// A frame the host sends to the chassis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HostFrame {
    /// `0xA5`, 9 bytes: velocity and curvature.
    PcControl(PcControl),
    /// `0xB3`, 1 byte: ask for the vehicle speed.
    VehicleSpeedRequest,
    /// `0xAF`: read or write parameters of a motor controller.
    Af(AfRequest),
}

/// A frame the chassis sends to the host, mapped per spec §6.1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ChassisFrame {
    /// `0xB3`, 5 bytes.
    VehicleSpeed(VehicleSpeed),
    /// `0xAF` write with the one ID 0x07.
    BatteryVoltage(BatteryVoltage),
    /// `0xAF` write with nine IDs, the first 0x06.
    AllState(AllState),
    /// Any other well-formed `0xAF`, raw.
    Af(AfResponse),
}

impl HostFrame {
    /// Is `byte` the ID of a host → chassis frame?
    pub fn is_frame_id(byte: u8) -> bool {
        matches!(byte, FRAME_ID_CONTROL | FRAME_ID_SPEED | FRAME_ID_AF)
    }

    /// Length on the wire.
    pub fn buffer_len(&self) -> usize {
        match self {
            Self::PcControl(_) => PcControl::LEN,
            Self::VehicleSpeedRequest => VehicleSpeedRequest::LEN,
            Self::Af(frame) => frame.buffer_len(),
        }
    }

    /// Writes the frame at the start of `buf` and returns its length.
    ///
    /// Refuses, writing nothing, a non-finite velocity, curvature or write value: such a frame
    /// would be dropped by the chassis (spec §6.3).
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        match self {
            Self::PcControl(control) => control.emit(buf),
            Self::VehicleSpeedRequest => VehicleSpeedRequest.emit(buf),
            Self::Af(frame) => {
                if let Some(offset) = request_non_finite_offset(frame) {
                    return Err(EncodeError::NonFinite { offset });
                }
                frame.emit_raw(buf)
            }
        }
    }

    /// Parses exactly one whole frame, with the device-side plausibility rules (spec §6.3).
    pub fn parse(bytes: &[u8]) -> Result<Self, DecodeError> {
        parse_exact(bytes, Self::is_frame_id, Self::scan)
    }

    /// Judges a candidate that starts with a host frame ID (spec §6.3).
    pub(crate) fn scan(input: &[u8]) -> Scan<Self> {
        match input.first() {
            Some(&FRAME_ID_CONTROL) => match PcControl::read(input) {
                None => Scan::Incomplete,
                Some(control) => match control.non_finite_offset() {
                    Some(offset) => Scan::Reject(DecodeError::NonFinite { offset }),
                    None => Scan::Frame(Self::PcControl(control), PcControl::LEN),
                },
            },
            Some(&FRAME_ID_SPEED) => Scan::Frame(Self::VehicleSpeedRequest, VehicleSpeedRequest::LEN),
            Some(&FRAME_ID_AF) => match AfFrame::scan(input) {
                Scan::Frame(frame, len) => match request_non_finite_offset(&frame) {
                    Some(offset) => Scan::Reject(DecodeError::NonFinite { offset }),
                    None => Scan::Frame(Self::Af(frame), len),
                },
                Scan::Incomplete => Scan::Incomplete,
                Scan::Reject(e) => Scan::Reject(e),
            },
            Some(&other) => Scan::Reject(DecodeError::UnknownFrameId(other)),
            None => Scan::Incomplete,
        }
    }
}

/// Host requests carry floats in every data slot.
fn request_non_finite_offset(frame: &AfFrame) -> Option<usize> {
    frame.non_finite_offset(|_, _| true)
}

impl ChassisFrame {
    /// Is `byte` the ID of a chassis → host frame?
    pub fn is_frame_id(byte: u8) -> bool {
        matches!(byte, FRAME_ID_SPEED | FRAME_ID_AF)
    }

    /// Length on the wire.
    pub fn buffer_len(&self) -> usize {
        match self {
            Self::VehicleSpeed(_) => VehicleSpeed::LEN,
            Self::BatteryVoltage(_) => BatteryVoltage::LEN,
            Self::AllState(_) => AllState::LEN,
            Self::Af(frame) => frame.buffer_len(),
        }
    }

    /// Writes the frame at the start of `buf` and returns its length.
    ///
    /// Refuses, writing nothing, any frame the host-side decoder would reject as implausible
    /// (non-finite floats where the protocol carries a value).
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        match self {
            Self::VehicleSpeed(speed) => speed.emit(buf),
            Self::BatteryVoltage(battery) => battery.emit(buf),
            Self::AllState(state) => state.emit(buf),
            Self::Af(frame) => match Self::classify(*frame) {
                Err(DecodeError::NonFinite { offset }) => Err(EncodeError::NonFinite { offset }),
                _ => frame.emit_raw(buf),
            },
        }
    }

    /// Parses exactly one whole frame with the host-side plausibility rules (spec §6.2) and the
    /// default speed bound of [`DEFAULT_MAX_SPEED_MPS`].
    pub fn parse(bytes: &[u8]) -> Result<Self, DecodeError> {
        parse_exact(bytes, Self::is_frame_id, |input| Self::scan(input, DEFAULT_MAX_SPEED_MPS))
    }

    /// Maps a well-formed 0xAF frame per spec §6.1 and checks its float slots (§6.2 step 3).
    fn classify(frame: AfFrame) -> Result<Self, DecodeError> {
        let (mapped, non_finite) = if frame.rw() == Rw::Write && frame.ids() == [ParamId::BatteryVoltage] {
            let volts = frame.slot_f32(0).unwrap_or(f32::NAN);
            let battery = BatteryVoltage { motor_id: frame.motor_id(), volts };
            (Self::BatteryVoltage(battery), frame.non_finite_offset(|_, _| true))
        } else if let Some(state) = AllState::from_af_frame(&frame) {
            (Self::AllState(state), state.non_finite_offset())
        } else {
            // A raw frame: a slot whose ID is 0x06 may hold a u32 field.
            (Self::Af(frame), frame.non_finite_offset(|_, id| id != ParamId::AllState))
        };
        match non_finite {
            Some(offset) => Err(DecodeError::NonFinite { offset }),
            None => Ok(mapped),
        }
    }

    /// Judges a candidate that starts with a chassis frame ID (spec §6.2).
    pub(crate) fn scan(input: &[u8], max_speed_mps: f32) -> Scan<Self> {
        match input.first() {
            Some(&FRAME_ID_SPEED) => match VehicleSpeed::read(input, max_speed_mps) {
                None => Scan::Incomplete,
                Some(Ok(speed)) => Scan::Frame(Self::VehicleSpeed(speed), VehicleSpeed::LEN),
                Some(Err(e)) => Scan::Reject(e),
            },
            Some(&FRAME_ID_AF) => match AfFrame::scan(input) {
                Scan::Frame(frame, len) => match Self::classify(frame) {
                    Ok(mapped) => Scan::Frame(mapped, len),
                    Err(e) => Scan::Reject(e),
                },
                Scan::Incomplete => Scan::Incomplete,
                Scan::Reject(e) => Scan::Reject(e),
            },
            Some(&other) => Scan::Reject(DecodeError::UnknownFrameId(other)),
            None => Scan::Incomplete,
        }
    }
}

/// Strict whole-frame parsing on top of a candidate scanner.
fn parse_exact<F>(
    bytes: &[u8],
    is_frame_id: fn(u8) -> bool,
    scan: impl Fn(&[u8]) -> Scan<F>,
) -> Result<F, DecodeError> {
    let &first = bytes.first().ok_or(DecodeError::Empty)?;
    if !is_frame_id(first) {
        return Err(DecodeError::UnknownFrameId(first));
    }
    match scan(bytes) {
        Scan::Frame(frame, len) if len == bytes.len() => Ok(frame),
        Scan::Frame(_, len) => Err(DecodeError::TrailingBytes { frame_len: len, available: bytes.len() }),
        Scan::Reject(e) => Err(e),
        Scan::Incomplete => Err(DecodeError::Truncated { needed: known_len(bytes), available: bytes.len() }),
    }
}

/// The length a truncated frame announces, as far as its bytes tell.
fn known_len(bytes: &[u8]) -> usize {
    match (bytes.first(), bytes.get(2), bytes.get(3)) {
        (Some(&FRAME_ID_CONTROL), ..) => PcControl::LEN,
        (Some(&FRAME_ID_SPEED), ..) => VehicleSpeed::LEN,
        (Some(&FRAME_ID_AF), Some(&rw), Some(&n)) => {
            let n = usize::from(n);
            if rw == Rw::Write.to_byte() { 4 + 5 * n } else { 4 + n }
        }
        _ => 4,
    }
}
