//! Rows of the benchmarks over DDS and of the apps above the facades: the Go2 and G1 round
//! trips, the ROS 2 bridge, recording, physics.

use anyhow::Context;
use serde_json::Value;

use super::Row;

/// The bridge's `cmd_vel` → datagram against the sum of its legs (p50).
const CMD_VEL_LEGS_RATIO: f64 = 1.2;

/// The ROS 2 bridge: `cmd_vel` → the ZSL-1 datagram, beside its two legs measured in the same run.
pub(crate) fn ros2_row(meta: &Value) -> anyhow::Result<Row> {
    let us = |key: &str| meta[key].as_f64().with_context(|| format!("ros2 meta {key}"));
    let (p50, p99) = (us("cmd_vel_to_wire_p50_us")?, us("cmd_vel_to_wire_p99_us")?);
    let (dds, call) = (us("dds_twist_p50_us")?, us("call_to_wire_p50_us")?);
    Ok(Row {
        path: "ROS 2 cmd_vel (Twist written) → ZSL-1 datagram at the dog, through robowire ros2".into(),
        figure: format!("p50 {p50:.1} µs, p99 {p99:.1} µs"),
        baseline: format!("its legs: DDS Twist delivery p50 {dds:.1} µs + move_velocity() → wire p50 {call:.1} µs"),
        ratio: format!("{:.2}× the legs", p50 / (dds + call)),
        target: format!("p50 ≤ {CMD_VEL_LEGS_RATIO}× the legs"),
        met: Some(p50 / (dds + call) <= CMD_VEL_LEGS_RATIO),
    })
}

/// Recording: the streams' send lateness with their links recorded and without (`recorded`,
/// the `robowire` crate's bench `recorded`), and the recorder's throughput (`meta`,
/// `robowire-record`'s bench `record`).
pub(crate) fn record_rows(recorded: &Value, meta: &Value) -> anyhow::Result<Vec<Row>> {
    let n = |key: &str| recorded[key].as_f64().with_context(|| format!("recorded meta {key}"));
    let (p50, p99) = (n("lateness_recorded_p50_us")?, n("lateness_recorded_p99_us")?);
    let (b50, b99) = (n("lateness_plain_p50_us")?, n("lateness_plain_p99_us")?);
    let dropped = n("stream_frames_dropped")?;
    Ok(vec![
        Row {
            path: "ZSL-1 HighLevel stream send lateness, its link recorded to MCAP".into(),
            figure: format!("p50 {p50:.0} µs, p99 {p99:.0} µs ({dropped:.0} frames dropped)"),
            baseline: format!("not recorded: p50 {b50:.0} µs, p99 {b99:.0} µs"),
            ratio: format!("p99 {:+.0} µs", p99 - b99),
            target: "–".into(),
            met: None,
        },
        stream_row(&recorded["kmc_stream"], "KMC Driver 0xA5 stream (100 Hz) send lateness, its serial link recorded")?,
        stream_row(
            &recorded["spline_stream"],
            "spline daemon simulator (1 kHz) send lateness, its shared memory recorded",
        )?,
        live_row(&recorded["live_stream"])?,
        throughput_row(&meta["unpaced_raw"], "Recorder capacity: 560-byte frames as fast as one thread taps, raw")?,
        throughput_row(
            &meta["unpaced_json"],
            "Recorder capacity: 560-byte frames as fast as one thread taps, with JSON",
        )?,
        paced_row(&meta["paced_1m_raw"], "Recorder at 1 M frames/s: 560-byte frames, raw")?,
        paced_row(&meta["paced_1m_raw_64b"], "Recorder at 1 M frames/s: 64-byte frames, raw")?,
        paced_row(&meta["links_100_at_1khz"], "Recorder: 100 links × 1 kHz (560-byte frames), with JSON")?,
        paced_row(&meta["links_100_at_1khz_zstd"], "Recorder: 100 links × 1 kHz, with JSON, zstd chunks")?,
    ])
}

/// A recorder run tapped as fast as one thread can: what the writer wrote per second.
fn throughput_row(run: &Value, path: &str) -> anyhow::Result<Row> {
    let n = |key: &str| run[key].as_f64().with_context(|| format!("record meta {key}"));
    Ok(Row {
        path: path.into(),
        figure: format!("{:.0} k frames/s written, {:.0} MB/s", n("written_per_s")? / 1e3, n("mb_per_s")?),
        baseline: format!(
            "offered {:.0} at {:.1} M/s; written {:.0}, dropped {:.0}, without JSON {:.0}",
            n("offered")?,
            n("offered_per_s")? / 1e6,
            n("written")?,
            n("dropped")?,
            n("json_skipped")?
        ),
        ratio: "–".into(),
        target: "–".into(),
        met: None,
    })
}

/// A recorder run tapped at a set rate: what was dropped (the target: nothing).
fn paced_row(run: &Value, path: &str) -> anyhow::Result<Row> {
    let n = |key: &str| run[key].as_f64().with_context(|| format!("record meta {key}"));
    let (offered, dropped) = (n("offered")?, n("dropped")?);
    Ok(Row {
        path: path.into(),
        figure: format!(
            "{:.0} dropped of {:.0} ({:.1} %), {:.0} without JSON",
            dropped,
            offered,
            100.0 * dropped / offered.max(1.0),
            n("json_skipped")?
        ),
        baseline: format!(
            "offered at {:.2} M frames/s, written at {:.0} MB/s",
            n("offered_per_s")? / 1e6,
            n("mb_per_s")?
        ),
        ratio: "–".into(),
        target: "none dropped".into(),
        met: Some(dropped == 0.0),
    })
}

/// The ZSL-1 stream streamed live to a viewer that reads nothing, beside the live view alone.
fn live_row(run: &Value) -> anyhow::Result<Row> {
    let n = |key: &str| run[key].as_f64().with_context(|| format!("live meta {key}"));
    let (p99, b99) = (n("stalled_p99_us")?, n("plain_p99_us")?);
    Ok(Row {
        path: "ZSL-1 HighLevel stream send lateness, its link live at 1 kHz to a viewer that reads nothing".into(),
        figure: format!(
            "p50 {:.0} µs, p99 {p99:.0} µs ({:.0} messages dropped for the viewer)",
            n("stalled_p50_us")?,
            n("viewer_dropped")?
        ),
        baseline: format!("live, no viewer: p50 {:.0} µs, p99 {b99:.0} µs", n("plain_p50_us")?),
        ratio: format!("p99 {:+.0} µs", p99 - b99),
        target: "–".into(),
        met: None,
    })
}

/// A stream recorded and not, alternating: its lateness each way.
fn stream_row(run: &Value, path: &str) -> anyhow::Result<Row> {
    let n = |key: &str| run[key].as_f64().with_context(|| format!("recorded meta {key}"));
    let (p99, b99) = (n("recorded_p99_us")?, n("plain_p99_us")?);
    Ok(Row {
        path: path.into(),
        figure: format!("p50 {:.0} µs, p99 {p99:.0} µs ({:.0} frames dropped)", n("recorded_p50_us")?, n("dropped")?),
        baseline: format!("not recorded: p50 {:.0} µs, p99 {b99:.0} µs", n("plain_p50_us")?),
        ratio: format!("p99 {:+.0} µs", p99 - b99),
        target: "–".into(),
        met: None,
    })
}

/// The physics rows (`cargo bench -p robowire-sim --features mujoco --bench physics` and the DDS
/// bench's 500 Hz round trips): each model's real-time factor beside the kinematic joint model,
/// and the Go2 round trip with physics on beside the kinematic simulator; none without MuJoCo.
pub(crate) fn physics_rows(physics: Option<&Value>, dds: &Value) -> anyhow::Result<Vec<Row>> {
    let Some(physics) = physics else { return Ok(Vec::new()) };
    let rtf = |key: &str| physics[key].as_f64().with_context(|| format!("physics meta {key}"));
    let mut rows = Vec::new();
    for (robot, label) in [("go2", "Go2 standing"), ("g1", "G1 hanging, 29 joints")] {
        let (physics, kinematic) = (rtf(&format!("{robot}_physics_rtf"))?, rtf(&format!("{robot}_kinematic_rtf"))?);
        rows.push(Row {
            path: format!("{label}: MuJoCo at 1 kHz, LowState built and encoded at 500 Hz, one thread"),
            figure: format!("{physics:.0}× real time"),
            baseline: format!("kinematic joint model, same loop: {kinematic:.0}×"),
            ratio: format!("{:.3}×", physics / kinematic),
            target: "≥ 1× real time".into(),
            met: Some(physics >= 1.0),
        });
    }
    let trips = &dds["go2_500hz_round_trip"];
    let us = |body: &str, pct: &str| trips[body][pct].as_f64().with_context(|| format!("dds meta {body}.{pct}"));
    for pct in ["p50", "p99"] {
        let (physics, kinematic) = (us("physics_us", pct)?, us("kinematic_us", pct)?);
        rows.push(Row {
            path: format!("Go2 LowCmd → LowState answer, 500 Hz stream, physics on, {pct}"),
            figure: format!("{physics:.1} µs"),
            baseline: format!("kinematic simulator, same settings: {kinematic:.1} µs"),
            ratio: format!("{:.2}×", physics / kinematic),
            target: "–".into(),
            met: None,
        });
    }
    Ok(rows)
}

/// The round trips over DDS against twice `ddsperf`'s figure, the one way against its half: ≤ 1.0×.
const DDS_ROUND_TRIP_RATIO: f64 = 1.0;

/// Rows of the DDS bench: round trip and one way, beside `ddsperf` with the same payload.
pub(crate) fn dds_rows(meta: &Value) -> anyhow::Result<Vec<Row>> {
    let us = |path: [&str; 2]| meta[path[0]][path[1]].as_f64().with_context(|| format!("dds meta {path:?}"));
    let trip_s = meta["round_trip_seconds"].as_f64().context("dds meta round_trip_seconds")?;
    let rounds = meta["round_trip_rounds"].as_f64().context("dds meta round_trip_rounds")?;
    let turns = format!("{trip_s:.0} s in {rounds:.0} turns with ddsperf");
    let (half50, half99) = (us(["ddsperf_half_round_trip_us", "p50"])?, us(["ddsperf_half_round_trip_us", "p99"])?);
    let mut rows = Vec::new();
    for pct in ["p50", "p99"] {
        let (trip, half) = (us(["round_trip_us", pct])?, if pct == "p50" { half50 } else { half99 });
        let ratio = trip / (2.0 * half);
        rows.push(Row {
            path: format!(
                "Go2 LowCmd → LowState answer via the simulator, DDS on loopback, taken by a listener, {pct} ({turns})"
            ),
            figure: format!("{trip:.1} µs"),
            baseline: format!("CycloneDDS ddsperf ping/pong, 812 B, round trip: {:.1} µs", 2.0 * half),
            ratio: format!("{ratio:.2}×"),
            target: format!("≤ {DDS_ROUND_TRIP_RATIO}× ddsperf"),
            met: Some(ratio <= DDS_ROUND_TRIP_RATIO),
        });
    }
    let (g_half50, g_half99) =
        (us(["ddsperf_1000_half_round_trip_us", "p50"])?, us(["ddsperf_1000_half_round_trip_us", "p99"])?);
    for pct in ["p50", "p99"] {
        let (trip, half) = (us(["g1_round_trip_us", pct])?, if pct == "p50" { g_half50 } else { g_half99 });
        let ratio = trip / (2.0 * half);
        rows.push(Row {
            path: format!(
                "G1 LowCmd → LowState answer via the simulator, DDS on loopback, taken by a listener, {pct} ({turns})"
            ),
            figure: format!("{trip:.1} µs"),
            baseline: format!("CycloneDDS ddsperf ping/pong, 1000 B, round trip: {:.1} µs", 2.0 * half),
            ratio: format!("{ratio:.2}×"),
            target: format!("≤ {DDS_ROUND_TRIP_RATIO}× ddsperf"),
            met: Some(ratio <= DDS_ROUND_TRIP_RATIO),
        });
    }
    let (t50, t99) = (us(["round_trip_task_us", "p50"])?, us(["round_trip_task_us", "p99"])?);
    rows.push(Row {
        path: format!(
            "Go2 LowCmd → LowState answer via the simulator, the answer taken by a task (`Reader::recv`) ({turns})"
        ),
        figure: format!("p50 {t50:.1} µs, p99 {t99:.1} µs"),
        baseline: format!(
            "taken by a listener: p50 {:.1} µs, p99 {:.1} µs",
            us(["round_trip_us", "p50"])?,
            us(["round_trip_us", "p99"])?
        ),
        ratio: format!("{:.2}× (p50)", t50 / us(["round_trip_us", "p50"])?),
        target: "–".into(),
        met: None,
    });
    let (w50, w99) = (us(["one_way_us", "p50"])?, us(["one_way_us", "p99"])?);
    for (pct, way, half) in [("p50", w50, half50), ("p99", w99, half99)] {
        let ratio = way / half;
        rows.push(Row {
            path: format!(
                "Go2 LowCmd write (encode, CRC, RTPS) → verified at a listener of another participant, one way, {pct}"
            ),
            figure: format!("{way:.1} µs"),
            baseline: format!("ddsperf half round trip, 812 B: {half:.1} µs"),
            ratio: format!("{ratio:.2}×"),
            target: format!("≤ {DDS_ROUND_TRIP_RATIO}× ddsperf's half"),
            met: Some(ratio <= DDS_ROUND_TRIP_RATIO),
        });
    }
    rows.extend(super::stalled_reader_rows(&meta["stalled_reader"])?);
    Ok(rows)
}

/// The G1 walking policy's inference beside a matrix product of the same weights, p50 and p99;
/// running on a G1, its ticks' lateness beside the LowCmd stream's, and the stream's lateness
/// while it runs beside the stream holding a pose without it.
pub(crate) fn policy_rows(policy: Option<&Value>) -> anyhow::Result<Vec<Row>> {
    let Some(policy) = policy else { return Ok(Vec::new()) };
    let ns = |model: &str, pct: &str| {
        policy[model][format!("{pct}_ns")].as_f64().with_context(|| format!("policy meta {model}.{pct}_ns"))
    };
    let shape = format!("{}×{}", policy["matmul"]["rows"], policy["matmul"]["columns"]);
    let mut rows = ["p50", "p99"]
        .into_iter()
        .map(|pct| {
            let (model, plain) = (ns("g1", pct)?, ns("matmul", pct)?);
            Ok(Row {
                path: format!("Unitree's G1 walking policy, one step on tract (LSTM 47 → 64, 64 → 32 → 12), {pct}"),
                figure: format!("{:.1} µs", model / 1e3),
                baseline: format!("tract MatMul of the same weights (1×47 · {shape}): {:.1} µs", plain / 1e3),
                ratio: format!("{:.2}×", model / plain),
                target: "–".into(),
                met: None,
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let running = &policy["running"];
    if running.is_null() {
        return Ok(rows);
    }
    let us = |phase: &str, pct: &str| {
        running[phase][format!("{pct}_us")].as_f64().with_context(|| format!("policy meta running.{phase}.{pct}_us"))
    };
    for pct in ["p50", "p99"] {
        let (ticks, stream) = (us("ticks", pct)?, us("stream_walking", pct)?);
        rows.push(Row {
            path: format!(
                "The G1 policy's ticks at 50 Hz on robowire's runner (kinematic sim G1, facade), lateness {pct}"
            ),
            figure: format!("{ticks:.0} µs"),
            baseline: format!("the facade's 500 Hz LowCmd stream meanwhile: {stream:.0} µs"),
            ratio: "–".into(),
            target: "–".into(),
            met: None,
        });
    }
    for pct in ["p50", "p99"] {
        let (walking, holding) = (us("stream_walking", pct)?, us("stream_holding", pct)?);
        rows.push(Row {
            path: format!("The G1's 500 Hz LowCmd stream while the policy runs, send lateness {pct}"),
            figure: format!("{walking:.0} µs"),
            baseline: format!("the same stream holding a pose, no policy: {holding:.0} µs"),
            ratio: if holding > 0.0 { format!("{:.2}×", walking / holding) } else { "–".into() },
            target: "–".into(),
            met: None,
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    #[test]
    fn the_recording_rows_take_the_streams_from_one_bench_and_the_recorder_from_the_other() {
        let stream =
            json!({"plain_p50_us": 1, "plain_p99_us": 50, "recorded_p50_us": 2, "recorded_p99_us": 60, "dropped": 0});
        let recorded = json!({
            "lateness_plain_p50_us": 0, "lateness_plain_p99_us": 40, "lateness_recorded_p50_us": 0,
            "lateness_recorded_p99_us": 45, "stream_frames_dropped": 0, "kmc_stream": stream, "spline_stream": stream,
            "live_stream": {"plain_p50_us": 1, "plain_p99_us": 50, "stalled_p50_us": 1, "stalled_p99_us": 52, "viewer_dropped": 7},
        });
        let run = json!({
            "offered": 100, "offered_per_s": 1e6, "written": 100, "written_per_s": 1e6, "mb_per_s": 560,
            "dropped": 0, "json_skipped": 0,
        });
        let record = json!({
            "unpaced_raw": run, "unpaced_json": run, "paced_1m_raw": run, "paced_1m_raw_64b": run,
            "links_100_at_1khz": run, "links_100_at_1khz_zstd": run,
        });
        let rows = record_rows(&recorded, &record).unwrap();
        assert_eq!(rows.len(), 10);
        assert_eq!(rows[0].ratio, "p99 +5 µs");
        assert_eq!(rows[1].ratio, "p99 +10 µs");
        assert_eq!(rows[3].ratio, "p99 +2 µs");
        assert!(rows[3].figure.contains("7 messages dropped for the viewer"), "{}", rows[3].figure);
        assert_eq!(rows[9].met, Some(true));
        assert!(record_rows(&record, &recorded).is_err(), "the two benches' figures apart");
    }
}
