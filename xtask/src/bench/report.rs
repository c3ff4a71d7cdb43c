//! The benchmark table as Markdown, and `docs/performance.md`: the table of the last
//! `cargo xtask bench` run with the run's date and machine, written by the run alone.

use std::fmt::Write as _;

use super::{BENCHES, Row};

/// The page the run writes, relative to the workspace root.
pub const PAGE: &str = "docs/performance.md";

/// The sources that measure the rows besides [`BENCHES`]: the Python rows, and physics (with
/// MuJoCo).
const OTHER_SOURCES: &[&str] = &["crates/robowire-py/bench/bench_python.py", "crates/robowire-sim/benches/physics.rs"];

/// The table as Markdown.
pub fn to_markdown(rows: &[Row]) -> String {
    let mut out =
        String::from("| path | figure | baseline (same run) | ratio | target | met |\n|---|---|---|---|---|---|\n");
    for r in rows {
        let met = match r.met {
            Some(true) => "yes",
            Some(false) => "**no**",
            None => "–",
        };
        let _ = writeln!(out, "| {} | {} | {} | {} | {} | {met} |", r.path, r.figure, r.baseline, r.ratio, r.target);
    }
    out
}

/// `docs/performance.md` for `rows` of a run made now (`quick`: with `--quick`).
pub fn page(rows: &[Row], quick: bool) -> String {
    let unix_s = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let cpus = std::thread::available_parallelism().map_or(0, usize::from);
    let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default();
    let command = if quick { "cargo xtask bench --quick" } else { "cargo xtask bench" };
    let missed = rows.iter().filter(|r| r.met == Some(false)).count();
    let mut out = String::from("# Performance\n\n<!-- Written by `cargo xtask bench`: a run overwrites it. -->\n\n");
    let _ = writeln!(
        out,
        "`{command}` on {}, {cpus} CPUs, Linux {}: every figure beside a baseline measured in the same run; \
         {} of {} targets missed. How each row is measured is in its bench's source:",
        civil_date(unix_s / 86_400),
        kernel.trim(),
        missed,
        rows.iter().filter(|r| r.met.is_some()).count(),
    );
    out.push('\n');
    let root = crate::workspace_root();
    // A bench is `benches/{bench}.rs` or, split in modules, `benches/{bench}/main.rs`.
    let sources = BENCHES.iter().map(|(package, bench)| {
        let file = format!("crates/{package}/benches/{bench}.rs");
        if root.join(&file).exists() { file } else { format!("crates/{package}/benches/{bench}/main.rs") }
    });
    for source in sources.chain(OTHER_SOURCES.iter().map(|s| s.to_string())) {
        let _ = writeln!(out, "- [`{source}`](../{source})");
    }
    out.push('\n');
    out.push_str(&to_markdown(rows));
    out
}

/// `YYYY-MM-DD` of the day `days` after 1970-01-01 (the proleptic Gregorian calendar).
fn civil_date(days: u64) -> String {
    // Howard Hinnant's days-to-civil, shifted so that years start in March.
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_of_known_days() {
        assert_eq!(civil_date(0), "1970-01-01");
        assert_eq!(civil_date(11_016), "2000-02-29");
        assert_eq!(civil_date(20_784), "2026-11-27");
    }

    #[test]
    fn every_source_the_page_names_exists() {
        let page = page(&[], true);
        let root = crate::workspace_root();
        for line in page.lines().filter_map(|l| l.strip_prefix("- [`")) {
            let source = line.split('`').next().unwrap();
            assert!(root.join(source).is_file(), "{source} named in {PAGE}");
        }
    }
}
