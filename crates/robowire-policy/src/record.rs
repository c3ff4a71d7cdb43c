//! The `policy` channel of a capture: each policy step as one frame (the step, its inference
//! time, the targets clamped so far, the command, the observation and the actions), described to
//! a recorder as the protocol [`POLICY`] and drawn by `robowire plot` ([`PLOTS`]).
//!
//! A frame, little-endian: step `u64`, inference `u32` ns, clamped `u32`, command `3 × f32`
//! (m/s, m/s, rad/s), then `n_obs` and `n_actions` as `u16`, the observation and the actions as
//! `f32`.

use robowire_core::Direction;
use robowire_core::json::serde_json::json;
use robowire_core::json::{ANY_VALUE, FrameError, JsonFrame, LinkPlots, LinkProtocol, PanelSpec, SeriesSpec};

use crate::control::StepReport;

/// The protocol's name in a capture.
pub const PROTOCOL: &str = "robowire.policy";
/// Its frames' JSON schema.
pub const SCHEMA: &str = "robowire.PolicyStep";
/// The fixed part of a frame, bytes.
const HEAD: usize = 8 + 4 + 4 + 12 + 2 + 2;

/// The policy's steps as a recorded link.
pub static POLICY: LinkProtocol = LinkProtocol {
    name: PROTOCOL,
    layout: "robowire policy step: step u64, inference ns u32, clamped u32, command 3 f32, n_obs u16, n_actions u16, obs, actions (f32, little-endian)",
    decode,
    wire_schema: None,
};

/// A frame of `report` into `out` (cleared first; no allocation once `out` has the room).
pub fn encode(report: &StepReport, out: &mut Vec<u8>) {
    out.clear();
    out.extend_from_slice(&report.step.to_le_bytes());
    let inference_ns = u32::try_from(report.inference.as_nanos()).unwrap_or(u32::MAX);
    out.extend_from_slice(&inference_ns.to_le_bytes());
    out.extend_from_slice(&u32::try_from(report.clamped).unwrap_or(u32::MAX).to_le_bytes());
    for v in report.command {
        out.extend_from_slice(&v.to_le_bytes());
    }
    // Observations and actions are a config's sizes: far below u16::MAX (checked at load).
    for len in [report.obs.len(), report.action.len()] {
        out.extend_from_slice(&u16::try_from(len).unwrap_or(u16::MAX).to_le_bytes());
    }
    for v in report.obs.iter().chain(&report.action) {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

#[derive(Debug, thiserror::Error)]
#[error("a policy step of {n_obs} observations and {n_actions} actions is {expected} bytes")]
struct Length {
    n_obs: usize,
    n_actions: usize,
    expected: usize,
}

fn decode(name: &'static str, _: Direction, frame: &[u8]) -> Result<JsonFrame, FrameError> {
    let short = || FrameError::decode(name, frame, Length { n_obs: 0, n_actions: 0, expected: HEAD });
    let head: &[u8; HEAD] = frame.get(..HEAD).and_then(|h| h.try_into().ok()).ok_or_else(short)?;
    let u16_at = |at: usize| usize::from(u16::from_le_bytes([head[at], head[at + 1]]));
    let u32_at = |at: usize| u32::from_le_bytes([head[at], head[at + 1], head[at + 2], head[at + 3]]);
    let f32_at = |bytes: &[u8], at: usize| f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let (n_obs, n_actions) = (u16_at(28), u16_at(30));
    let expected = HEAD + 4 * (n_obs + n_actions);
    if frame.len() != expected {
        return Err(FrameError::decode(name, frame, Length { n_obs, n_actions, expected }));
    }
    let values: Vec<f32> = (0..n_obs + n_actions).map(|i| f32_at(frame, HEAD + 4 * i)).collect();
    let step = u64::from_le_bytes([head[0], head[1], head[2], head[3], head[4], head[5], head[6], head[7]]);
    let command: Vec<f32> = (0..3).map(|i| f32_at(head, 16 + 4 * i)).collect();
    Ok(JsonFrame {
        schema: SCHEMA,
        value: json!({
            "step": step,
            "inference_us": f64::from(u32_at(8)) / 1e3,
            "clamped": u32_at(12),
            "command": command,
            "obs": &values[..n_obs],
            "action": &values[n_obs..],
        }),
    })
}

const fn series(name: &'static str, pointer: &'static str) -> SeriesSpec {
    SeriesSpec { name, direction: Direction::Sent, schema: SCHEMA, pointer, held: true, range: ANY_VALUE }
}

/// What `robowire plot` draws of a policy's steps: the command, the first actions, the
/// inference time.
pub static PLOTS: [LinkPlots; 1] = [LinkPlots {
    protocol: PROTOCOL,
    panels: &[
        PanelSpec {
            title: "command",
            y_label: "m/s, rad/s",
            series: &[series("vx", "/command/0"), series("vy", "/command/1"), series("wz", "/command/2")],
        },
        PanelSpec {
            title: "actions (the policy's first four joints)",
            y_label: "action",
            series: &[
                series("0", "/action/0"),
                series("1", "/action/1"),
                series("2", "/action/2"),
                series("3", "/action/3"),
            ],
        },
        PanelSpec { title: "inference", y_label: "time (µs)", series: &[series("inference", "/inference_us")] },
    ],
}];

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use robowire_core::json::LinkDescription;

    use super::*;

    #[test]
    fn a_step_reads_back_as_json() {
        let report = StepReport {
            step: 7,
            obs: vec![0.5, -1.0],
            action: vec![0.25],
            command: [0.5, 0.0, -0.25],
            inference: Duration::from_micros(120),
            clamped: 3,
        };
        let mut frame = Vec::new();
        encode(&report, &mut frame);
        let read = POLICY.decode(Direction::Sent, &frame).unwrap();
        assert_eq!(read.schema, SCHEMA);
        assert_eq!(
            read.value,
            json!({"step": 7, "inference_us": 120.0, "clamped": 3, "command": [0.5, 0.0, -0.25], "obs": [0.5, -1.0], "action": [0.25]})
        );
        // Any cut or extra byte is an error, not a panic.
        for len in 0..frame.len() {
            assert!(POLICY.decode(Direction::Sent, &frame[..len]).is_err(), "{len}");
        }
        frame.push(0);
        assert!(POLICY.decode(Direction::Sent, &frame).is_err());
    }
}
