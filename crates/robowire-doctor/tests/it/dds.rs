//! One broken DDS setup per test, each asserting its ✗ and its fix, and the healthy Go2 passing.

use std::time::Duration;

use robowire_dds::qos::Qos;
use robowire_dds::{Participant, ParticipantOptions};
use robowire_devices::DeviceKind;
use robowire_doctor::{Check, Options, Report, Target, Verdict};
use robowire_sim::g1::{G1Fault, G1Sim, G1SimConfig};
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
use unitree_proto::{LowCmd, Message};

/// How long the doctor listens: discovery on loopback takes milliseconds (a newcomer is answered
/// at once); the rest measures `rt/lowstate`.
const LISTEN: Duration = Duration::from_secs(2);

fn on_lo(domain: u16) -> ParticipantOptions {
    ParticipantOptions::new(domain, Some("lo"))
}

fn diagnose(kind: DeviceKind, domain: u16) -> Report {
    let options = Options { interface: None, domain, timeout: LISTEN };
    robowire_doctor::diagnose(&Target::Unitree { kind, interface: "lo".into() }, &options)
}

fn check<'a>(report: &'a Report, name: &str) -> &'a Check {
    report.checks.iter().find(|c| c.name == name).unwrap_or_else(|| panic!("no check {name}:\n{report}"))
}

fn failures(report: &Report) -> Vec<&str> {
    report.checks.iter().filter(|c| c.verdict == Verdict::Fail).map(|c| c.name.as_str()).collect()
}

#[test]
fn a_simulated_go2_on_loopback_passes_every_check() {
    robowire_dds::netns::with_private_network(|| {
        let _sim = Go2Sim::spawn(Go2SimConfig { participant: on_lo(0), ..Go2SimConfig::default() }).unwrap();
        let report = diagnose(DeviceKind::Go2, 0);
        assert!(!report.failed(), "{report}");
        let state = check(&report, "rt/lowstate");
        assert!(state.saw.contains(" samples in "), "{state}");
        assert_eq!(check(&report, "LowState CRC").verdict, Verdict::Pass);
        assert!(check(&report, "DDS participants").saw.starts_with("1 on domain 0: robowire "), "{report}");
        assert_eq!(check(&report, "services").saw, "motion_switcher 1.0.0.1, sport 1.0.0.1");
        // The simulated Go2 boots as the robot does, its sport mode owning the motors.
        assert!(check(&report, "motors").saw.starts_with("sport mode \"normal\" owns them"), "{report}");
    });
}

#[test]
fn the_simulator_on_domain_1_and_the_doctor_on_0() {
    robowire_dds::netns::with_private_network(|| {
        let _sim = Go2Sim::spawn(Go2SimConfig { participant: on_lo(1), ..Go2SimConfig::default() }).unwrap();
        let report = diagnose(DeviceKind::Go2, 0);
        assert_eq!(failures(&report), ["DDS participants"], "{report}");
        let found = check(&report, "DDS participants");
        assert_eq!(found.saw, "nobody on domain 0; participants on domain 1 (1)");
        assert_eq!(
            found.fix.as_deref(),
            Some("use domain 1 (robowire --domain 1; Unitree's SDK: ChannelFactoryInitialize(1, …))")
        );
    });
}

#[test]
fn a_second_lowcmd_writer() {
    robowire_dds::netns::with_private_network(|| {
        let _sim = Go2Sim::spawn(Go2SimConfig { participant: on_lo(0), ..Go2SimConfig::default() }).unwrap();
        let other = Participant::new(on_lo(0)).unwrap();
        let writer = other.writer::<LowCmd>(LowCmd::TOPIC, Qos::STREAM_WRITER).unwrap();
        let report = diagnose(DeviceKind::Go2, 0);
        assert_eq!(failures(&report), ["rt/lowcmd writers"], "{report}");
        let found = check(&report, "rt/lowcmd writers");
        let guid: String = writer.guid().iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(found.saw, format!("already published by 1: {guid} (robowire)"));
        assert_eq!(
            found.fix.as_deref(),
            Some("stop that controller before starting yours: two writers of rt/lowcmd fight over the motors")
        );
    });
}

#[test]
fn a_g1_whose_lowstate_crc_is_corrupted() {
    robowire_dds::netns::with_private_network(|| {
        let sim = G1Sim::spawn(G1SimConfig { participant: on_lo(0), ..G1SimConfig::default() }).unwrap();
        sim.inject(G1Fault::BitFlips { every: 2 });
        let report = diagnose(DeviceKind::G1, 0);
        assert_eq!(failures(&report), ["LowState CRC"], "{report}");
        let found = check(&report, "LowState CRC");
        assert!(found.saw.contains("with a good CRC ("), "{found}");
        assert!(!found.saw.starts_with("100.0%"), "{found}");
        assert!(found.fix.as_deref().unwrap().contains("Unitree's CRC"), "{found}");
        assert_eq!(check(&report, "HG mode_machine").saw, "5: a G1 Dof29; LowCmds must carry it");
    });
}
