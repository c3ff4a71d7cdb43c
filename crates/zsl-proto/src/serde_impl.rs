//! JSON shapes of the datagrams (feature `serde`): what `robowire decode zsl --json` and
//! `robowire dog status --json` print. Units are in the key names; joint arrays are per leg
//! (FR, FL, RR, RL); floats in robowire-core's one JSON form. The shared-memory blocks (leg
//! commands, leg states, an IMU record) are objects per leg (`FR`, …) and joint (`abad`, …).

use robowire_core::serde_f32::F32 as Float;
use serde::ser::{Serialize, SerializeMap, SerializeSeq, Serializer};
use zerocopy::little_endian::F32;

use crate::shm::{JointControl, JointFaults, JointState, Leg, LegControl, LegState, NavImu};
use crate::udp::{HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState, Model};

/// Little-endian floats as a JSON array.
struct Floats<'a>(&'a [F32]);

impl Serialize for Floats<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.0.len()))?;
        for v in self.0 {
            seq.serialize_element(&Float(v.get()))?;
        }
        seq.end()
    }
}

/// `{"abad": […], "hip": […], "knee": […], "foot": […]}`.
struct Joints<'a>(&'a [[F32; 4]; 4]);

impl Serialize for Joints<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(4))?;
        for (name, legs) in ["abad", "hip", "knee", "foot"].iter().zip(self.0) {
            map.serialize_entry(name, &Floats(legs))?;
        }
        map.end()
    }
}

fn model_name(magic: u16) -> &'static str {
    match Model::from_magic(magic) {
        Ok(Model::Zsl1) => "zsl-1",
        Ok(Model::Zsl1W) => "zsl-1w",
        Err(_) => "unknown",
    }
}

/// `"datagram"` and `"model"` (from the magic), the first entries of a command.
fn command_header<M: SerializeMap>(map: &mut M, datagram: &str, magic: u16) -> Result<(), M::Error> {
    map.serialize_entry("datagram", datagram)?;
    map.serialize_entry("model", model_name(magic))
}

/// One entry per joint: `{prefix}abad{suffix}`, `{prefix}hip{suffix}`, `{prefix}knee{suffix}`.
fn by_joint<M: SerializeMap>(map: &mut M, names: [&str; 3], arrays: &[[F32; 4]; 3]) -> Result<(), M::Error> {
    for (name, legs) in names.iter().zip(arrays) {
        map.serialize_entry(name, &Floats(legs))?;
    }
    Ok(())
}

/// `{"datagram":"high_level_command","model":"zsl-1","mode":18,"mode_name":"Move",…}`.
impl Serialize for HighLevelCommand {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        command_header(&mut map, "high_level_command", self.magic())?;
        map.serialize_entry("mode", &self.mode.get())?;
        map.serialize_entry("mode_name", &format_args!("{:?}", self.control_mode()))?;
        map.serialize_entry("action", &self.action.get())?;
        map.serialize_entry("action_name", &format_args!("{:?}", self.action_code()))?;
        map.serialize_entry("flag", &self.flag.get())?;
        map.serialize_entry("vx_mps", &Float(self.vx.get()))?;
        map.serialize_entry("vy_mps", &Float(self.vy.get()))?;
        map.serialize_entry("roll_rate_radps", &Float(self.roll_rate.get()))?;
        map.serialize_entry("pitch_rate_radps", &Float(self.pitch_rate.get()))?;
        map.serialize_entry("yaw_rate_radps", &Float(self.yaw_rate.get()))?;
        map.serialize_entry("height_rate_mps", &Float(self.height_rate.get()))?;
        map.serialize_entry("checksum", &self.checksum())?;
        map.end()
    }
}

/// `{"datagram":"low_level_command","model":"zsl-1","q_des_abad":[…],…,"checksum":…}`.
impl Serialize for LowLevelCommand {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let m = &self.motor;
        let mut map = s.serialize_map(None)?;
        command_header(&mut map, "low_level_command", self.magic())?;
        by_joint(&mut map, ["q_des_abad", "q_des_hip", "q_des_knee"], &m.q_des)?;
        by_joint(&mut map, ["qd_des_abad", "qd_des_hip", "qd_des_knee"], &m.qd_des)?;
        by_joint(&mut map, ["kp_abad", "kp_hip", "kp_knee"], &m.kp)?;
        by_joint(&mut map, ["kd_abad", "kd_hip", "kd_knee"], &m.kd)?;
        by_joint(&mut map, ["tau_abad_ff", "tau_hip_ff", "tau_knee_ff"], &m.tau_ff)?;
        map.serialize_entry("checksum", &self.checksum())?;
        map.end()
    }
}

/// `{"datagram":"high_level_state","mode":1,"mode_name":"Stand","battery_percent":…,
/// "error_word":0,"error_name":"none",…}`.
impl Serialize for HighLevelState {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        map.serialize_entry("datagram", "high_level_state")?;
        map.serialize_entry("mode", &self.control_mode.get())?;
        map.serialize_entry("mode_name", &format_args!("{:?}", self.mode()))?;
        map.serialize_entry("battery_percent", &self.battery_percent.get())?;
        map.serialize_entry("error_word", &self.error_word.get())?;
        match self.error() {
            None => map.serialize_entry("error_name", "none")?,
            Some(code) => map.serialize_entry("error_name", &format_args!("{code:?}"))?,
        }
        map.serialize_entry("sdk_mismatch", &self.sdk_mismatch.get())?;
        map.serialize_entry("quaternion_wxyz", &Floats(&self.quaternion))?;
        map.serialize_entry("gyro_radps", &Floats(&self.gyro))?;
        map.serialize_entry("acc_mps2", &Floats(&self.acc))?;
        map.serialize_entry("rpy_rad", &Floats(&self.rpy))?;
        map.serialize_entry("body_velocity_mps", &Floats(&self.body_velocity))?;
        map.serialize_entry("world_velocity_mps", &Floats(&self.world_velocity))?;
        map.serialize_entry("position_m", &Floats(&self.position))?;
        map.serialize_entry("joint_angle_rad", &Joints(&self.joint_angle))?;
        map.serialize_entry("joint_velocity_radps", &Joints(&self.joint_velocity))?;
        map.serialize_entry("joint_torque_nm", &Joints(&self.joint_torque))?;
        map.end()
    }
}

/// `{"datagram":"low_level_state","has_motor_data":true,"q_abad":[…],…,"rpy_rad":[…]}`.
impl Serialize for LowLevelState {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let m = &self.motor;
        let mut map = s.serialize_map(None)?;
        map.serialize_entry("datagram", "low_level_state")?;
        map.serialize_entry("has_motor_data", &self.has_motor_data())?;
        by_joint(&mut map, ["q_abad", "q_hip", "q_knee"], &m.q)?;
        by_joint(&mut map, ["qd_abad", "qd_hip", "qd_knee"], &m.qd)?;
        by_joint(&mut map, ["tau_abad_fb", "tau_hip_fb", "tau_knee_fb"], &m.tau_fb)?;
        map.serialize_entry("quaternion_wxyz", &Floats(&self.quaternion))?;
        map.serialize_entry("gyro_radps", &Floats(&self.gyro))?;
        map.serialize_entry("acc_mps2", &Floats(&self.acc))?;
        map.serialize_entry("rpy_rad", &Floats(&self.rpy))?;
        map.end()
    }
}

/// The datagram inside, as its own JSON form.
impl Serialize for crate::udp::AnyDatagram {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Self::HighLevelCommand(d) => d.serialize(s),
            Self::HighLevelState(d) => d.serialize(s),
            Self::LowLevelCommand(d) => d.serialize(s),
            Self::LowLevelState(d) => d.serialize(s),
        }
    }
}

/// Joint names in memory order, as the shared-memory JSON keys them.
const JOINT_NAMES: [&str; 4] = ["abad", "hip", "knee", "foot"];

/// One entry per joint of a leg: `"abad"`, `"hip"`, `"knee"`, `"foot"`.
fn by_joint_name<M: SerializeMap, T: Serialize>(map: &mut M, joints: &[T; 4]) -> Result<(), M::Error> {
    for (name, joint) in JOINT_NAMES.iter().zip(joints) {
        map.serialize_entry(name, joint)?;
    }
    Ok(())
}

/// Four legs of a shared-memory block as `{"FR": …, "FL": …, "RR": …, "RL": …}`.
pub(crate) struct Legs<'a, T>(pub(crate) &'a [T; 4]);

impl<T: Serialize> Serialize for Legs<'_, T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(4))?;
        for (leg, value) in Leg::ALL.iter().zip(self.0) {
            map.serialize_entry(leg.abbreviation(), value)?;
        }
        map.end()
    }
}

/// `{"p_des_rad":…,"v_des_radps":…,"kp":…,"kd":…,"t_ff_nm":…}`.
impl Serialize for JointControl {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(5))?;
        let names = ["p_des_rad", "v_des_radps", "kp", "kd", "t_ff_nm"];
        for (name, value) in names.iter().zip(self.values()) {
            map.serialize_entry(name, &Float(value))?;
        }
        map.end()
    }
}

/// `{"abad":{…},"hip":{…},"knee":{…},"foot":{…},"flags":1}`.
impl Serialize for LegControl {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(5))?;
        by_joint_name(&mut map, &self.joints)?;
        map.serialize_entry("flags", &self.flags.get())?;
        map.end()
    }
}

/// `{"overvoltage":false,"overcurrent":false,…}`.
impl Serialize for JointFaults {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(5))?;
        map.serialize_entry("overvoltage", &self.overvoltage)?;
        map.serialize_entry("overcurrent", &self.overcurrent)?;
        map.serialize_entry("over_temperature", &self.over_temperature)?;
        map.serialize_entry("overspeed", &self.overspeed)?;
        map.serialize_entry("dual_encoder", &self.dual_encoder)?;
        map.end()
    }
}

/// `{"p_rad":…,"v_radps":…,"t_nm":…,"flags":…,"enabled":true,"faults":{…},"voltage_v":48,
/// "temperature_c":25}`: the flag word as it is and decoded (spec §4.4).
impl Serialize for JointState {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let flags = self.joint_flags();
        let mut map = s.serialize_map(Some(8))?;
        map.serialize_entry("p_rad", &Float(self.p.get()))?;
        map.serialize_entry("v_radps", &Float(self.v.get()))?;
        map.serialize_entry("t_nm", &Float(self.t.get()))?;
        map.serialize_entry("flags", &flags.0)?;
        map.serialize_entry("enabled", &flags.enabled())?;
        map.serialize_entry("faults", &flags.faults())?;
        map.serialize_entry("voltage_v", &flags.voltage_v())?;
        map.serialize_entry("temperature_c", &flags.temperature_c())?;
        map.end()
    }
}

/// `{"abad":{…},"hip":{…},"knee":{…},"foot":{…}}`.
impl Serialize for LegState {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(4))?;
        by_joint_name(&mut map, &self.joints)?;
        map.end()
    }
}

/// `{"timestamp_ns":…,"acc_mps2":[…],"gyro_radps":[…],"quaternion_wxyz":[…]}`.
impl Serialize for NavImu {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(4))?;
        map.serialize_entry("timestamp_ns", &self.timestamp_ns.get())?;
        map.serialize_entry("acc_mps2", &Floats(&self.sample.acc))?;
        map.serialize_entry("gyro_radps", &Floats(&self.sample.gyro))?;
        map.serialize_entry("quaternion_wxyz", &Floats(&self.sample.q))?;
        map.end()
    }
}
