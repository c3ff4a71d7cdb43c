//! `robowire decode zsl`: a ZSL-1 UDP datagram, told by its length and magic, decoded strictly.

use std::process::ExitCode;

use anyhow::bail;
use clap::Args;
use serde_json::{Map, Value, json};
use zsl_proto::udp::{HighLevelCommand, HighLevelState, LowLevelCommand, LowLevelState, Model};
use zsl_proto::zerocopy::little_endian::F32;

use crate::hex;

#[derive(Debug, Args)]
pub(crate) struct ZslDecodeArgs {
    /// The datagram in hex (40, 248, 272 or 560 bytes), or '-' for standard input.
    hex: String,
    /// One JSON object on one line.
    #[arg(long)]
    json: bool,
}

/// An f32 as its shortest JSON number, non-finite values as strings.
fn f(v: f32) -> Value {
    if v.is_finite() {
        serde_json::from_str(&serde_json::to_string(&v).unwrap_or_default()).unwrap_or(Value::Null)
    } else if v.is_nan() {
        Value::from(if v.is_sign_negative() { "-NaN" } else { "NaN" })
    } else {
        Value::from(if v > 0.0 { "Infinity" } else { "-Infinity" })
    }
}

fn fs(values: &[F32]) -> Value {
    Value::Array(values.iter().map(|v| f(v.get())).collect())
}

fn model_name(model: Model) -> &'static str {
    match model {
        Model::Zsl1 => "zsl-1",
        Model::Zsl1W => "zsl-1w",
    }
}

fn by_joint(names: [&str; 3], arrays: &[[F32; 4]; 3], object: &mut Map<String, Value>) {
    for (name, legs) in names.iter().zip(arrays) {
        object.insert((*name).to_string(), fs(legs));
    }
}

fn decode(bytes: &[u8]) -> anyhow::Result<Value> {
    Ok(match bytes.len() {
        HighLevelCommand::LEN => {
            let (c, model) = HighLevelCommand::decode(bytes)?;
            json!({
                "datagram": "high_level_command",
                "model": model_name(model),
                "mode": c.mode.get(),
                "mode_name": format!("{:?}", c.control_mode()),
                "action": c.action.get(),
                "action_name": format!("{:?}", c.action_code()),
                "flag": c.flag.get(),
                "vx_mps": f(c.vx.get()),
                "vy_mps": f(c.vy.get()),
                "roll_rate_radps": f(c.roll_rate.get()),
                "pitch_rate_radps": f(c.pitch_rate.get()),
                "yaw_rate_radps": f(c.yaw_rate.get()),
                "height_rate_mps": f(c.height_rate.get()),
                "checksum": c.checksum(),
            })
        }
        LowLevelCommand::LEN => {
            let (c, model) = LowLevelCommand::decode(bytes)?;
            let mut o = Map::new();
            o.insert("datagram".into(), "low_level_command".into());
            o.insert("model".into(), model_name(model).into());
            let m = &c.motor;
            by_joint(["q_des_abad", "q_des_hip", "q_des_knee"], &m.q_des, &mut o);
            by_joint(["qd_des_abad", "qd_des_hip", "qd_des_knee"], &m.qd_des, &mut o);
            by_joint(["kp_abad", "kp_hip", "kp_knee"], &m.kp, &mut o);
            by_joint(["kd_abad", "kd_hip", "kd_knee"], &m.kd, &mut o);
            by_joint(["tau_abad_ff", "tau_hip_ff", "tau_knee_ff"], &m.tau_ff, &mut o);
            o.insert("checksum".into(), c.checksum().into());
            Value::Object(o)
        }
        HighLevelState::LEN => high_level_state_json(&HighLevelState::decode_strict(bytes)?),
        LowLevelState::LEN => {
            let s = LowLevelState::decode_strict(bytes)?;
            let mut o = Map::new();
            o.insert("datagram".into(), "low_level_state".into());
            let m = &s.motor;
            by_joint(["q_abad", "q_hip", "q_knee"], &m.q, &mut o);
            by_joint(["qd_abad", "qd_hip", "qd_knee"], &m.qd, &mut o);
            by_joint(["tau_abad_fb", "tau_hip_fb", "tau_knee_fb"], &m.tau_fb, &mut o);
            o.insert("quaternion_wxyz".into(), fs(&s.quaternion));
            o.insert("gyro_radps".into(), fs(&s.gyro));
            o.insert("acc_mps2".into(), fs(&s.acc));
            o.insert("rpy_rad".into(), fs(&s.rpy));
            Value::Object(o)
        }
        n => bail!(
            "{n} bytes is no ZSL-1 datagram (40 HighLevel command, 560 HighLevel state, 248 LowLevel command, 272 LowLevel state)"
        ),
    })
}

pub(crate) fn run(args: &ZslDecodeArgs) -> anyhow::Result<ExitCode> {
    let bytes = hex::parse_arg(&args.hex)?;
    let value = decode(&bytes)?;
    if args.json {
        println!("{}", serde_json::to_string(&value)?);
    } else {
        println!("{}", serde_json::to_string_pretty(&value)?);
    }
    Ok(ExitCode::SUCCESS)
}

/// A HighLevel state as JSON (the `robowire decode zsl` and `robowire dog status --json` schema).
pub(crate) fn high_level_state_json(s: &HighLevelState) -> Value {
    let joints = |a: &[[F32; 4]; 4]| json!({"abad": fs(&a[0]), "hip": fs(&a[1]), "knee": fs(&a[2]), "foot": fs(&a[3])});
    json!({
        "datagram": "high_level_state",
        "mode": s.control_mode.get(),
        "mode_name": format!("{:?}", s.mode()),
        "battery_percent": s.battery_percent.get(),
        "error_word": s.error_word.get(),
        "error_name": format!("{:?}", s.error()),
        "sdk_mismatch": s.sdk_mismatch.get(),
        "quaternion_wxyz": fs(&s.quaternion),
        "gyro_radps": fs(&s.gyro),
        "acc_mps2": fs(&s.acc),
        "rpy_rad": fs(&s.rpy),
        "body_velocity_mps": fs(&s.body_velocity),
        "world_velocity_mps": fs(&s.world_velocity),
        "position_m": fs(&s.position),
        "joint_angle_rad": joints(&s.joint_angle),
        "joint_velocity_radps": joints(&s.joint_velocity),
        "joint_torque_nm": joints(&s.joint_torque),
    })
}
