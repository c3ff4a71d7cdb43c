//! 0xAF auxiliary read/write frames (spec §3.3 – §3.5, §6.1).

use robowire_core::BufferTooSmall;
use robowire_core::le::{LeWriter, u32_at};

use crate::{DecodeError, EncodeError, FRAME_ID_AF, MAX_IDS};

/// 0xAF `rw` byte (offset 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Rw {
    /// `RW_READ` = 0x00: a read request, no data.
    Read = 0x00,
    /// `RW_WRITE` = 0x01: a write request, or the response to a read; carries data.
    Write = 0x01,
}

impl Rw {
    /// The byte on the wire.
    pub fn to_byte(self) -> u8 {
        self as u8
    }

    /// `Read` or `Write`, or `InvalidRw`.
    pub fn from_byte(byte: u8) -> Result<Self, DecodeError> {
        match byte {
            0x00 => Ok(Self::Read),
            0x01 => Ok(Self::Write),
            other => Err(DecodeError::InvalidRw(other)),
        }
    }
}

/// Parameter IDs of the 0xAF channel (spec §3.4). Any other value is undefined and rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ParamId {
    /// 0x00, write: system reset (robowire sends the value 0.0).
    #[default]
    SystemReset = 0x00,
    /// 0x03, write: speed command in electrical RPM (ERPM).
    SpeedErpm = 0x03,
    /// 0x05, write: servo pulse width in µs.
    ServoPulseUs = 0x05,
    /// 0x06, read: the 9-field all-state record.
    AllState = 0x06,
    /// 0x07, read: battery voltage in V.
    BatteryVoltage = 0x07,
}

impl ParamId {
    /// The byte on the wire.
    pub fn to_byte(self) -> u8 {
        self as u8
    }

    /// The ID, or `UnknownParamId`.
    pub fn from_byte(byte: u8) -> Result<Self, DecodeError> {
        match byte {
            0x00 => Ok(Self::SystemReset),
            0x03 => Ok(Self::SpeedErpm),
            0x05 => Ok(Self::ServoPulseUs),
            0x06 => Ok(Self::AllState),
            0x07 => Ok(Self::BatteryVoltage),
            other => Err(DecodeError::UnknownParamId(other)),
        }
    }
}

/// Outcome of looking at a candidate frame at the start of a buffer.
#[derive(Debug)]
pub(crate) enum Scan<F> {
    /// Plausible so far; the frame needs more bytes.
    Incomplete,
    /// Implausible: skip one byte and search again.
    Reject(DecodeError),
    /// A frame of this many bytes.
    Frame(F, usize),
}

/// An 0xAF frame as it is on the wire, either direction, without allocation.
///
/// | offset | size | field |
/// |---:|---:|---|
/// | 0 | 1 | `0xAF` |
/// | 1 | 1 | `motor_id` (0 = left, 1 = right in the vendor driver) |
/// | 2 | 1 | `rw` |
/// | 3 | 1 | `n_id`, 1..=16 |
/// | 4 | n_id | `ids` |
/// | 4 + n_id | 4·n_id | data slots, only when `rw` is [`Rw::Write`] |
///
/// Requests are built with the constructors ([`battery_read`](Self::battery_read), …) and sent
/// as [`HostFrame::Af`](crate::HostFrame::Af); responses the host decoder does not map to
/// [`BatteryVoltage`] or [`AllState`] arrive raw as [`ChassisFrame::Af`](crate::ChassisFrame::Af),
/// their slots as raw 4-byte values (a slot may be a u32, not a float).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AfFrame {
    motor_id: u8,
    rw: Rw,
    n_ids: u8,
    ids: [ParamId; MAX_IDS],
    slots: [[u8; 4]; MAX_IDS],
}

/// An 0xAF frame sent by the host.
pub type AfRequest = AfFrame;
/// An 0xAF frame sent by the chassis, kept raw.
pub type AfResponse = AfFrame;

impl AfFrame {
    fn new(motor_id: u8, rw: Rw, count: usize) -> Result<Self, EncodeError> {
        if count == 0 || count > MAX_IDS {
            return Err(EncodeError::IdCount(count));
        }
        Ok(Self { motor_id, rw, n_ids: count as u8, ids: [ParamId::SystemReset; MAX_IDS], slots: [[0; 4]; MAX_IDS] })
    }

    /// A read request for `ids` (1..=16 of them).
    pub fn read(motor_id: u8, ids: &[ParamId]) -> Result<Self, EncodeError> {
        let mut frame = Self::new(motor_id, Rw::Read, ids.len())?;
        frame.ids[..ids.len()].copy_from_slice(ids);
        Ok(frame)
    }

    /// A write frame: each ID with its f32 value (1..=16 entries).
    ///
    /// Non-finite values are refused when the frame is emitted.
    pub fn write(motor_id: u8, entries: &[(ParamId, f32)]) -> Result<Self, EncodeError> {
        let mut frame = Self::new(motor_id, Rw::Write, entries.len())?;
        for (i, &(id, value)) in entries.iter().enumerate() {
            frame.ids[i] = id;
            frame.slots[i] = value.to_le_bytes();
        }
        Ok(frame)
    }

    /// A write frame with raw 4-byte slots (for u32 fields), 1..=16 entries.
    pub fn write_raw(motor_id: u8, entries: &[(ParamId, [u8; 4])]) -> Result<Self, EncodeError> {
        let mut frame = Self::new(motor_id, Rw::Write, entries.len())?;
        for (i, &(id, slot)) in entries.iter().enumerate() {
            frame.ids[i] = id;
            frame.slots[i] = slot;
        }
        Ok(frame)
    }

    fn single(motor_id: u8, rw: Rw, id: ParamId, value: f32) -> Self {
        let mut ids = [ParamId::SystemReset; MAX_IDS];
        ids[0] = id;
        let mut slots = [[0; 4]; MAX_IDS];
        if rw == Rw::Write {
            slots[0] = value.to_le_bytes();
        }
        Self { motor_id, rw, n_ids: 1, ids, slots }
    }

    /// Battery voltage read request (ID 0x07), 5 bytes: `af <motor> 00 01 07`.
    pub fn battery_read(motor_id: u8) -> Self {
        Self::single(motor_id, Rw::Read, ParamId::BatteryVoltage, 0.0)
    }

    /// All-state read request (ID 0x06), 5 bytes: `af <motor> 00 01 06`.
    pub fn all_state_read(motor_id: u8) -> Self {
        Self::single(motor_id, Rw::Read, ParamId::AllState, 0.0)
    }

    /// Speed command write (ID 0x03) in electrical RPM, 9 bytes.
    pub fn speed_write_erpm(motor_id: u8, erpm: f32) -> Self {
        Self::single(motor_id, Rw::Write, ParamId::SpeedErpm, erpm)
    }

    /// Servo pulse width write (ID 0x05) in µs, 9 bytes.
    pub fn servo_pulse_write_us(motor_id: u8, pulse_us: f32) -> Self {
        Self::single(motor_id, Rw::Write, ParamId::ServoPulseUs, pulse_us)
    }

    /// System reset (ID 0x00, value 0.0), 9 bytes (spec §6.1).
    pub fn system_reset(motor_id: u8) -> Self {
        Self::single(motor_id, Rw::Write, ParamId::SystemReset, 0.0)
    }

    /// Addressed motor controller.
    pub fn motor_id(&self) -> u8 {
        self.motor_id
    }

    /// Read or write.
    pub fn rw(&self) -> Rw {
        self.rw
    }

    /// The parameter IDs, 1..=16 of them.
    pub fn ids(&self) -> &[ParamId] {
        &self.ids[..usize::from(self.n_ids)]
    }

    /// The data slots, one per ID for [`Rw::Write`], none for [`Rw::Read`].
    pub fn slots(&self) -> &[[u8; 4]] {
        match self.rw {
            Rw::Read => &[],
            Rw::Write => &self.slots[..usize::from(self.n_ids)],
        }
    }

    /// Slot `index` read as f32, bit for bit.
    pub fn slot_f32(&self, index: usize) -> Option<f32> {
        self.slots().get(index).map(|s| f32::from_le_bytes(*s))
    }

    /// Slot `index` read as u32 (the all-state `id` and `error_code` fields are u32).
    pub fn slot_u32(&self, index: usize) -> Option<u32> {
        self.slots().get(index).map(|s| u32::from_le_bytes(*s))
    }

    /// Frame length on the wire: `4 + n_id (+ 4·n_id for writes)`.
    pub fn buffer_len(&self) -> usize {
        frame_len(self.rw, usize::from(self.n_ids))
    }

    /// Offset of the first data slot for which `must_be_finite(index, id)` holds but whose f32 is
    /// NaN or infinite.
    pub(crate) fn non_finite_offset(&self, must_be_finite: impl Fn(usize, ParamId) -> bool) -> Option<usize> {
        let data_start = 4 + usize::from(self.n_ids);
        self.slots()
            .iter()
            .enumerate()
            .find(|&(i, slot)| must_be_finite(i, self.ids[i]) && !f32::from_le_bytes(*slot).is_finite())
            .map(|(i, _)| data_start + 4 * i)
    }

    /// Writes the frame as it is; direction-specific checks are the caller's.
    pub(crate) fn emit_raw(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        let needed = self.buffer_len();
        if buf.len() < needed {
            return Err(BufferTooSmall { needed, available: buf.len() }.into());
        }
        let mut w = LeWriter::new(buf);
        w.put_u8(FRAME_ID_AF)?;
        w.put_u8(self.motor_id)?;
        w.put_u8(self.rw.to_byte())?;
        w.put_u8(self.n_ids)?;
        for id in self.ids() {
            w.put_u8(id.to_byte())?;
        }
        for slot in self.slots() {
            w.put_bytes(slot)?;
        }
        Ok(w.written())
    }

    /// Structural check of a candidate starting with `0xAF` (spec §6.2 steps 2–3): header fields
    /// are judged as soon as their bytes are present; data slots are not judged here.
    pub(crate) fn scan(input: &[u8]) -> Scan<Self> {
        let Some(&rw) = input.get(2) else { return Scan::Incomplete };
        let rw = match Rw::from_byte(rw) {
            Ok(rw) => rw,
            Err(e) => return Scan::Reject(e),
        };
        let Some(&n_ids) = input.get(3) else { return Scan::Incomplete };
        let count = usize::from(n_ids);
        if count == 0 || count > MAX_IDS {
            return Scan::Reject(DecodeError::InvalidIdCount(n_ids));
        }
        let mut ids = [ParamId::SystemReset; MAX_IDS];
        for (i, &byte) in input.iter().skip(4).take(count).enumerate() {
            match ParamId::from_byte(byte) {
                Ok(id) => ids[i] = id,
                Err(e) => return Scan::Reject(e),
            }
        }
        let len = frame_len(rw, count);
        if input.len() < len {
            return Scan::Incomplete;
        }
        let mut slots = [[0; 4]; MAX_IDS];
        if rw == Rw::Write {
            for (i, slot) in slots.iter_mut().take(count).enumerate() {
                *slot = u32_at(input, 4 + count + 4 * i).unwrap_or(0).to_le_bytes();
            }
        }
        Scan::Frame(Self { motor_id: input[1], rw, n_ids, ids, slots }, len)
    }
}

/// `4 + n_id (+ 4·n_id for writes)` (spec §3.3).
const fn frame_len(rw: Rw, count: usize) -> usize {
    match rw {
        Rw::Read => 4 + count,
        Rw::Write => 4 + 5 * count,
    }
}

/// Battery voltage: the response to [`AfFrame::battery_read`] (`rw` = write, one ID 0x07).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BatteryVoltage {
    /// Motor controller that answered.
    pub motor_id: u8,
    /// Battery voltage, V.
    pub volts: f32,
}

impl BatteryVoltage {
    /// Frame length in bytes.
    pub const LEN: usize = 9;

    /// The raw frame this response travels in.
    pub fn to_af_frame(&self) -> AfFrame {
        AfFrame::single(self.motor_id, Rw::Write, ParamId::BatteryVoltage, self.volts)
    }

    /// Writes the 9-byte frame; refuses NaN and infinities.
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        if !self.volts.is_finite() {
            return Err(EncodeError::NonFinite { offset: 5 });
        }
        self.to_af_frame().emit_raw(buf)
    }
}

/// All-state record: the response to [`AfFrame::all_state_read`] (`rw` = write, 9 IDs, the
/// first 0x06), 49 bytes (spec §3.5, example #9).
///
/// `id` and `error_code` are u32 read from the slot bytes, never floats converted to integers;
/// the reserved slots are kept bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AllState {
    /// Motor controller that answered.
    pub motor_id: u8,
    /// The frame's nine IDs as received: [`AllState::IDS`] in every frame the protocol defines.
    pub ids: [ParamId; 9],
    /// Field 0, `id` (u32; meaning undocumented).
    pub id: u32,
    /// Field 1, position, degrees.
    pub position_deg: f32,
    /// Field 2, speed, rpm.
    pub speed_rpm: f32,
    /// Field 3, current, A.
    pub current_a: f32,
    /// Field 4, temperature, °C.
    pub temperature_c: f32,
    /// Field 5, error bit mask (u32; bits undocumented).
    pub error_code: u32,
    /// Fields 6..=8, reserved; content undefined, kept bit for bit.
    pub reserved: [f32; 3],
}

impl AllState {
    /// Frame length in bytes.
    pub const LEN: usize = 49;
    /// The IDs of an all-state response: 0x06 nine times, one per field.
    pub const IDS: [ParamId; 9] = [ParamId::AllState; 9];
    /// Indices of the slots that must hold finite floats (position, speed, current, temperature).
    const FLOAT_FIELDS: core::ops::RangeInclusive<usize> = 1..=4;

    /// A record for `motor_id` with every field zero.
    pub fn new(motor_id: u8) -> Self {
        Self {
            motor_id,
            ids: Self::IDS,
            id: 0,
            position_deg: 0.0,
            speed_rpm: 0.0,
            current_a: 0.0,
            temperature_c: 0.0,
            error_code: 0,
            reserved: [0.0; 3],
        }
    }

    /// The raw frame this record travels in.
    pub fn to_af_frame(&self) -> AfFrame {
        let mut frame = AfFrame {
            motor_id: self.motor_id,
            rw: Rw::Write,
            n_ids: 9,
            ids: [ParamId::SystemReset; MAX_IDS],
            slots: [[0; 4]; MAX_IDS],
        };
        frame.ids[..9].copy_from_slice(&self.ids);
        let fields = [
            self.id.to_le_bytes(),
            self.position_deg.to_le_bytes(),
            self.speed_rpm.to_le_bytes(),
            self.current_a.to_le_bytes(),
            self.temperature_c.to_le_bytes(),
            self.error_code.to_le_bytes(),
            self.reserved[0].to_le_bytes(),
            self.reserved[1].to_le_bytes(),
            self.reserved[2].to_le_bytes(),
        ];
        frame.slots[..9].copy_from_slice(&fields);
        frame
    }

    /// The record in an all-state frame (`rw` = write, 9 IDs, the first 0x06), if it is one.
    pub(crate) fn from_af_frame(frame: &AfFrame) -> Option<Self> {
        if frame.rw != Rw::Write || frame.n_ids != 9 || frame.ids[0] != ParamId::AllState {
            return None;
        }
        let slot = |i: usize| frame.slots[i];
        let mut ids = Self::IDS;
        ids.copy_from_slice(&frame.ids[..9]);
        Some(Self {
            motor_id: frame.motor_id,
            ids,
            id: u32::from_le_bytes(slot(0)),
            position_deg: f32::from_le_bytes(slot(1)),
            speed_rpm: f32::from_le_bytes(slot(2)),
            current_a: f32::from_le_bytes(slot(3)),
            temperature_c: f32::from_le_bytes(slot(4)),
            error_code: u32::from_le_bytes(slot(5)),
            reserved: [f32::from_le_bytes(slot(6)), f32::from_le_bytes(slot(7)), f32::from_le_bytes(slot(8))],
        })
    }

    /// Offset of the first non-finite float field (position, speed, current, temperature).
    pub(crate) fn non_finite_offset(&self) -> Option<usize> {
        self.to_af_frame().non_finite_offset(|i, _| Self::FLOAT_FIELDS.contains(&i))
    }

    /// Writes the 49-byte frame; refuses non-finite position, speed, current or temperature.
    pub fn emit(&self, buf: &mut [u8]) -> Result<usize, EncodeError> {
        if let Some(offset) = self.non_finite_offset() {
            return Err(EncodeError::NonFinite { offset });
        }
        self.to_af_frame().emit_raw(buf)
    }
}
