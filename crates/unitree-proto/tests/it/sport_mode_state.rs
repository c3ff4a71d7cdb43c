//! The Go2 `SportModeState_` codec against Unitree's own IDL class serialized by CycloneDDS'
//! Python binding (CPython 3.10, `robowire_fixtures::peers`; gated like every interop test): the
//! same bytes in XCDR1 and XCDR2, and every field of the vendor's sample read back.

use std::path::Path;
use std::process::Command;

use robowire_core::cdr::{CdrEncoding, CdrType};
use serde_json::Value;
use unitree_proto::F32;
use unitree_proto::sport_state::{PathPoint, SPORT_MODE_STATE_LAYOUT, SportModeState};

fn f32s(value: &Value) -> Vec<f32> {
    value.as_array().unwrap().iter().map(|v| v.as_f64().unwrap() as f32).collect()
}

fn f32_of(value: &Value) -> f32 {
    value.as_f64().unwrap() as f32
}

fn gets(values: &[F32]) -> Vec<f32> {
    values.iter().map(|v| v.get()).collect()
}

/// The sample of `tests/interop/sport_mode_state.py`, made here independently: the floats are
/// `k * 0.731 - 97.25` for k = 1, 2, ... in IDL field order, computed in f64 and rounded to f32.
fn the_scripts_sample() -> SportModeState {
    let mut k = 0.0f64;
    let mut next = || {
        k += 1.0;
        F32::new((k * 0.731 - 97.25) as f32)
    };
    let mut s = SportModeState::default();
    s.stamp.sec = (-123456).into();
    s.stamp.nanosec = 987654321.into();
    s.imu_state.quaternion = std::array::from_fn(|_| next());
    s.imu_state.gyroscope = std::array::from_fn(|_| next());
    s.imu_state.accelerometer = std::array::from_fn(|_| next());
    s.imu_state.rpy = std::array::from_fn(|_| next());
    s.imu_state.temperature = 201;
    s.error_code = 0xDEAD_BEEF.into();
    s.mode = 7;
    s.progress = next();
    s.gait_type = 3;
    s.foot_raise_height = next();
    s.position = std::array::from_fn(|_| next());
    s.body_height = next();
    s.velocity = std::array::from_fn(|_| next());
    s.yaw_speed = next();
    s.range_obstacle = std::array::from_fn(|_| next());
    s.foot_force = [-1, 300, -32768, 32767].map(Into::into);
    s.foot_position_body = std::array::from_fn(|_| next());
    s.foot_speed_body = std::array::from_fn(|_| next());
    for point in &mut s.path_point {
        let [t_from_start, x, y, yaw, vx, vy, vyaw] = std::array::from_fn(|_| next());
        *point = PathPoint { t_from_start, x, y, yaw, vx, vy, vyaw };
    }
    s
}

/// Every field of `state` against the vendor's `fields` (`dataclasses.asdict` of its sample).
fn assert_fields(state: &SportModeState, f: &Value, what: &str) {
    let names: Vec<&str> = f.as_object().unwrap().keys().map(String::as_str).collect();
    let idl: Vec<&str> = SPORT_MODE_STATE_LAYOUT.idl_fields().map(|field| field.name).collect();
    assert_eq!(names.len(), idl.len(), "{what}: the vendor's fields {names:?}, ours {idl:?}");
    assert!(idl.iter().all(|n| names.contains(n)), "{what}: the vendor's fields {names:?}, ours {idl:?}");

    assert_eq!(i64::from(state.stamp.sec.get()), f["stamp"]["sec"].as_i64().unwrap(), "{what}: stamp.sec");
    assert_eq!(u64::from(state.stamp.nanosec.get()), f["stamp"]["nanosec"].as_u64().unwrap(), "{what}: stamp.nanosec");
    assert_eq!(u64::from(state.error_code.get()), f["error_code"].as_u64().unwrap(), "{what}: error_code");
    let imu = &f["imu_state"];
    assert_eq!(gets(&state.imu_state.quaternion), f32s(&imu["quaternion"]), "{what}: imu_state.quaternion");
    assert_eq!(gets(&state.imu_state.gyroscope), f32s(&imu["gyroscope"]), "{what}: imu_state.gyroscope");
    assert_eq!(gets(&state.imu_state.accelerometer), f32s(&imu["accelerometer"]), "{what}: imu_state.accelerometer");
    assert_eq!(gets(&state.imu_state.rpy), f32s(&imu["rpy"]), "{what}: imu_state.rpy");
    assert_eq!(u64::from(state.imu_state.temperature), imu["temperature"].as_u64().unwrap(), "{what}: temperature");
    assert_eq!(u64::from(state.mode), f["mode"].as_u64().unwrap(), "{what}: mode");
    assert_eq!(state.progress.get(), f32_of(&f["progress"]), "{what}: progress");
    assert_eq!(u64::from(state.gait_type), f["gait_type"].as_u64().unwrap(), "{what}: gait_type");
    assert_eq!(state.foot_raise_height.get(), f32_of(&f["foot_raise_height"]), "{what}: foot_raise_height");
    assert_eq!(gets(&state.position), f32s(&f["position"]), "{what}: position");
    assert_eq!(state.body_height.get(), f32_of(&f["body_height"]), "{what}: body_height");
    assert_eq!(gets(&state.velocity), f32s(&f["velocity"]), "{what}: velocity");
    assert_eq!(state.yaw_speed.get(), f32_of(&f["yaw_speed"]), "{what}: yaw_speed");
    assert_eq!(gets(&state.range_obstacle), f32s(&f["range_obstacle"]), "{what}: range_obstacle");
    let foot_force: Vec<i64> = f["foot_force"].as_array().unwrap().iter().map(|v| v.as_i64().unwrap()).collect();
    assert_eq!(state.foot_force.map(|v| i64::from(v.get())).to_vec(), foot_force, "{what}: foot_force");
    assert_eq!(gets(&state.foot_position_body), f32s(&f["foot_position_body"]), "{what}: foot_position_body");
    assert_eq!(gets(&state.foot_speed_body), f32s(&f["foot_speed_body"]), "{what}: foot_speed_body");
    let points = f["path_point"].as_array().unwrap();
    assert_eq!(points.len(), state.path_point.len(), "{what}: path_point");
    for (i, (ours, theirs)) in state.path_point.iter().zip(points).enumerate() {
        let values = [ours.t_from_start, ours.x, ours.y, ours.yaw, ours.vx, ours.vy, ours.vyaw].map(|v| v.get());
        let names = ["t_from_start", "x", "y", "yaw", "vx", "vy", "vyaw"];
        assert_eq!(values.to_vec(), names.map(|n| f32_of(&theirs[n])).to_vec(), "{what}: path_point[{i}]");
    }
}

#[test]
fn unitree_sport_mode_state_serialized_by_cyclonedds_is_our_bytes() {
    let Some(python) = robowire_fixtures::interop::require(robowire_fixtures::peers::unitree_python()) else {
        return;
    };
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/interop/sport_mode_state.py");
    let out = Command::new(python).arg(script).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let vendor: Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();

    let ours = the_scripts_sample();
    assert_fields(&ours, &vendor["fields"], "our sample");
    for (key, encoding, len) in [("xcdr1", CdrEncoding::Xcdr1, 512), ("xcdr2", CdrEncoding::Xcdr2, 516)] {
        let payload = vendor[key].as_str().and_then(robowire_fixtures::hex_bytes);
        let payload = payload.unwrap_or_else(|| panic!("no {key} payload: {vendor}"));
        assert_eq!(payload[..4], encoding.header(), "{key}: the encapsulation header");
        let mut body = [0u8; 516];
        assert_eq!(ours.encode_cdr_body(encoding, &mut body), Ok(len), "{key}");
        assert_eq!(payload[4..], body[..len], "{key}: Unitree's bytes are ours");
        let decoded = SportModeState::decode_body(encoding, &payload[4..]).unwrap();
        assert_fields(&decoded, &vendor["fields"], key);
        assert_eq!(decoded, ours, "{key}");
    }
}
