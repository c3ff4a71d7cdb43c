//! The KMC chassis simulator on a pseudo-terminal: healthy, and with line noise.

use std::time::Duration;

use robowire_doctor::{Options, Target, Verdict};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig, Fault};

fn diagnose(sim: &ChassisSim) -> robowire_doctor::Report {
    let options = Options { interface: None, domain: 0, timeout: Duration::from_secs(1) };
    robowire_doctor::diagnose(&Target::Kmc(sim.path()), &options)
}

#[test]
fn a_simulated_chassis_passes() {
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    let report = diagnose(&sim);
    assert!(!report.failed(), "{report}");
    let battery = report.checks.iter().find(|c| c.name == "battery").unwrap();
    assert_eq!(battery.saw, "25.2 V");
}

#[test]
fn line_noise_is_named_with_its_likely_cause() {
    let sim = ChassisSim::spawn(ChassisSimConfig::default()).unwrap();
    sim.inject(Fault::Garbage { bytes: 4096 });
    let report = diagnose(&sim);
    let failed: Vec<_> = report.checks.iter().filter(|c| c.verdict == Verdict::Fail).collect();
    assert_eq!(failed.len(), 1, "{report}");
    assert_eq!(failed[0].name, "line noise");
    assert!(failed[0].saw.contains("% of "), "{report}");
    assert!(
        failed[0].fix.as_deref().unwrap().starts_with("a wrong baud rate or flow control reads as noise"),
        "{report}"
    );
}
