//! The golden regression suite: every fixture decodes to its expected fields and re-encodes
//! byte for byte. `--bless` rewrites robowire's own expected fields from the decoder (never the
//! bytes); vendor-generated vectors (Unitree) are never rewritten.

pub mod kmc;
pub mod rtps;
pub mod unitree;
pub mod zsl1;

use serde::Serialize;
use serde_json::Value;

/// What the suite found for one fixture.
#[derive(Debug)]
pub struct Outcome {
    /// Fixture name.
    pub name: String,
    /// Everything that did not match; empty when the fixture passed.
    pub problems: Vec<String>,
    /// The expected fields were rewritten (`--bless`).
    pub blessed: bool,
}

impl Outcome {
    /// A passed or failed check.
    pub fn new(name: impl Into<String>, problems: Vec<String>) -> Self {
        Self { name: name.into(), problems, blessed: false }
    }
}

/// A value as JSON, through text so that f32 values keep their shortest form.
pub(crate) fn to_json<T: Serialize>(value: &T) -> anyhow::Result<Value> {
    Ok(serde_json::from_str(&serde_json::to_string(value)?)?)
}

/// `cargo xtask golden [--bless]`: every suite, a line per check; an error if any failed.
pub fn run(bless: bool) -> anyhow::Result<()> {
    let kmc_path = kmc::kmc_fixture_path();
    let unitree_path = unitree::vectors_path();
    let zsl1_path = zsl1::frames_path();
    let rtps_path = rtps::fixtures_path();
    let suites = [
        ("kmc", kmc::check_kmc(&kmc_path, bless)?),
        ("unitree", unitree::check(&unitree_path)?),
        ("zsl1", zsl1::check(&zsl1_path)?),
        ("rtps", rtps::check(&rtps_path)?),
    ];
    let mut failed = 0;
    let mut total = 0;
    for (suite, outcomes) in &suites {
        for outcome in outcomes {
            total += 1;
            let status = if !outcome.problems.is_empty() {
                failed += 1;
                "FAIL"
            } else if outcome.blessed {
                "BLESSED"
            } else {
                "ok"
            };
            println!("{suite:<8} {:<48} {status}", outcome.name);
            for problem in &outcome.problems {
                println!("    {problem}");
            }
        }
    }
    anyhow::ensure!(failed == 0, "{failed} of {total} golden checks failed");
    println!(
        "{total} golden checks passed ({}, {}, {}, {})",
        kmc_path.display(),
        unitree_path.display(),
        zsl1_path.display(),
        rtps_path.display()
    );
    Ok(())
}
