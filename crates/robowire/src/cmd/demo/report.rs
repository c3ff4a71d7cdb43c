//! What each scenario reports: its checks and the figures of the end-of-demo summary table
//! (and of `--json`).

use std::time::Duration;

use robowire_core::timing::LatenessSummary;
use serde_json::{Map, Value, json};

/// One thing a scenario commanded and whether it was observed.
#[derive(Debug)]
pub(crate) struct Check {
    pub(crate) what: String,
    pub(crate) passed: bool,
    pub(crate) observed: String,
    /// A timing figure against a loose bound: reported, never a failure of the demo (the
    /// machine may be shared; `cargo xtask bench` enforces the targets on an idle one).
    pub(crate) timing: bool,
}

impl Check {
    /// A functional check: what was commanded was observed.
    pub(crate) fn new(what: impl Into<String>, passed: bool, observed: impl Into<String>) -> Self {
        Self { what: what.into(), passed, observed: observed.into(), timing: false }
    }

    /// A timing figure and whether it met its loose bound (reported only).
    pub(crate) fn timing(what: impl Into<String>, met: bool, observed: impl Into<String>) -> Self {
        Self { timing: true, ..Self::new(what, met, observed) }
    }

    fn json(&self) -> Value {
        let kind = if self.timing { "timing" } else { "functional" };
        json!({"check": self.what, "kind": kind, "passed": self.passed, "observed": self.observed})
    }
}

/// The demo's live bound on a periodic stream's median send lateness, µs: loose enough for a
/// shared machine (`cargo xtask bench` holds the tight targets).
pub(crate) const MAX_P50_LATENESS_US: u32 = 100;

impl Check {
    /// "`stream` sends on time": its median lateness within [`MAX_P50_LATENESS_US`] (a timing
    /// figure).
    pub(crate) fn on_time(stream: &str, lateness: &LatenessSummary) -> Self {
        Self::timing(
            format!("{stream}: send lateness p50 ≤ {MAX_P50_LATENESS_US} µs"),
            lateness.count > 0 && lateness.p50_us <= MAX_P50_LATENESS_US,
            format!("p50 {} µs, p99 {} µs over {} sends", lateness.p50_us, lateness.p99_us, lateness.count),
        )
    }
}

/// A fault the scenario injected, and whether the client side detected it.
#[derive(Debug)]
pub(crate) struct InjectedFault {
    /// What was injected, in a few words.
    pub(crate) injected: String,
    /// Whether the stack noticed (or, for a tolerated fault, rode it out as designed).
    pub(crate) detected: bool,
    /// How it showed, in a few words.
    pub(crate) how: String,
}

impl InjectedFault {
    pub(crate) fn new(injected: impl Into<String>, detected: bool, how: impl Into<String>) -> Self {
        Self { injected: injected.into(), detected, how: how.into() }
    }
}

/// One device's scenario: what it commanded and observed, with its rates, timing
/// percentiles, decoder counters, faults and checks.
#[derive(Debug)]
pub(crate) struct DeviceReport {
    /// The `--only` name.
    pub(crate) device: &'static str,
    /// Wall time of the scenario.
    pub(crate) elapsed: Duration,
    /// Short lines: what the scenario asked of the device.
    pub(crate) commanded: Vec<String>,
    /// Short lines: what came back.
    pub(crate) observed: Vec<String>,
    /// Measured rates, Hz.
    pub(crate) rates_hz: Vec<(&'static str, f64)>,
    /// Timing percentiles (latency, lateness, jitter), µs.
    pub(crate) timings: Vec<(&'static str, LatenessSummary)>,
    /// Decoder and link counters.
    pub(crate) counters: Vec<(&'static str, u64)>,
    /// Faults injected and what became of them.
    pub(crate) faults: Vec<InjectedFault>,
    /// The pass/fail checks.
    pub(crate) checks: Vec<Check>,
}

impl DeviceReport {
    pub(crate) fn new(device: &'static str) -> Self {
        Self {
            device,
            elapsed: Duration::ZERO,
            commanded: Vec::new(),
            observed: Vec::new(),
            rates_hz: Vec::new(),
            timings: Vec::new(),
            counters: Vec::new(),
            faults: Vec::new(),
            checks: Vec::new(),
        }
    }

    /// Every functional check passed (timing figures are reported, not judged here).
    pub(crate) fn passed(&self) -> bool {
        self.checks.iter().filter(|c| !c.timing).all(|c| c.passed)
    }

    /// The device's entry of the `--json` report.
    pub(crate) fn json(&self) -> Value {
        let object = |pairs: &mut dyn Iterator<Item = (String, Value)>| Value::Object(pairs.collect::<Map<_, _>>());
        json!({
            "device": self.device,
            "passed": self.passed(),
            "elapsed_s": round3(self.elapsed.as_secs_f64()),
            "commanded": self.commanded,
            "observed": self.observed,
            "rates_hz": object(&mut self.rates_hz.iter().map(|(k, v)| (k.to_string(), json!(round3(*v))))),
            "timings_us": object(&mut self.timings.iter().map(|(k, t)| {
                (k.to_string(), json!({"count": t.count, "p50": t.p50_us, "p99": t.p99_us, "max": t.max_us}))
            })),
            "counters": object(&mut self.counters.iter().map(|(k, v)| (k.to_string(), json!(v)))),
            "faults": self.faults.iter().map(|f| json!({
                "injected": f.injected, "detected": f.detected, "observed": f.how
            })).collect::<Vec<_>>(),
            "checks": self.checks.iter().map(Check::json).collect::<Vec<_>>(),
        })
    }
}

fn round3(v: f64) -> f64 {
    (v * 1e3).round() / 1e3
}

/// The whole demo as JSON: overall result (functional checks), every check (flat, with its
/// kind), every device.
pub(crate) fn json(reports: &[DeviceReport]) -> Value {
    let failed = reports.iter().flat_map(|r| &r.checks).filter(|c| !c.timing && !c.passed).count();
    json!({
        "passed": failed == 0,
        "failed": failed,
        "checks": reports.iter().flat_map(|r| &r.checks).map(Check::json).collect::<Vec<_>>(),
        "devices": reports.iter().map(DeviceReport::json).collect::<Vec<_>>(),
    })
}

/// The summary table: one column per device, one row per kind of figure; a cell may span
/// several lines.
pub(crate) fn table(reports: &[DeviceReport]) -> String {
    let rows: Vec<(&str, Vec<Vec<String>>)> = vec![
        (
            "result",
            reports
                .iter()
                .map(|r| {
                    let functional: Vec<_> = r.checks.iter().filter(|c| !c.timing).collect();
                    let ok = functional.iter().filter(|c| c.passed).count();
                    vec![format!("{} {ok}/{} checks", if r.passed() { "ok" } else { "FAIL" }, functional.len())]
                })
                .collect(),
        ),
        ("time", reports.iter().map(|r| vec![format!("{:.1} s", r.elapsed.as_secs_f64())]).collect()),
        ("commanded", reports.iter().map(|r| r.commanded.clone()).collect()),
        ("observed", reports.iter().map(|r| r.observed.clone()).collect()),
        (
            "rates",
            reports.iter().map(|r| r.rates_hz.iter().map(|(k, hz)| format!("{k} {hz:.1} Hz")).collect()).collect(),
        ),
        (
            "p50/p99/max µs",
            reports
                .iter()
                .map(|r| r.timings.iter().map(|(k, t)| format!("{k} {}/{}/{}", t.p50_us, t.p99_us, t.max_us)).collect())
                .collect(),
        ),
        ("counters", reports.iter().map(|r| r.counters.iter().map(|(k, v)| format!("{k} {v}")).collect()).collect()),
        (
            "faults",
            reports
                .iter()
                .map(|r| {
                    r.faults
                        .iter()
                        .map(|f| format!("{} {} {}", f.injected, if f.detected { "->" } else { "-> MISSED:" }, f.how))
                        .collect()
                })
                .collect(),
        ),
    ];
    let label_width = rows.iter().map(|(label, _)| label.chars().count()).max().unwrap_or(0);
    let widths: Vec<usize> = (0..reports.len())
        .map(|i| {
            rows.iter()
                .flat_map(|(_, cells)| cells[i].iter())
                .map(|line| line.chars().count())
                .chain([reports[i].device.len()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut out = String::new();
    let mut line = |label: &str, cells: &[&str]| {
        let mut text = format!("  {label:<label_width$}");
        for (cell, width) in cells.iter().zip(&widths) {
            text.push_str(&format!("  {cell:<width$}"));
        }
        out.push_str(text.trim_end());
        out.push('\n');
    };
    let devices: Vec<&str> = reports.iter().map(|r| r.device).collect();
    line("", &devices);
    let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
    line(&"-".repeat(label_width), &rule.iter().map(String::as_str).collect::<Vec<_>>());
    for (label, cells) in &rows {
        let height = cells.iter().map(Vec::len).max().unwrap_or(0).max(1);
        for k in 0..height {
            let texts: Vec<&str> = cells.iter().map(|c| c.get(k).map_or("", String::as_str)).collect();
            line(if k == 0 { label } else { "" }, &texts);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(device: &'static str, passed: bool) -> DeviceReport {
        let mut r = DeviceReport::new(device);
        r.elapsed = Duration::from_millis(1500);
        r.commanded = vec!["+0.50 m/s".into()];
        r.observed = vec!["+0.499 m/s".into(), "0.72 rad turned".into()];
        r.rates_hz = vec![("control", 100.04)];
        r.timings = vec![("lateness", LatenessSummary { count: 10, p50_us: 12, p99_us: 45, max_us: 80 })];
        r.counters = vec![("frames", 812)];
        r.faults = vec![InjectedFault::new("64 garbage bytes", passed, "skipped 64")];
        r.checks = vec![Check::new("speed", passed, "+0.499 m/s")];
        r
    }

    #[test]
    fn table_has_a_column_per_device_and_multi_line_cells() {
        let text = table(&[report("kmc", true), report("zsl1", false)]);
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[0].contains("kmc") && lines[0].contains("zsl1"), "{text}");
        let result = lines.iter().find(|l| l.trim_start().starts_with("result")).unwrap();
        assert!(result.contains("ok 1/1 checks") && result.contains("FAIL 0/1 checks"), "{text}");
        let observed = lines.iter().position(|l| l.trim_start().starts_with("observed")).unwrap();
        assert!(lines[observed + 1].contains("0.72 rad turned"), "second line of the cell: {text}");
        assert!(text.contains("lateness 12/45/80") && text.contains("control 100.0 Hz"), "{text}");
        assert!(text.contains("-> MISSED: skipped 64"), "an undetected fault stands out: {text}");
        // Columns line up: every row's second cell starts where the header's does.
        let column = lines[0].find("zsl1").unwrap();
        assert!(result[column..].starts_with("FAIL"), "{text}");
    }

    #[test]
    fn json_carries_checks_and_per_device_figures() {
        let value = json(&[report("kmc", true), report("zsl1", false)]);
        assert_eq!(value["passed"], false);
        assert_eq!(value["failed"], 1);
        assert_eq!(value["checks"].as_array().unwrap().len(), 2);
        let kmc = &value["devices"][0];
        assert_eq!(kmc["device"], "kmc");
        assert_eq!(kmc["elapsed_s"], 1.5);
        assert_eq!(kmc["rates_hz"]["control"], 100.04);
        assert_eq!(kmc["timings_us"]["lateness"]["p99"], 45);
        assert_eq!(kmc["counters"]["frames"], 812);
        assert_eq!(kmc["faults"][0]["detected"], true);
        assert_eq!(value["devices"][1]["passed"], false);
    }
}
