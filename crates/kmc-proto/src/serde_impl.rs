//! JSON shapes of frames (feature `serde`): the golden fixtures' `fields` objects and
//! `robowire decode kmc --json`. Field names are the spec's; floats in robowire-core's one JSON
//! form (non-finite ones as the strings `"NaN"`, `"-NaN"`, `"Infinity"`, `"-Infinity"`).

use robowire_core::serde_f32::F32;
use serde::ser::{Serialize, SerializeMap, SerializeSeq, Serializer};

use crate::{AfFrame, AllState, ChassisFrame, HostFrame, Rw};

/// A 4-byte slot as 8 lowercase hex digits, in wire order.
struct Slot([u8; 4]);

impl Serialize for Slot {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        const HEX: &[u8; 16] = b"0123456789abcdef";
        let mut text = [0u8; 8];
        for (i, byte) in self.0.iter().enumerate() {
            text[2 * i] = HEX[usize::from(byte >> 4)];
            text[2 * i + 1] = HEX[usize::from(byte & 0x0f)];
        }
        s.serialize_str(core::str::from_utf8(&text).unwrap_or_default())
    }
}

struct Ids<'a>(&'a [crate::ParamId]);

impl Serialize for Ids<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.0.len()))?;
        for id in self.0 {
            seq.serialize_element(&id.to_byte())?;
        }
        seq.end()
    }
}

struct Floats<'a>(&'a [[u8; 4]]);

impl Serialize for Floats<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.0.len()))?;
        for slot in self.0 {
            seq.serialize_element(&F32(f32::from_le_bytes(*slot)))?;
        }
        seq.end()
    }
}

struct Slots<'a>(&'a [[u8; 4]]);

impl Serialize for Slots<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.0.len()))?;
        for slot in self.0 {
            seq.serialize_element(&Slot(*slot))?;
        }
        seq.end()
    }
}

fn rw_name(rw: Rw) -> &'static str {
    match rw {
        Rw::Read => "read",
        Rw::Write => "write",
    }
}

/// `motor_id`, `rw`, `ids`, then the slots as floats (requests) or raw hex (responses).
fn af_entries<M: SerializeMap>(map: &mut M, frame: &AfFrame, slots_as_floats: bool) -> Result<(), M::Error> {
    map.serialize_entry("motor_id", &frame.motor_id())?;
    map.serialize_entry("rw", rw_name(frame.rw()))?;
    map.serialize_entry("ids", &Ids(frame.ids()))?;
    if frame.rw() == Rw::Write {
        if slots_as_floats {
            map.serialize_entry("data", &Floats(frame.slots()))?;
        } else {
            map.serialize_entry("slots", &Slots(frame.slots()))?;
        }
    }
    Ok(())
}

fn all_state_entries<M: SerializeMap>(map: &mut M, state: &AllState) -> Result<(), M::Error> {
    map.serialize_entry("motor_id", &state.motor_id)?;
    if state.ids != AllState::IDS {
        map.serialize_entry("ids", &Ids(&state.ids))?;
    }
    map.serialize_entry("id", &state.id)?;
    map.serialize_entry("position_deg", &F32(state.position_deg))?;
    map.serialize_entry("speed_rpm", &F32(state.speed_rpm))?;
    map.serialize_entry("current_a", &F32(state.current_a))?;
    map.serialize_entry("temperature_c", &F32(state.temperature_c))?;
    map.serialize_entry("error_code", &state.error_code)?;
    map.serialize_entry("reserved_0", &F32(state.reserved[0]))?;
    map.serialize_entry("reserved_1", &F32(state.reserved[1]))?;
    map.serialize_entry("reserved_2", &F32(state.reserved[2]))
}

/// `{"frame":"pc_control","velocity_mps":0.5,"curvature_per_m":0.4}`,
/// `{"frame":"vehicle_speed_request"}`, `{"frame":"af_request","motor_id":0,"rw":"write","ids":[3],"data":[1500.0]}`.
impl Serialize for HostFrame {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        match self {
            Self::PcControl(c) => {
                map.serialize_entry("frame", "pc_control")?;
                map.serialize_entry("velocity_mps", &F32(c.velocity_mps))?;
                map.serialize_entry("curvature_per_m", &F32(c.curvature_per_m))?;
            }
            Self::VehicleSpeedRequest => map.serialize_entry("frame", "vehicle_speed_request")?,
            Self::Af(frame) => {
                map.serialize_entry("frame", "af_request")?;
                af_entries(&mut map, frame, true)?;
            }
        }
        map.end()
    }
}

/// `{"frame":"vehicle_speed","speed_mps":1.25}`, `{"frame":"battery_voltage","motor_id":0,"volts":24.5}`,
/// `{"frame":"all_state","motor_id":1,"id":1,"position_deg":90.0,…,"reserved_2":0.0}`,
/// `{"frame":"af_response","motor_id":0,"rw":"write","ids":[6],"slots":["01000000"]}`.
impl Serialize for ChassisFrame {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        match self {
            Self::VehicleSpeed(v) => {
                map.serialize_entry("frame", "vehicle_speed")?;
                map.serialize_entry("speed_mps", &F32(v.speed_mps))?;
            }
            Self::BatteryVoltage(b) => {
                map.serialize_entry("frame", "battery_voltage")?;
                map.serialize_entry("motor_id", &b.motor_id)?;
                map.serialize_entry("volts", &F32(b.volts))?;
            }
            Self::AllState(state) => {
                map.serialize_entry("frame", "all_state")?;
                all_state_entries(&mut map, state)?;
            }
            Self::Af(frame) => {
                map.serialize_entry("frame", "af_response")?;
                af_entries(&mut map, frame, false)?;
            }
        }
        map.end()
    }
}
