//! Rows of the RTPS core's benchmarks (`rtps-proto`'s criterion bench): a 1 KB best-effort
//! sample's receive path, its write, and the wire layer's parse, each beside a memcpy of the same
//! datagram from the same run.

use std::path::Path;

use anyhow::Context;
use serde_json::Value;

use super::{Row, mean_ns};

/// The criterion group of `crates/rtps-proto/benches/rtps.rs`.
const GROUP: &str = "rtps";
/// The baseline: a memcpy of the datagram.
const MEMCPY: &str = "memcpy_1KB";

/// The datagram's length in bytes: the throughput the bench declares for its group.
fn datagram_bytes(criterion: &Path) -> anyhow::Result<u64> {
    let path = criterion.join(GROUP).join(MEMCPY).join("new/benchmark.json");
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let value: Value = serde_json::from_str(&text)?;
    value["throughput"]["Bytes"].as_u64().with_context(|| format!("no throughput in bytes in {}", path.display()))
}

/// Rows of the RTPS benchmarks: receive, write, wire parse.
pub(crate) fn rows(criterion: &Path) -> anyhow::Result<Vec<Row>> {
    let bytes = datagram_bytes(criterion)?;
    let copy = mean_ns(criterion, GROUP, MEMCPY)?;
    [
        ("parse_handle_data_1KB", "RTPS: parse + handle a 1 KB DATA"),
        ("write_1KB", "RTPS: write → datagram (1 KB)"),
        ("wire_parse_1KB", "RTPS wire: parse a 1 KB DATA datagram"),
    ]
    .into_iter()
    .map(|(bench, label)| {
        let ns = mean_ns(criterion, GROUP, bench)?;
        Ok(Row {
            path: label.into(),
            figure: format!("{ns:.1} ns"),
            baseline: format!("memcpy {bytes} B: {copy:.1} ns"),
            ratio: format!("{:.1}×", ns / copy),
            target: "–".into(),
            met: None,
        })
    })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writes what criterion writes for one benchmark: its mean and its declared throughput.
    fn bench(criterion: &Path, name: &str, mean_ns: f64, bytes: u64) {
        let dir = criterion.join(GROUP).join(name).join("new");
        std::fs::create_dir_all(&dir).unwrap();
        let estimates = serde_json::json!({"mean": {"point_estimate": mean_ns}});
        std::fs::write(dir.join("estimates.json"), estimates.to_string()).unwrap();
        let benchmark = serde_json::json!({"group_id": GROUP, "function_id": name, "throughput": {"Bytes": bytes}});
        std::fs::write(dir.join("benchmark.json"), benchmark.to_string()).unwrap();
    }

    #[test]
    fn each_row_stands_beside_the_memcpy_of_the_same_datagram() {
        let criterion = std::env::temp_dir().join(format!("xtask-bench-rtps-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&criterion);
        assert!(rows(&criterion).is_err(), "no criterion output is an error");
        bench(&criterion, MEMCPY, 14.0, 1068);
        bench(&criterion, "parse_handle_data_1KB", 210.0, 1068);
        bench(&criterion, "write_1KB", 140.0, 1068);
        assert!(rows(&criterion).is_err(), "a missing bench is an error");
        bench(&criterion, "wire_parse_1KB", 42.0, 1068);
        let rows = rows(&criterion).unwrap();
        std::fs::remove_dir_all(&criterion).unwrap();
        let got: Vec<_> =
            rows.iter().map(|r| (r.path.as_str(), r.figure.as_str(), r.baseline.as_str(), r.ratio.as_str())).collect();
        assert_eq!(
            got,
            [
                ("RTPS: parse + handle a 1 KB DATA", "210.0 ns", "memcpy 1068 B: 14.0 ns", "15.0×"),
                ("RTPS: write → datagram (1 KB)", "140.0 ns", "memcpy 1068 B: 14.0 ns", "10.0×"),
                ("RTPS wire: parse a 1 KB DATA datagram", "42.0 ns", "memcpy 1068 B: 14.0 ns", "3.0×"),
            ]
        );
        assert!(rows.iter().all(|r| r.met.is_none() && r.target == "–"));
    }
}
