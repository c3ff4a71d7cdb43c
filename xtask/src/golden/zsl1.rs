//! ZSL-1 golden datagrams (`fixtures/zsl1/frames.json`), captured from or verified through the
//! vendor's SDK v0.2.7: commands decode strictly to their captured fields, re-encode byte for byte,
//! and are rebuilt from the vendor call that produced them; states decode like the vendor client
//! and give the values its getters returned. Vendor data: never rewritten.

use std::path::{Path, PathBuf};

use anyhow::Context;
use serde_json::Value;
use zsl_proto::rules::{ActionClear, check_all, move_ranges};
use zsl_proto::udp::{
    ControlMode, HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState, Model, ReturnCode,
};
use zsl_proto::zerocopy::little_endian::F32;

use super::Outcome;
use crate::{hex_decode, hex_encode, workspace_root};

/// The ZSL-1 fixture file.
pub fn frames_path() -> PathBuf {
    workspace_root().join("fixtures/zsl1/frames.json")
}

/// Floats in the fixtures are rounded to 7 significant digits; NaN is the string "NaN".
fn float_matches(ours: f32, expected: &Value) -> bool {
    match expected {
        Value::String(s) if s == "NaN" => ours.is_nan(),
        Value::Number(n) => {
            let e = n.as_f64().unwrap_or(f64::NAN);
            let o = f64::from(ours);
            (o - e).abs() <= 1e-6 * e.abs().max(1.0)
        }
        _ => false,
    }
}

fn floats_match(ours: &[F32], expected: &Value) -> bool {
    expected
        .as_array()
        .is_some_and(|e| e.len() == ours.len() && ours.iter().zip(e).all(|(o, e)| float_matches(o.get(), e)))
}

struct Checker {
    problems: Vec<String>,
}

impl Checker {
    fn float(&mut self, key: &str, ours: f32, decoded: &Value) {
        if !float_matches(ours, &decoded[key]) {
            self.problems.push(format!("{key}: decoded {ours}, fixture {}", decoded[key]));
        }
    }
    fn floats(&mut self, key: &str, ours: &[F32], expected: &Value) {
        if !floats_match(ours, expected) {
            let ours: Vec<f32> = ours.iter().map(|v| v.get()).collect();
            self.problems.push(format!("{key}: decoded {ours:?}, fixture {expected}"));
        }
    }
    fn int(&mut self, key: &str, ours: u64, expected: &Value) {
        if expected.as_u64() != Some(ours) {
            self.problems.push(format!("{key}: decoded {ours}, fixture {expected}"));
        }
    }
}

/// The command the vendor call in `api` produces, if the call is one of §5.2 / §10.
fn command_for_call(api: &str) -> Option<HighLevelCommand> {
    if api.contains("idle stream") {
        return Some(HighLevelCommand::default());
    }
    if api.contains("error word") {
        // The sender overwrites the mode of an accepted move(0.5, 0, 0) with 0 (spec §3.1).
        let mut c = HighLevelCommand::move_velocity(0.5, 0.0, 0.0);
        c.mode = 0.into();
        return Some(c);
    }
    let (name, args, n) = robowire_fixtures::zsl1::vendor_call(api)?;
    let arg = |i: usize| (i < n).then(|| args[i]);
    let mut command = match name {
        "standUp" => HighLevelCommand::stand_up(),
        "lieDown" => HighLevelCommand::lie_down(),
        "passive" => HighLevelCommand::passive(),
        "move" => HighLevelCommand::move_velocity(arg(0)?, arg(1)?, arg(2)?),
        "jump" => HighLevelCommand::jump(),
        "frontJump" => HighLevelCommand::front_jump(),
        "backflip" => HighLevelCommand::backflip(),
        "shakeHand" => HighLevelCommand::shake_hand(),
        "twoLegStand" => HighLevelCommand::two_leg_stand(arg(0)?, arg(1)?),
        "cancelTwoLegStand" => HighLevelCommand::cancel_two_leg_stand(),
        "attitudeControl" => HighLevelCommand::attitude(arg(0)?, arg(1)?, arg(2)?, arg(3)?),
        "crawl" => HighLevelCommand::crawl(arg(0)?, arg(1)?, arg(2)?),
        "climb" => HighLevelCommand::climb(arg(0)?, arg(1)?, arg(2)?),
        "cancelCrawl" | "cancelClimb" => HighLevelCommand::cancel_crawl_or_climb(),
        _ => return None,
    };
    if api.contains("frame group 2") {
        // After the sender's automatic clear: the 7th datagram and later.
        let mut clear = ActionClear::default();
        for _ in 0..7 {
            clear.before_send(&mut command);
        }
    }
    Some(command)
}

fn check_high_level_command(entry: &Value, bytes: &[u8], c: &mut Checker) {
    let decoded = &entry["decoded"];
    let (command, model) = match HighLevelCommand::decode(bytes) {
        Ok(ok) => ok,
        Err(e) => return c.problems.push(format!("does not decode: {e}")),
    };
    if decoded["magic"].as_str() != Some(&format!("0x{:04x}", command.magic())) {
        c.problems.push(format!("magic 0x{:04x}, fixture {}", command.magic(), decoded["magic"]));
    }
    c.float("f32_04_vx", command.vx.get(), decoded);
    c.float("f32_08_vy", command.vy.get(), decoded);
    c.float("f32_0c_roll_vel", command.roll_rate.get(), decoded);
    c.float("f32_10_pitch_vel", command.pitch_rate.get(), decoded);
    c.float("f32_14_yaw", command.yaw_rate.get(), decoded);
    c.float("f32_18_height_vel", command.height_rate.get(), decoded);
    c.int("u16_1c_action", command.action.get().into(), &decoded["u16_1c_action"]);
    c.int("u16_1e_mode", command.mode.get().into(), &decoded["u16_1e_mode"]);
    c.int("u16_20_flag", command.flag.get().into(), &decoded["u16_20_flag"]);
    c.int("u16_22_reserved", command.reserved_22.get().into(), &decoded["u16_22_reserved"]);
    c.int("u32_24_checksum", command.checksum().into(), &decoded["u32_24_checksum"]);
    if command.encode(model) != bytes {
        c.problems.push("does not re-encode byte for byte".into());
    }
    let api = entry["api"].as_str().unwrap_or_default();
    let mut call = api.to_string();
    if entry["return_value"].as_u64() == Some(u64::from(ReturnCode::SpeedTooLarge.raw())) {
        // Refused client-side: the rules must refuse the arguments too, and the datagram on the
        // wire is the previous, still latched command the note names.
        match command_for_call(api) {
            Some(refused) if refused.control_mode() == ControlMode::Move => {
                let args = [refused.vx.get(), refused.vy.get(), refused.yaw_rate.get()];
                if check_all(&move_ranges(model), args).is_ok() {
                    c.problems.push("the vendor refused the arguments, robowire's rules accept them".into());
                }
            }
            _ => c.problems.push("cannot check the refused call".into()),
        }
        let note = entry["note"].as_str().unwrap_or_default();
        call = note.split("previous command, ").nth(1).map(|p| format!("HighLevel.{p}")).unwrap_or_default();
    }
    match command_for_call(&call) {
        Some(built) if built.encode(model) == bytes => {}
        Some(built) => c.problems.push(format!("the call encodes to {}", hex_encode(&built.encode(model)))),
        None => c.problems.push(format!("no encoder for the call {api:?}")),
    }
}

const LOW_COMMAND_NAMES: [[&str; 3]; 5] = [
    ["q_des_abad", "q_des_hip", "q_des_knee"],
    ["qd_des_abad", "qd_des_hip", "qd_des_knee"],
    ["kp_abad", "kp_hip", "kp_knee"],
    ["kd_abad", "kd_hip", "kd_knee"],
    ["tau_abad_ff", "tau_hip_ff", "tau_knee_ff"],
];

fn check_low_level_command(entry: &Value, bytes: &[u8], c: &mut Checker) {
    let decoded = &entry["decoded"];
    let (command, model) = match LowLevelCommand::decode(bytes) {
        Ok(ok) => ok,
        Err(e) => return c.problems.push(format!("does not decode: {e}")),
    };
    let m = &command.motor;
    for (arrays, names) in [&m.q_des, &m.qd_des, &m.kp, &m.kd, &m.tau_ff].into_iter().zip(LOW_COMMAND_NAMES) {
        for (legs, name) in arrays.iter().zip(names) {
            if !decoded[name].is_null() {
                c.floats(name, legs, &decoded[name]);
            }
        }
    }
    c.int("u32_f4_checksum", command.checksum().into(), &decoded["u32_f4_checksum"]);
    if command.encode(model) != bytes {
        c.problems.push("does not re-encode byte for byte".into());
    }
    let api = entry["api"].as_str().unwrap_or_default();
    if let Some(motor) = robowire_fixtures::zsl1::motor_command(api)
        && LowLevelCommand::new(motor).encode(Model::Zsl1) != bytes
    {
        c.problems.push("the command the call describes encodes differently".into());
    }
    if api.contains("idle stream") && LowLevelCommand::default().encode(Model::Zsl1) != bytes {
        c.problems.push("the idle command encodes differently".into());
    }
}

fn check_high_level_state(entry: &Value, bytes: &[u8], c: &mut Checker) {
    let decoded = &entry["decoded"];
    let mut state = HighLevelState::default();
    if let Err(e) = state.update_lenient(bytes) {
        return c.problems.push(format!("does not decode leniently: {e}"));
    }
    let strict_ok = HighLevelState::decode_strict(bytes).is_ok();
    if strict_ok != bytes.starts_with(&[0xa5, 0x5a]) {
        c.problems.push("strict decoding disagrees with the header".into());
    }
    let getters = &decoded["readback_via_getters"];
    let a = &state.joint_angle;
    let v = &state.joint_velocity;
    let t = &state.joint_torque;
    for (getter, values) in [
        ("getQuaternion", &state.quaternion[..]),
        ("getBodyGyro", &state.gyro[..]),
        ("getBodyAcc", &state.acc[..]),
        ("getRPY", &state.rpy[..]),
        ("getBodyVelocity", &state.body_velocity[..]),
        ("getWorldVelocity", &state.world_velocity[..]),
        ("getPosition", &state.position[..]),
        ("getLegAbadJoint", &a[0][..]),
        ("getLegHipJoint", &a[1][..]),
        ("getLegKneeJoint", &a[2][..]),
        ("getLegAbadJointVel", &v[0][..]),
        ("getLegHipJointVel", &v[1][..]),
        ("getLegKneeJointVel", &v[2][..]),
        ("getLegAbadJointTorque", &t[0][..]),
        ("getLegHipJointTorque", &t[1][..]),
        ("getLegKneeJointTorque", &t[2][..]),
    ] {
        if !getters[getter].is_null() {
            c.floats(getter, values, &getters[getter]);
        }
    }
    if !getters["getBatteryPower"].is_null() {
        c.int("getBatteryPower", state.battery_percent.get().into(), &getters["getBatteryPower"]);
    }
    if !getters["getCurrentCtrlmode"].is_null() {
        c.int("getCurrentCtrlmode", state.control_mode.get().into(), &getters["getCurrentCtrlmode"]);
    }
    if !decoded["u32_1f4_error"].is_null() {
        c.int("u32_1f4_error", state.error_word.get().into(), &decoded["u32_1f4_error"]);
    }
    if state.encode() != bytes {
        c.problems.push("does not re-encode byte for byte".into());
    }
}

fn check_low_level_state(entry: &Value, bytes: &[u8], c: &mut Checker) {
    let decoded = &entry["decoded"];
    let mut state = LowLevelState::default();
    let update = match state.update_lenient(bytes) {
        Ok(u) => u,
        Err(e) => return c.problems.push(format!("does not decode leniently: {e}")),
    };
    let readback = if decoded["readback"].is_null() { decoded } else { &decoded["readback"] };
    let expected_motor_data = readback["haveMotorData"].as_bool().context("haveMotorData");
    match expected_motor_data {
        Ok(expected) if expected == update.header_ok && expected == state.has_motor_data() => {}
        _ => c.problems.push("haveMotorData disagrees".into()),
    }
    if LowLevelState::decode_strict(bytes).is_ok() != state.has_motor_data() {
        c.problems.push("strict decoding disagrees with the magic".into());
    }
    let m = &state.motor;
    let names =
        [["q_abad", "q_hip", "q_knee"], ["qd_abad", "qd_hip", "qd_knee"], ["tau_abad_fb", "tau_hip_fb", "tau_knee_fb"]];
    for (arrays, names) in [&m.q, &m.qd, &m.tau_fb].into_iter().zip(names) {
        for (legs, name) in arrays.iter().zip(names) {
            if !readback[name].is_null() {
                c.floats(name, legs, &readback[name]);
            }
        }
    }
    if !decoded["q_hip_readback"].is_null() {
        c.floats("q_hip_readback", &m.q[1], &decoded["q_hip_readback"]);
    }
    for (getter, values) in [
        ("getQuaternion", &state.quaternion[..]),
        ("getBodyGyro", &state.gyro[..]),
        ("getBodyAcc", &state.acc[..]),
        ("getRPY", &state.rpy[..]),
    ] {
        if !readback[getter].is_null() {
            c.floats(getter, values, &readback[getter]);
        }
    }
    if state.encode() != bytes {
        c.problems.push("does not re-encode byte for byte".into());
    }
}

/// Runs every ZSL-1 fixture.
pub fn check(path: &Path) -> anyhow::Result<Vec<Outcome>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let entries: Vec<Value> = serde_json::from_str(&text)?;
    let mut outcomes = Vec::new();
    for (i, entry) in entries.iter().enumerate() {
        let bytes = hex_decode(entry["hex"].as_str().context("hex")?)?;
        let mut checker = Checker { problems: Vec::new() };
        match (entry["direction"].as_str(), bytes.len()) {
            (Some("sdk->dog"), 40) => check_high_level_command(entry, &bytes, &mut checker),
            (Some("sdk->dog"), 248) => check_low_level_command(entry, &bytes, &mut checker),
            (Some("dog->sdk"), 560) => check_high_level_state(entry, &bytes, &mut checker),
            (Some("dog->sdk"), 272) => check_low_level_state(entry, &bytes, &mut checker),
            (direction, len) => checker.problems.push(format!("unexpected {direction:?} datagram of {len} bytes")),
        }
        let api = entry["api"].as_str().unwrap_or_default();
        let name: String = api.chars().take(48).collect();
        outcomes.push(Outcome::new(format!("#{i:02} {name}"), checker.problems));
    }
    Ok(outcomes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// All 36 datagrams of the vendor's SDK, under `cargo test`.
    #[test]
    fn zsl1_frames_pass() {
        let outcomes = check(&frames_path()).unwrap();
        assert_eq!(outcomes.len(), 36);
        for outcome in outcomes {
            assert!(outcome.problems.is_empty(), "{}: {:?}", outcome.name, outcome.problems);
        }
    }
}
