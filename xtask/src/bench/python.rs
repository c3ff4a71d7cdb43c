//! The Python rows of `cargo xtask bench`: `crates/robowire-py/bench/bench_python.py` in the
//! CPython 3.10 interop environment on the wheel `cargo xtask test` builds, beside the vendor's
//! module and Unitree's SDK.

use std::process::Command;

use anyhow::Context;
use serde_json::Value;

use crate::bench::Row;
use crate::python::{py310_with_wheel, run, target_dir};
use crate::workspace_root;
use robowire_fixtures::peers::peers_dir;

/// The Python rows of `cargo xtask bench`: `move()` call to wire from Python (robowire beside the
/// vendor's module and a plain socket, and beside robowire's Rust API from `rust_udp`, the ZSL-1
/// UDP bench's metadata of the same run), and LowCmd encode with CRC beside Unitree's SDK.
pub(crate) fn rows(quick: bool, rust_udp: &Value) -> anyhow::Result<Vec<Row>> {
    let root = workspace_root();
    let target = target_dir(&root);
    let (py310, _) = py310_with_wheel(&root, &target)?;
    let out = target.join("bench-meta-python.json");
    let vendor = peers_dir().join("zsibot_sdk/lib/zsl-1/x86_64");
    run(
        "bench_python.py",
        Command::new(&py310)
            .arg(root.join("crates/robowire-py/bench/bench_python.py"))
            .arg(&out)
            .args(quick.then_some("--quick"))
            .env("PYTHONPATH", &vendor)
            .current_dir(&root),
    )?;
    let meta: Value = serde_json::from_str(&std::fs::read_to_string(&out).context("Python bench output")?)?;
    python_rows(&meta, rust_udp)
}

fn python_rows(meta: &Value, rust_udp: &Value) -> anyhow::Result<Vec<Row>> {
    let us = |v: &Value, key: &str| v[key].as_f64().map(|ns| ns / 1e3).with_context(|| format!("{key} in {v}"));
    let wire = &meta["call_to_wire"];
    let ours = &wire["robowire"];
    let (p50, p99) = (us(ours, "p50_ns")?, us(ours, "p99_ns")?);
    let figure = format!("p50 {p50:.1} µs, p99 {p99:.1} µs");
    let path = "ZSL-1 call to wire from Python: robowire.zsl1 move() → datagram at the dog";
    let mut rows = Vec::new();
    let vendor = &wire["vendor"];
    rows.push(if vendor.is_object() {
        let (v50, v99) = (us(vendor, "p50_ns")?, us(vendor, "p99_ns")?);
        Row {
            path: path.into(),
            figure: figure.clone(),
            baseline: format!("the vendor's mc_sdk_zsl_1_py: p50 {v50:.0} µs, p99 {v99:.0} µs"),
            ratio: format!("{:.3}× the vendor's p50", p50 / v50),
            target: "p50 below the vendor's".into(),
            met: Some(p50 < v50),
        }
    } else {
        Row {
            path: path.into(),
            figure: figure.clone(),
            baseline: "the vendor's module does not load here (CPython 3.10, x86_64)".into(),
            ratio: "–".into(),
            target: "p50 below the vendor's".into(),
            met: None,
        }
    });
    let raw = &wire["raw_socket"];
    let raw50 = us(raw, "p50_ns")?;
    let rust50 = us(rust_udp, "call_to_wire_p50_ns")?;
    rows.push(Row {
        path: format!("{path} (floors)"),
        figure,
        baseline: format!(
            "a Python socket sending the datagram itself: p50 {raw50:.1} µs; the Rust API: p50 {rust50:.1} µs"
        ),
        ratio: format!("{:.1}× the Python socket", p50 / raw50),
        target: "–".into(),
        met: None,
    });
    let encode = &meta["lowcmd_encode"];
    let ns = encode["robowire_encode_ns"].as_f64().context("robowire_encode_ns")?;
    let path = "Unitree LowCmd encode with CRC from Python: robowire.unitree LowCmd.encode()";
    rows.push(match (encode["sdk_crc_ns"].as_f64(), encode["sdk_pure_python_crc_ns"].as_f64()) {
        (Some(sdk), Some(pure)) => Row {
            path: path.into(),
            figure: format!("{ns:.0} ns"),
            baseline: format!(
                "unitree_sdk2py CRC().Crc(cmd): {:.0} µs; its pure-Python CRC: {:.0} µs",
                sdk / 1e3,
                pure / 1e3
            ),
            ratio: format!("1/{:.0} of the SDK's Crc", sdk / ns),
            target: "faster than the SDK".into(),
            met: Some(ns < sdk),
        },
        _ => Row {
            path: path.into(),
            figure: format!("{ns:.0} ns"),
            baseline: "unitree_sdk2py is not installed here".into(),
            ratio: "–".into(),
            target: "faster than the SDK".into(),
            met: None,
        },
    });
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn python_rows_compare_with_the_vendor_only_when_it_ran() {
        let rust = serde_json::json!({"call_to_wire_p50_ns": 6000.0});
        let mut meta = serde_json::json!({
            "call_to_wire": {
                "raw_socket": {"p50_ns": 20000, "p99_ns": 80000},
                "robowire": {"p50_ns": 40000, "p99_ns": 150000},
                "vendor": {"p50_ns": 1200000, "p99_ns": 2100000},
            },
            "lowcmd_encode": {"robowire_encode_ns": 300.0, "sdk_crc_ns": 130000.0, "sdk_pure_python_crc_ns": 1.4e6},
        });
        let rows = python_rows(&meta, &rust).unwrap();
        assert_eq!([rows[0].met, rows[1].met, rows[2].met], [Some(true), None, Some(true)]);
        assert_eq!(rows[1].ratio, "2.0× the Python socket");
        meta["call_to_wire"].as_object_mut().unwrap().remove("vendor");
        meta["lowcmd_encode"].as_object_mut().unwrap().remove("sdk_crc_ns");
        let rows = python_rows(&meta, &rust).unwrap();
        assert_eq!([rows[0].met, rows[2].met], [None, None]);
        meta["call_to_wire"]["robowire"]["p50_ns"] = serde_json::json!(2_000_000);
        meta["call_to_wire"]["vendor"] = serde_json::json!({"p50_ns": 1200000, "p99_ns": 2100000});
        assert_eq!(python_rows(&meta, &rust).unwrap()[0].met, Some(false));
    }
}
