//! `cargo xtask bench`: runs the criterion benchmarks and prints one table, each figure beside
//! its baseline measured in the same run, with the ratio and the target from the issues.
//! Writes the table to `target/bench-report.md` and `target/bench-report.json`, and the page
//! `docs/performance.md` ([`report`]).

mod apps;
mod lowcmd;
mod python;
pub mod report;
mod rtps;

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};
use serde::Serialize;
use serde_json::Value;

use crate::workspace_root;

/// A criterion bench target to run: package and bench name.
/// The latency and loop-jitter programs among them write their figures to `bench-meta-*.json`.
pub(crate) const BENCHES: &[(&str, &str)] = &[
    ("kmc-proto", "codec"),
    ("kmc", "serial"),
    ("unitree-proto", "lowcmd"),
    ("rtps-proto", "rtps"),
    ("zsl", "spline"),
    ("zsl", "udp"),
    ("robowire", "streams"),
    ("robowire", "dds"),
    ("robowire-ros2", "cmd_vel"),
    ("robowire-record", "record"),
    ("robowire", "recorded"),
    ("robowire-policy", "inference"),
];

/// One row of the table.
#[derive(Debug, Serialize)]
pub struct Row {
    /// What was measured.
    pub path: String,
    /// The figure.
    pub figure: String,
    /// The baseline, measured in the same run.
    pub baseline: String,
    /// Figure relative to baseline.
    pub ratio: String,
    /// The target from the issues.
    pub target: String,
    /// Whether the target is met (`None` when there is no target).
    pub met: Option<bool>,
}

fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from)
}

/// Mean time of one criterion benchmark, ns.
pub(crate) fn mean_ns(criterion: &Path, group: &str, bench: &str) -> anyhow::Result<f64> {
    let path = criterion.join(group).join(bench).join("new/estimates.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let value: Value = serde_json::from_str(&text)?;
    value["mean"]["point_estimate"].as_f64().with_context(|| format!("no mean in {}", path.display()))
}

/// Runs the benchmarks (`quick`: shorter measurements) and returns the table.
pub fn run(quick: bool) -> anyhow::Result<Vec<Row>> {
    let root = workspace_root();
    let target = target_dir(&root);
    std::fs::create_dir_all(&target)?;
    let meta_path = target.join("bench-meta.json");
    let spline_meta_path = target.join("bench-meta-spline.json");
    let udp_meta_path = target.join("bench-meta-zsl-udp.json");
    let kmc_meta_path = target.join("bench-meta-kmc.json");
    let streams_meta_path = target.join("bench-meta-streams.json");
    let dds_meta_path = target.join("bench-meta-dds.json");
    let ros2_meta_path = target.join("bench-meta-ros2.json");
    let record_meta_path = target.join("bench-meta-record.json");
    let recorded_meta_path = target.join("bench-meta-recorded.json");
    let policy_meta_path = target.join("bench-meta-policy.json");
    let times: &[&str] = if quick {
        &["--warm-up-time", "0.5", "--measurement-time", "1"]
    } else {
        &["--warm-up-time", "2", "--measurement-time", "5"]
    };
    // With MuJoCo here, the DDS bench measures round trips with physics on too, and the physics
    // bench runs.
    let mujoco =
        crate::mujoco::lib_dir(&target).inspect_err(|missing| println!("physics benchmarks skipped: {missing}")).ok();
    let physics_meta_path = target.join("bench-meta-physics.json");
    let physics_bench: &[(&str, &str)] = if mujoco.is_some() { &[("robowire-sim", "physics")] } else { &[] };
    for &(package, bench) in BENCHES.iter().chain(physics_bench) {
        let features: &[&str] =
            if mujoco.is_some() && matches!(bench, "dds" | "physics") { &["--features", "mujoco"] } else { &[] };
        let status = Command::new("cargo")
            .args(["bench", "-p", package, "--bench", bench])
            .args(features)
            .arg("--")
            .args(times)
            .envs(mujoco.iter().flat_map(|dir| [("MUJOCO_DYNAMIC_LINK_DIR", dir), ("LD_LIBRARY_PATH", dir)]))
            .env("ROBOWIRE_BENCH_META_PHYSICS", &physics_meta_path)
            .env("ROBOWIRE_BENCH_META", &meta_path)
            .env("ROBOWIRE_BENCH_META_SPLINE", &spline_meta_path)
            .env("ROBOWIRE_BENCH_META_ZSL_UDP", &udp_meta_path)
            .env("ROBOWIRE_BENCH_META_KMC", &kmc_meta_path)
            .env("ROBOWIRE_BENCH_META_STREAMS", &streams_meta_path)
            .env("ROBOWIRE_BENCH_META_DDS", &dds_meta_path)
            .env("ROBOWIRE_BENCH_META_ROS2", &ros2_meta_path)
            .env("ROBOWIRE_BENCH_META_RECORD", &record_meta_path)
            .env("ROBOWIRE_BENCH_META_RECORDED", &recorded_meta_path)
            .env("ROBOWIRE_BENCH_META_POLICY", &policy_meta_path)
            .envs(quick.then_some(("ROBOWIRE_BENCH_QUICK", "1")))
            .current_dir(&root)
            .status()
            .context("running cargo bench")?;
        if !status.success() {
            bail!("cargo bench -p {package} --bench {bench} failed ({status})");
        }
    }
    let criterion = target.join("criterion");
    let meta: Value = serde_json::from_str(&std::fs::read_to_string(&meta_path).context("bench metadata")?)?;
    let mut rows = Vec::new();

    let encode = mean_ns(&criterion, "kmc_encode", "pc_control")?;
    let copy9 = mean_ns(&criterion, "kmc_encode", "memcpy_9B")?;
    rows.push(Row {
        path: "KMC encode 0xA5 (9 B)".into(),
        figure: format!("{encode:.2} ns/frame"),
        baseline: format!("memcpy 9 B: {copy9:.2} ns"),
        ratio: format!("{:.1}×", encode / copy9),
        target: "–".into(),
        met: None,
    });
    let stream_bytes = meta["kmc_decode_1MiB"]["stream_bytes"].as_f64().context("stream_bytes")?;
    let copy = mean_ns(&criterion, "kmc_decode_1MiB", "memcpy")?;
    let copy_mbps = stream_bytes / copy * 1e3;
    for (bench, label) in
        [("host_side", "KMC decode, host side (1 MiB mixed)"), ("device_side", "KMC decode, device side (1 MiB mixed)")]
    {
        let ns = mean_ns(&criterion, "kmc_decode_1MiB", bench)?;
        let mbps = stream_bytes / ns * 1e3;
        let frames = meta["kmc_decode_1MiB"][format!("{bench}_frames")].as_f64().context("frame count")?;
        rows.push(Row {
            path: label.into(),
            figure: format!("{mbps:.0} MB/s, {:.1} M frames/s", frames / ns * 1e3),
            baseline: format!("memcpy 1 MiB: {copy_mbps:.0} MB/s"),
            ratio: format!("{:.2} %", 100.0 * mbps / copy_mbps),
            target: "≥ 200 MB/s".into(),
            met: Some(mbps >= 200.0),
        });
    }

    let kmc: Value = serde_json::from_str(&std::fs::read_to_string(&kmc_meta_path).context("KMC bench metadata")?)?;
    rows.extend(round_trip_rows(
        &kmc,
        "KMC 0xB3 request → speed frame via UartClient and the simulator (pty)",
        "raw pty echo (1 B out, 5 B back)",
        None,
    )?);

    rows.extend(lowcmd::rows(&criterion)?);
    rows.extend(rtps::rows(&criterion)?);
    let spline: Value =
        serde_json::from_str(&std::fs::read_to_string(&spline_meta_path).context("spline bench metadata")?)?;
    rows.extend(spline_rows(&spline)?);
    let udp: Value =
        serde_json::from_str(&std::fs::read_to_string(&udp_meta_path).context("ZSL-1 UDP bench metadata")?)?;
    rows.extend(zsl_udp_rows(&criterion, &udp)?);
    rows.extend(python::rows(quick, &udp)?);
    let streams: Value =
        serde_json::from_str(&std::fs::read_to_string(&streams_meta_path).context("streams bench metadata")?)?;
    rows.extend(stream_rows(&streams)?);
    let dds: Value = serde_json::from_str(&std::fs::read_to_string(&dds_meta_path).context("DDS bench metadata")?)?;
    rows.extend(apps::dds_rows(&dds)?);
    let ros2: Value = serde_json::from_str(&std::fs::read_to_string(&ros2_meta_path).context("ROS 2 bench metadata")?)?;
    rows.push(apps::ros2_row(&ros2)?);
    let record: Value =
        serde_json::from_str(&std::fs::read_to_string(&record_meta_path).context("recorder bench metadata")?)?;
    let recorded: Value = serde_json::from_str(
        &std::fs::read_to_string(&recorded_meta_path).context("recorded streams bench metadata")?,
    )?;
    rows.extend(apps::record_rows(&recorded, &record)?);
    let physics: Option<Value> = match mujoco {
        Some(_) => {
            Some(serde_json::from_str(&std::fs::read_to_string(&physics_meta_path).context("physics bench metadata")?)?)
        }
        None => None,
    };
    rows.extend(apps::physics_rows(physics.as_ref(), &dds)?);
    // Unitree's G1 policy only where `../shared/policies` is.
    let policy: Option<Value> =
        std::fs::read_to_string(&policy_meta_path).ok().map(|t| serde_json::from_str(&t)).transpose()?;
    rows.extend(apps::policy_rows(policy.as_ref())?);

    let markdown = report::to_markdown(&rows);
    println!("\n{markdown}");
    std::fs::write(target.join("bench-report.md"), &markdown)?;
    std::fs::write(target.join("bench-report.json"), serde_json::to_string_pretty(&rows)? + "\n")?;
    let page = root.join(report::PAGE);
    std::fs::write(&page, report::page(&rows, quick))?;
    println!("written: {}, bench-report.json and {}", target.join("bench-report.md").display(), page.display());
    Ok(rows)
}

/// The p50 and p99 rows of a round trip measured sample by sample beside a raw echo (metadata
/// keys `round_trip_{p}_ns` and `raw_echo_{p}_ns`); the target, if any, bounds the p50 ratio.
fn round_trip_rows(meta: &Value, path: &str, echo: &str, p50_max_ratio: Option<f64>) -> anyhow::Result<Vec<Row>> {
    let us = |key: String| meta[&key].as_f64().map(|ns| ns / 1e3).with_context(|| format!("bench metadata {key}"));
    ["p50", "p99"]
        .into_iter()
        .map(|pct| {
            let (trip, raw) = (us(format!("round_trip_{pct}_ns"))?, us(format!("raw_echo_{pct}_ns"))?);
            let max_ratio = p50_max_ratio.filter(|_| pct == "p50");
            Ok(Row {
                path: format!("{path}, {pct}"),
                figure: format!("{trip:.1} µs"),
                baseline: format!("{echo}: {raw:.1} µs"),
                ratio: format!("{:.2}×", trip / raw),
                target: max_ratio.map_or_else(|| "–".into(), |r| format!("≤ {r}× raw")),
                met: max_ratio.map(|r| trip <= r * raw),
            })
        })
        .collect()
}

/// Rows of the spline shared-memory benchmark (cross-process round trip).
fn spline_rows(meta: &Value) -> anyhow::Result<Vec<Row>> {
    let rt = &meta["spline_roundtrip"];
    let ns = |key: &str| rt[key].as_f64().with_context(|| format!("spline_roundtrip.{key}"));
    let mut rows = Vec::new();
    for pct in ["p50", "p99"] {
        let (facade, raw, flags) =
            (ns(&format!("facade_{pct}_ns"))?, ns(&format!("raw_{pct}_ns"))?, ns(&format!("flags_{pct}_ns"))?);
        rows.push(Row {
            path: format!("Spline handshake round trip, 2 processes, {pct}"),
            figure: format!("{facade:.0} ns"),
            baseline: format!("raw C-like atomics + copies: {raw:.0} ns (flags only: {flags:.0} ns)"),
            ratio: format!("{:.2}×", facade / raw),
            target: "≤ 1.5× raw".into(),
            met: Some(facade <= 1.5 * raw),
        });
    }
    Ok(rows)
}

/// Rows of the ZSL-1 UDP benchmarks: codec, call-to-wire latency, round trip via the simulator.
fn zsl_udp_rows(criterion: &Path, meta: &Value) -> anyhow::Result<Vec<Row>> {
    let group = "zsl_udp_codec";
    let mut rows = Vec::new();
    for (bench, label, copy) in [
        ("hl_command_encode_40B", "ZSL-1 HighLevel command encode (40 B, checksum)", "memcpy_40B"),
        ("hl_command_decode_40B", "ZSL-1 HighLevel command decode, strict", "memcpy_40B"),
        ("hl_state_decode_strict_560B", "ZSL-1 HighLevel state decode, strict (560 B)", "memcpy_560B"),
        ("hl_state_update_lenient_560B", "ZSL-1 HighLevel state decode, lenient", "memcpy_560B"),
        ("ll_command_encode_248B", "ZSL-1 LowLevel command encode (248 B)", "memcpy_248B"),
        ("ll_command_decode_248B", "ZSL-1 LowLevel command decode, strict", "memcpy_248B"),
        ("ll_state_decode_strict_272B", "ZSL-1 LowLevel state decode, strict (272 B)", "memcpy_272B"),
    ] {
        let (ns, base) = (mean_ns(criterion, group, bench)?, mean_ns(criterion, group, copy)?);
        rows.push(Row {
            path: label.into(),
            figure: format!("{ns:.1} ns"),
            baseline: format!("{}: {base:.1} ns", copy.replace('_', " ")),
            ratio: format!("{:.1}×", ns / base),
            target: "–".into(),
            met: None,
        });
    }
    let us = |key: &str| meta[key].as_f64().map(|ns| ns / 1e3).with_context(|| format!("zsl udp meta {key}"));
    let raw50 = us("raw_echo_p50_ns")?;
    let (wire50, wire99) = (us("call_to_wire_p50_ns")?, us("call_to_wire_p99_ns")?);
    rows.push(Row {
        path: "ZSL-1 call to wire: move() → datagram at the dog's socket".into(),
        figure: format!("p50 {wire50:.1} µs, p99 {wire99:.1} µs"),
        baseline: format!("raw UDP echo round trip p50 {raw50:.1} µs (vendor client: ~1840 µs)"),
        ratio: format!("{:.2}× raw echo", wire50 / raw50),
        target: "p50 ≤ 50 µs".into(),
        met: Some(wire50 <= 50.0),
    });
    rows.extend(round_trip_rows(
        meta,
        "ZSL-1 command → state round trip via the simulator",
        "raw UDP echo round trip",
        Some(1.5),
    )?);
    Ok(rows)
}

/// Send lateness of every periodic stream: p50 ≤ 20 µs, p99 ≤ 100 µs.
const STREAM_P50_US: u64 = 20;
const STREAM_P99_US: u64 = 100;
/// A stream's p99 against the bare loop's.
const STREAM_P99_RATIO: f64 = 1.5;
/// The ZSL-1 command interval at the dog: |interval − 2 ms| p99 ≤ 150 µs.
const INTERVAL_AT_DOG_P99_US: u64 = 150;

/// `p50 / p99 / max` of a lateness summary in the metadata.
fn percentiles_us(summary: &Value) -> anyhow::Result<(u64, u64, u64)> {
    let field = |f: &str| summary[f].as_u64().with_context(|| format!("streams meta {f} in {summary}"));
    Ok((field("p50_us")?, field("p99_us")?, field("max_us")?))
}

/// Rows of the streams bench: each periodic stream beside a bare `clock_nanosleep` loop, the
/// ZSL-1 interval at the dog, the runner's spin.
fn stream_rows(meta: &Value) -> anyhow::Result<Vec<Row>> {
    let seconds = meta["seconds"].as_f64().context("streams meta seconds")?;
    let mut rows = Vec::new();
    for stream in meta["streams"].as_array().context("streams meta streams")? {
        let name = stream["name"].as_str().context("stream name")?;
        let (p50, p99, max) = percentiles_us(&stream["lateness"])?;
        let (b50, b99, bmax) = percentiles_us(&stream["bare_loop"])?;
        let ratio = p99 as f64 / b99.max(1) as f64;
        rows.push(Row {
            path: format!("{name}: send lateness over {seconds:.0} s"),
            figure: format!("p50 {p50} µs, p99 {p99} µs, max {max} µs"),
            baseline: format!("bare clock_nanosleep loop, same rate: p50 {b50} µs, p99 {b99} µs, max {bmax} µs"),
            ratio: format!("{ratio:.2}× (p99)"),
            target: format!("p50 ≤ {STREAM_P50_US} µs, p99 ≤ {STREAM_P99_US} µs, ≤ {STREAM_P99_RATIO}× bare (p99)"),
            met: Some(p50 <= STREAM_P50_US && p99 <= STREAM_P99_US && ratio <= STREAM_P99_RATIO),
        });
    }
    let (i50, i99, imax) = percentiles_us(&meta["zsl_interval_at_dog"])?;
    rows.push(Row {
        path: "ZSL-1 HighLevel command interval at the simulated dog: deviation from 2 ms".into(),
        figure: format!("p50 {i50} µs, p99 {i99} µs, max {imax} µs"),
        baseline: "period 2 ms".into(),
        ratio: format!("{:.1} % of the period (p99)", i99 as f64 / 20.0),
        target: format!("p99 ≤ {INTERVAL_AT_DOG_P99_US} µs"),
        met: Some(i99 <= INTERVAL_AT_DOG_P99_US),
    });
    let spin = &meta["spin"];
    let (b50, b99, _) = percentiles_us(&spin["bare_loop"])?;
    for run in spin["runs"].as_array().context("streams meta spin runs")? {
        let us = run["spin_us"].as_u64().context("spin_us")?;
        let (p50, p99, max) = percentiles_us(&run["lateness"])?;
        let cpu = run["cpu_percent"].as_f64().context("cpu_percent")?;
        let chosen = if run["default"].as_bool() == Some(true) { " (the default)" } else { "" };
        rows.push(Row {
            path: format!("runner alone at 500 Hz, final spin {us} µs{chosen}"),
            figure: format!("p50 {p50} µs, p99 {p99} µs, max {max} µs; CPU {cpu:.1} % of a core"),
            baseline: format!("bare clock_nanosleep loop: p50 {b50} µs, p99 {b99} µs"),
            ratio: format!("{:.2}× (p99)", p99 as f64 / b99.max(1) as f64),
            target: "–".into(),
            met: None,
        });
    }
    Ok(rows)
}

/// A stalled reader may raise the LowCmd stream's p99 lateness to 1.5× the healthy run's, and no
/// send may be later than 1 ms (a reader that stops reading, reliable QoS).
const STALLED_P99_RATIO: f64 = 1.5;
const STALLED_MAX_US: u64 = 1000;

/// Rows of the stalled-reader runs: the Go2 client's LowCmd stream with a healthy RELIABLE
/// reader, and beside it the same stream while the reader stalls.
pub(crate) fn stalled_reader_rows(meta: &Value) -> anyhow::Result<Vec<Row>> {
    let case = |key: &str| -> anyhow::Result<(u64, u64, u64, u64, f64, f64)> {
        let c = &meta[key];
        let (p50, p99, max) = percentiles_us(&c["lateness"])?;
        let dropped = c["dropped"].as_u64().with_context(|| format!("dds meta stalled_reader.{key}.dropped"))?;
        let run = c["run_s"].as_f64().with_context(|| format!("dds meta stalled_reader.{key}.run_s"))?;
        let stall = c["stall_s"].as_f64().with_context(|| format!("dds meta stalled_reader.{key}.stall_s"))?;
        Ok((p50, p99, max, dropped, run, stall))
    };
    let (b50, b99, bmax) = percentiles_us(&meta["bare_loop"]["lateness"])?;
    let bare = format!("bare clock_nanosleep loop, same rate and CPU: p50 {b50} µs, p99 {b99} µs, max {bmax} µs");
    let (h50, h99, hmax, hdropped, hrun, _) = case("healthy")?;
    let figure = |p50: u64, p99: u64, max: u64, dropped: u64| {
        format!("p50 {p50} µs, p99 {p99} µs, max {max} µs; {dropped} dropped")
    };
    let mut rows = vec![Row {
        path: format!("Go2 LowCmd stream (500 Hz) send lateness, a healthy RELIABLE reader of rt/lowcmd ({hrun:.0} s)"),
        figure: figure(h50, h99, hmax, hdropped),
        baseline: bare.clone(),
        ratio: "–".into(),
        target: format!("max ≤ {} ms", STALLED_MAX_US / 1000),
        met: Some(hmax <= STALLED_MAX_US),
    }];
    let (r50, r99, rmax, rdropped, rrun, _) = case("healthy_recorded")?;
    let frames_dropped = meta["healthy_recorded"]["recorded"]["dropped"].as_u64().unwrap_or(0);
    rows.push(Row {
        path: format!("Go2 LowCmd stream (500 Hz) send lateness, its link recorded to MCAP ({rrun:.0} s)"),
        figure: format!("{}; {frames_dropped} frames dropped by the recorder", figure(r50, r99, rmax, rdropped)),
        baseline: format!("not recorded: {}", figure(h50, h99, hmax, hdropped)),
        ratio: format!("p99 {:+} µs", r99 as i64 - h99 as i64),
        target: "–".into(),
        met: None,
    });
    for (key, what) in [
        ("stops_taking", "stops taking samples (its participant still acknowledges)"),
        ("stopped", "is stopped (SIGSTOP: neither reads nor acknowledges)"),
        ("stopped_long", "is stopped (SIGSTOP) far longer than any send window lasts; keep last 1: nothing fills"),
    ] {
        let (p50, p99, max, dropped, run, stall) = case(key)?;
        let ratio = p99 as f64 / h99.max(1) as f64;
        rows.push(Row {
            path: format!(
                "Go2 LowCmd stream (500 Hz) send lateness, the reader {what}: {stall:.1} s of a {run:.1} s run"
            ),
            figure: figure(p50, p99, max, dropped),
            baseline: format!("healthy reader: {}; {bare}", figure(h50, h99, hmax, hdropped)),
            ratio: format!("{ratio:.2}× (p99); max {:.2} ms", max as f64 / 1000.0),
            target: format!("p99 ≤ {STALLED_P99_RATIO}× healthy, max ≤ {} ms", STALLED_MAX_US / 1000),
            met: Some(ratio <= STALLED_P99_RATIO && max <= STALLED_MAX_US),
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_rows_bound_the_p50_ratio_only() {
        let meta = serde_json::json!({
            "round_trip_p50_ns": 60_000.0, "raw_echo_p50_ns": 50_000.0,
            "round_trip_p99_ns": 90_000.0, "raw_echo_p99_ns": 50_000.0,
        });
        let rows = round_trip_rows(&meta, "trip", "raw echo", Some(1.5)).unwrap();
        assert_eq!((rows[0].path.as_str(), rows[0].figure.as_str()), ("trip, p50", "60.0 µs"));
        assert_eq!((rows[0].baseline.as_str(), rows[0].ratio.as_str()), ("raw echo: 50.0 µs", "1.20×"));
        assert_eq!((rows[0].target.as_str(), rows[0].met), ("≤ 1.5× raw", Some(true)));
        assert_eq!((rows[1].target.as_str(), rows[1].met), ("–", None), "1.8× at p99 is not judged");
        let rows = round_trip_rows(&meta, "trip", "raw echo", None).unwrap();
        assert!(rows.iter().all(|r| r.met.is_none()));
        assert!(round_trip_rows(&serde_json::json!({}), "trip", "raw", None).is_err(), "missing keys are errors");
    }

    #[test]
    fn stalled_reader_rows_judge_p99_against_the_healthy_run_and_the_max() {
        let case = |p99: u64, max: u64, dropped: u64| {
            serde_json::json!({
                "lateness": {"count": 1500, "p50_us": 0, "p99_us": p99, "max_us": max},
                "dropped": dropped, "run_s": 3.0, "stall_s": 1.0,
            })
        };
        let meta = serde_json::json!({
            "bare_loop": {"run_s": 3.0, "lateness": {"count": 1500, "p50_us": 50, "p99_us": 90, "max_us": 1200}},
            "healthy": case(40, 900, 0),
            "healthy_recorded": case(30, 800, 0),
            "stops_taking": case(60, 1000, 0),
            "stopped": case(61, 500, 0),
            "stopped_long": case(50, 1001, 0),
        });
        let rows = stalled_reader_rows(&meta).unwrap();
        assert_eq!(rows.len(), 5);
        assert_eq!((rows[0].target.as_str(), rows[0].met), ("max ≤ 1 ms", Some(true)));
        assert_eq!(rows[1].baseline, "not recorded: p50 0 µs, p99 40 µs, max 900 µs; 0 dropped");
        assert_eq!((rows[1].ratio.as_str(), rows[1].met), ("p99 -10 µs", None));
        assert_eq!(rows[2].figure, "p50 0 µs, p99 60 µs, max 1000 µs; 0 dropped");
        assert_eq!(
            rows[2].baseline,
            "healthy reader: p50 0 µs, p99 40 µs, max 900 µs; 0 dropped; \
             bare clock_nanosleep loop, same rate and CPU: p50 50 µs, p99 90 µs, max 1200 µs"
        );
        assert_eq!((rows[2].ratio.as_str(), rows[2].met), ("1.50× (p99); max 1.00 ms", Some(true)));
        assert_eq!(rows[3].met, Some(false), "p99 above 1.5× healthy");
        assert_eq!(rows[4].met, Some(false), "a send later than 1 ms");
        assert!(rows[4].path.contains("nothing fills") && rows[4].figure.ends_with("0 dropped"));
        assert!(rows[0].baseline.starts_with("bare clock_nanosleep loop"));
        assert!(stalled_reader_rows(&serde_json::json!({})).is_err(), "missing keys are errors");
    }
}
