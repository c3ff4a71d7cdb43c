//! One check's outcome, and a run's list of them.

use std::fmt;

use serde::Serialize;

/// What a check concluded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Fine.
    Pass,
    /// Broken: the check says the fix.
    Fail,
    /// Could not be told (not readable, not measurable).
    Unknown,
}

impl Verdict {
    /// Its mark in the checklist: ✓, ✗ or ?.
    pub fn mark(self) -> char {
        match self {
            Self::Pass => '✓',
            Self::Fail => '✗',
            Self::Unknown => '?',
        }
    }
}

/// One check: its name, verdict, what it saw, and for a failure the one thing to do.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Check {
    /// What was checked (`interface`, `multicast route`, `rt/lowstate`).
    pub name: String,
    /// The verdict.
    pub verdict: Verdict,
    /// What was observed.
    pub saw: String,
    /// What to do (every failure has one).
    pub fix: Option<String>,
}

impl Check {
    /// A passed check.
    pub fn pass(name: &str, saw: impl Into<String>) -> Self {
        Self { name: name.into(), verdict: Verdict::Pass, saw: saw.into(), fix: None }
    }

    /// A failed check and its fix.
    pub fn fail(name: &str, saw: impl Into<String>, fix: impl Into<String>) -> Self {
        Self { name: name.into(), verdict: Verdict::Fail, saw: saw.into(), fix: Some(fix.into()) }
    }

    /// A check that could not tell.
    pub fn unknown(name: &str, saw: impl Into<String>) -> Self {
        Self { name: name.into(), verdict: Verdict::Unknown, saw: saw.into(), fix: None }
    }
}

impl fmt::Display for Check {
    /// `✗ name: saw`, then `  fix: …` on a line of its own.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}: {}", self.verdict.mark(), self.name, self.saw)?;
        if let Some(fix) = &self.fix {
            write!(f, "\n  fix: {fix}")?;
        }
        Ok(())
    }
}

/// Every check of one run, in the order they ran.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Report {
    /// What was diagnosed (`go2:eth0`).
    pub target: String,
    /// The checks.
    pub checks: Vec<Check>,
}

impl Report {
    /// Whether a check failed.
    pub fn failed(&self) -> bool {
        self.checks.iter().any(|c| c.verdict == Verdict::Fail)
    }
}

impl fmt::Display for Report {
    /// One line per check (two with a fix).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for check in &self.checks {
            writeln!(f, "{check}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failure_prints_its_fix_under_it() {
        let check = Check::fail("multicast", "eth0 lacks MULTICAST", "sudo ip link set eth0 multicast on");
        assert_eq!(check.to_string(), "✗ multicast: eth0 lacks MULTICAST\n  fix: sudo ip link set eth0 multicast on");
        assert_eq!(Check::pass("link", "up").to_string(), "✓ link: up");
        assert_eq!(Check::unknown("MTU", "not measured").to_string(), "? MTU: not measured");
    }

    #[test]
    fn a_report_fails_when_one_check_does() {
        let mut report =
            Report { target: "go2:eth0".into(), checks: vec![Check::pass("a", "x"), Check::unknown("b", "y")] };
        assert!(!report.failed());
        report.checks.push(Check::fail("c", "z", "do it"));
        assert!(report.failed());
        let json = serde_json::to_value(&report).unwrap();
        assert_eq!(json["checks"][2]["verdict"], "fail");
        assert_eq!(json["checks"][2]["fix"], "do it");
        assert_eq!(json["checks"][0]["fix"], serde_json::Value::Null);
    }
}
