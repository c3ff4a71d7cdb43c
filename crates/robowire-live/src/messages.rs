//! The messages the live view makes itself, in Foxglove's well-known schemas (JSON encoded):
//! `foxglove.Log` for events, `foxglove.FrameTransform` for a robot's base and
//! `foxglove.FrameTransforms` for its bodies; and its own counts.

use std::time::{SystemTime, UNIX_EPOCH};

use foxglove::{RawChannel, Schema};
use robowire_core::json::Value;
use robowire_core::kinematics::Kinematics;
use serde_json::json;

use crate::LiveStats;

/// A `foxglove.Log` level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    /// Detail.
    Debug = 1,
    /// A change of state (connected, armed).
    Info = 2,
    /// Something a user should see (a refusal, a silent peer).
    Warning = 3,
    /// A fault (a damping trip, a lost device).
    Error = 4,
    /// The end of a run.
    Fatal = 5,
}

/// Unix time now, ns (0 before 1970).
pub(crate) fn unix_now_ns() -> u64 {
    SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
}

fn time(unix_ns: u64) -> Value {
    json!({ "sec": unix_ns / 1_000_000_000, "nsec": unix_ns % 1_000_000_000 })
}

/// `message` from `name` at `level` on the log channel.
pub(crate) fn log(channel: &RawChannel, level: Level, name: &str, message: &str) {
    let log = json!({
        "timestamp": time(unix_now_ns()),
        "level": level as u8,
        "message": message,
        "name": name,
        "file": "",
        "line": 0,
    });
    channel.log(&serde_json::to_vec(&log).unwrap_or_default());
}

/// The JSON schema of `foxglove.Log`.
pub(crate) fn log_schema() -> Schema {
    let schema = json!({
        "title": "foxglove.Log",
        "type": "object",
        "properties": {
            "timestamp": time_schema(),
            "level": { "type": "integer", "minimum": 0, "maximum": 5 },
            "message": { "type": "string" },
            "name": { "type": "string" },
            "file": { "type": "string" },
            "line": { "type": "integer", "minimum": 0 },
        },
    });
    Schema::new("foxglove.Log", "jsonschema", serde_json::to_vec(&schema).unwrap_or_default())
}

fn time_schema() -> Value {
    json!({
        "type": "object",
        "properties": { "sec": { "type": "integer", "minimum": 0 }, "nsec": { "type": "integer", "minimum": 0 } },
    })
}

/// `child` in `parent`: a translation, m, then a rotation (w, x, y, z).
fn transform(parent: &str, child: &str, translation_m: [f64; 3], [w, x, y, z]: [f64; 4], unix_ns: u64) -> Value {
    json!({
        "timestamp": time(unix_ns),
        "parent_frame_id": parent,
        "child_frame_id": child,
        "translation": { "x": translation_m[0], "y": translation_m[1], "z": translation_m[2] },
        "rotation": { "x": x, "y": y, "z": z, "w": w },
    })
}

/// A robot's base in the world from a decoded state: its attitude from the IMU's quaternion
/// (`imu_state.quaternion`, Unitree's w, x, y, z) and, where the state says it
/// (`rt/sportmodestate`), its position; the frame is `{device}/base`, the device the link's first
/// name. `None` for a state with no attitude.
pub(crate) fn frame_transform(link: &str, state: &Value, unix_ns: u64) -> Option<Value> {
    let number = |v: &Value| v.as_f64().filter(|x| x.is_finite());
    let quaternion = state.pointer("/imu_state/quaternion")?.as_array()?;
    let [w, x, y, z] = <[&Value; 4]>::try_from(quaternion.iter().collect::<Vec<_>>()).ok()?.map(number);
    let (w, x, y, z) = (w?, x?, y?, z?);
    let norm = (w * w + x * x + y * y + z * z).sqrt();
    if norm < 1e-6 {
        return None;
    }
    let position = state.pointer("/position").and_then(Value::as_array).filter(|p| p.len() == 3);
    let at = |i: usize| position.and_then(|p| number(&p[i])).unwrap_or(0.0);
    let device = link.split('/').next().unwrap_or(link);
    let rotation = [w, x, y, z].map(|c| c / norm);
    Some(transform("world", &format!("{device}/base"), [at(0), at(1), at(2)], rotation, unix_ns))
}

/// A robot's base in the world from where a simulator or an estimator says it is: position, m,
/// and roll, pitch, yaw (ZYX), rad.
pub(crate) fn base_transform(device: &str, position_m: [f64; 3], rpy_rad: [f64; 3], unix_ns: u64) -> Value {
    let [roll, pitch, yaw] = rpy_rad.map(|a| a / 2.0);
    let (cr, sr, cp, sp, cy, sy) = (roll.cos(), roll.sin(), pitch.cos(), pitch.sin(), yaw.cos(), yaw.sin());
    let rotation = [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ];
    transform("world", &format!("{device}/base"), position_m, rotation, unix_ns)
}

/// A robot's bodies from a decoded state of `robot`'s: each body's frame (`{device}/{body}`) in
/// its parent's (`{device}/base` for the base's children) at the state's joint positions, as
/// one `foxglove.FrameTransforms`. A body whose hinge's position is missing or not finite is left
/// out. `None` for a state without its motors.
pub(crate) fn joint_transforms(device: &str, robot: &Kinematics, state: &Value, unix_ns: u64) -> Option<Value> {
    let motors = state.pointer(robot.motor_states_pointer)?.as_array()?;
    let transforms: Vec<Value> = robot
        .bodies
        .iter()
        .filter_map(|body| {
            let q = match body.hinge {
                Some(hinge) => Some(motors.get(hinge.motor)?.get("q")?.as_f64().filter(|q| q.is_finite())?),
                None => None,
            };
            let pose = body.pose(q);
            let (parent, child) = (format!("{device}/{}", body.parent), format!("{device}/{}", body.name));
            Some(transform(&parent, &child, pose.translation_m, pose.rotation, unix_ns))
        })
        .collect();
    Some(json!({ "transforms": transforms }))
}

/// `foxglove.FrameTransform`'s JSON schema.
fn frame_transform_json_schema() -> Value {
    let vector = |names: &[&str]| {
        let properties: serde_json::Map<String, Value> =
            names.iter().map(|n| ((*n).to_string(), json!({ "type": "number" }))).collect();
        json!({ "type": "object", "properties": properties })
    };
    json!({
        "title": "foxglove.FrameTransform",
        "type": "object",
        "properties": {
            "timestamp": time_schema(),
            "parent_frame_id": { "type": "string" },
            "child_frame_id": { "type": "string" },
            "translation": vector(&["x", "y", "z"]),
            "rotation": vector(&["x", "y", "z", "w"]),
        },
    })
}

/// The schema of `foxglove.FrameTransform`.
pub(crate) fn frame_transform_schema() -> Schema {
    let schema = frame_transform_json_schema();
    Schema::new("foxglove.FrameTransform", "jsonschema", serde_json::to_vec(&schema).unwrap_or_default())
}

/// The schema of `foxglove.FrameTransforms`.
pub(crate) fn frame_transforms_schema() -> Schema {
    let schema = json!({
        "title": "foxglove.FrameTransforms",
        "type": "object",
        "properties": { "transforms": { "type": "array", "items": frame_transform_json_schema() } },
    });
    Schema::new("foxglove.FrameTransforms", "jsonschema", serde_json::to_vec(&schema).unwrap_or_default())
}

/// The counts as `/robowire/live` says them.
pub(crate) fn live_stats_json(stats: &LiveStats) -> Value {
    json!({
        "channels": stats.links.iter().map(|l| json!({
            "topic": l.topic, "seen": l.seen, "sent": l.sent, "undecodable": l.undecodable,
        })).collect::<Vec<_>>(),
        "clients": stats.viewers.iter().map(|v| json!({
            "addr": v.addr.to_string(), "forwarded": v.forwarded, "dropped": v.dropped,
        })).collect::<Vec<_>>(),
        "ring_dropped": stats.ring_dropped,
        "viewer_dropped_total": stats.viewer_dropped_total,
    })
}

/// The JSON schema of `/robowire/live`.
pub(crate) fn live_stats_schema() -> Schema {
    let counts = |fields: &[&str]| {
        let mut properties: serde_json::Map<String, Value> =
            fields.iter().map(|n| ((*n).to_string(), json!({ "type": "integer", "minimum": 0 }))).collect();
        for name in ["topic", "addr"] {
            properties.insert(name.into(), json!({ "type": "string" }));
        }
        json!({ "type": "array", "items": { "type": "object", "properties": properties } })
    };
    let schema = json!({
        "title": "robowire.LiveStats",
        "type": "object",
        "properties": {
            "channels": counts(&["seen", "sent", "undecodable"]),
            "clients": counts(&["forwarded", "dropped"]),
            "ring_dropped": { "type": "integer", "minimum": 0 },
            "viewer_dropped_total": { "type": "integer", "minimum": 0 },
        },
    });
    Schema::new("robowire.LiveStats", "jsonschema", serde_json::to_vec(&schema).unwrap_or_default())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pose_s_roll_pitch_yaw_is_the_zyx_quaternion() {
        let t = base_transform("go2", [1.0, 2.0, 0.3], [0.0, 0.0, std::f64::consts::FRAC_PI_2], 0);
        let r = &t["rotation"];
        let half = std::f64::consts::FRAC_1_SQRT_2;
        for (axis, want) in [("x", 0.0), ("y", 0.0), ("z", half), ("w", half)] {
            assert!((r[axis].as_f64().unwrap() - want).abs() < 1e-12, "{axis}: {t}");
        }
        assert_eq!(t["translation"], json!({ "x": 1.0, "y": 2.0, "z": 0.3 }));
        // Roll alone turns about x.
        let t = base_transform("go2", [0.0; 3], [0.2, 0.0, 0.0], 0);
        assert!((t["rotation"]["x"].as_f64().unwrap() - 0.1f64.sin()).abs() < 1e-12, "{t}");
    }

    #[test]
    fn an_imu_quaternion_is_the_base_frame_and_a_position_its_place() {
        let state = json!({ "imu_state": { "quaternion": [2.0, 0.0, 0.0, 0.0] } });
        let t = frame_transform("go2/low_level", &state, 1_500_000_000).unwrap();
        assert_eq!(t["child_frame_id"], "go2/base");
        assert_eq!(t["rotation"], json!({ "x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0 }));
        assert_eq!(t["translation"], json!({ "x": 0.0, "y": 0.0, "z": 0.0 }));
        assert_eq!(t["timestamp"], json!({ "sec": 1, "nsec": 500_000_000 }));
        let state = json!({ "imu_state": { "quaternion": [1, 0, 0, 0] }, "position": [1.0, 2.0, 0.3] });
        assert_eq!(frame_transform("g1", &state, 0).unwrap()["translation"], json!({ "x": 1.0, "y": 2.0, "z": 0.3 }));
        for bad in [
            json!({}),
            json!({ "imu_state": { "quaternion": [0, 0, 0, 0] } }),
            json!({ "imu_state": { "quaternion": [1, 0, 0] } }),
            json!({ "imu_state": { "quaternion": ["NaN", 0, 0, 0] } }),
        ] {
            assert!(frame_transform("go2", &bad, 0).is_none(), "{bad}");
        }
    }
}
