use super::*;
use crate::check::Verdict;

fn robot() -> DiscoveredParticipant {
    DiscoveredParticipant {
        guid_prefix: [1, 16, 0xab, 0xcd, 0, 0, 0, 1, 0, 0, 0, 2],
        vendor: ([1, 16], Some("Eclipse CycloneDDS")),
        user_data: Vec::new(),
        unicast: vec!["192.168.123.161:7410".parse().unwrap()],
    }
}

fn endpoint(topic: &str, writer: bool, entity: u8) -> DiscoveredEndpoint {
    let mut guid = [0u8; 16];
    guid[..12].copy_from_slice(&robot().guid_prefix);
    guid[15] = entity;
    DiscoveredEndpoint { guid, writer, topic: topic.into(), type_name: "unitree_go::msg::dds_::LowState_".into() }
}

fn healthy() -> DdsObservation {
    DdsObservation {
        domain: 0,
        seconds: 2.0,
        interface_ipv4: vec![([192, 168, 123, 99].into(), 24)],
        loopback: false,
        participants: vec![robot()],
        endpoints: vec![endpoint(LOWSTATE, true, 2), endpoint(LOWCMD, false, 7)],
        other_domains: Vec::new(),
        lowstate: Some((TopicStats { samples: 1000, ..TopicStats::default() }, 2.0)),
        mode_machine: None,
        services: Vec::new(),
        motors_owner: None,
    }
}

fn failed(checks: &[Check]) -> Vec<&Check> {
    checks.iter().filter(|c| c.verdict == Verdict::Fail).collect()
}

#[test]
fn a_robot_publishing_good_lowstates_passes() {
    let checks = checks(&healthy());
    assert!(failed(&checks).is_empty(), "{checks:#?}");
    assert_eq!(checks[0].saw, "1 on domain 0: Eclipse CycloneDDS 0110abcd0000000100000002 at 192.168.123.161:7410");
    assert_eq!(checks[2].saw, "1000 samples in 2.0 s (500 Hz)");
    assert_eq!(checks[3].saw, "100.0% of 1000 with a good CRC (0 bad CRC, 0 undecodable)");
}

#[test]
fn nobody_on_the_domain_names_the_domain_that_has_traffic() {
    let seen = DdsObservation { participants: Vec::new(), other_domains: vec![(1, 1), (2, 0)], ..healthy() };
    let checks = checks(&seen);
    assert_eq!(checks.len(), 1);
    assert_eq!(checks[0].saw, "nobody on domain 0; participants on domain 1 (1)");
    assert!(checks[0].fix.as_deref().unwrap().starts_with("use domain 1"));
    let silent = DdsObservation { participants: Vec::new(), ..healthy() };
    assert!(checks_of(&silent)[0].saw.starts_with("nobody heard on domain 0 nor on domains 0–9"));
}

fn checks_of(seen: &DdsObservation) -> Vec<Check> {
    checks(seen)
}

#[test]
fn a_participant_announcing_another_subnet_is_unreachable() {
    let mut seen = healthy();
    seen.participants[0].unicast = vec!["172.17.0.2:7410".parse().unwrap()];
    seen.lowstate = Some((TopicStats::default(), 2.0));
    let checks = checks(&seen);
    let failed = failed(&checks);
    assert_eq!(failed.len(), 2);
    assert_eq!(failed[0].name, "DDS locators");
    assert!(failed[0].saw.contains("announces 172.17.0.2:7410: not reachable from 192.168.123.99/24"));
    assert_eq!(failed[1].saw, "1 writer(s) discovered, no sample arrived in 2.0 s");
}

#[test]
fn loopback_locators_are_reachable_from_loopback_only() {
    let mut seen = healthy();
    seen.participants[0].unicast = vec!["127.0.0.1:7410".parse().unwrap()];
    assert_eq!(failed(&checks(&seen))[0].name, "DDS locators");
    (seen.interface_ipv4, seen.loopback) = (vec![([127, 0, 0, 1].into(), 8)], true);
    assert!(failed(&checks(&seen)).is_empty());
}

#[test]
fn bad_crcs_and_a_second_lowcmd_writer_fail() {
    let mut seen = healthy();
    seen.lowstate = Some((TopicStats { samples: 900, checksum_errors: 100, ..TopicStats::default() }, 2.0));
    seen.endpoints.push(endpoint(LOWCMD, true, 3));
    let checks = checks(&seen);
    let failed = failed(&checks);
    assert_eq!(failed.len(), 2);
    assert_eq!(failed[0].saw, "90.0% of 1000 with a good CRC (100 bad CRC, 0 undecodable)");
    assert_eq!(failed[1].saw, "already published by 1: 0110abcd000000010000000200000003 (Eclipse CycloneDDS)");
    assert!(failed[1].fix.as_deref().unwrap().contains("two writers of rt/lowcmd"));
}

#[test]
fn no_lowstate_writer_says_so() {
    let mut seen = healthy();
    seen.endpoints.retain(|e| e.topic != LOWSTATE);
    seen.lowstate = None;
    assert_eq!(failed(&checks(&seen))[0].saw, "no participant publishes rt/lowstate");
}

#[test]
fn services_the_motors_owner_and_the_mode_machine_are_reported() {
    let mut seen = healthy();
    seen.endpoints
        .push(DiscoveredEndpoint { topic: "rt/api/motion_switcher/request".into(), ..endpoint("", false, 9) });
    assert_eq!(services(&seen.endpoints), ["motion_switcher"]);
    seen.services = vec![("motion_switcher".into(), Some(Ok("1.0.0.1".into()))), ("vui".into(), None)];
    seen.motors_owner = Some(Ok("normal".into()));
    seen.mode_machine = Some(5);
    let checks = checks(&seen);
    assert!(failed(&checks).is_empty(), "{checks:#?}");
    let saw = |name: &str| checks.iter().find(|c| c.name == name).unwrap().saw.clone();
    assert_eq!(saw("services"), "motion_switcher 1.0.0.1, vui (not asked)");
    assert!(saw("motors").starts_with("sport mode \"normal\" owns them"));
    assert_eq!(saw("HG mode_machine"), "5: a G1 Dof29; LowCmds must carry it");
    seen.motors_owner = Some(Err("timed out".into()));
    seen.mode_machine = Some(200);
    let checks = super::checks(&seen);
    let verdict = |name: &str| checks.iter().find(|c| c.name == name).unwrap().verdict;
    assert_eq!((verdict("motors"), verdict("HG mode_machine")), (Verdict::Unknown, Verdict::Unknown));
}

#[test]
fn a_service_that_does_not_answer_fails() {
    let mut seen = healthy();
    seen.services = vec![("sport".into(), Some(Err("no answer within 2 s".into())))];
    let checks = checks(&seen);
    let failed = failed(&checks);
    assert_eq!(failed.len(), 1);
    assert_eq!(failed[0].saw, "discovered but not answering: sport (no answer within 2 s)");
    assert!(failed[0].fix.as_deref().unwrap().contains("send request error"));
}
