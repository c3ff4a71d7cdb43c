//! The ZSL-1 checks: pure functions of a [`Zsl1Observation`].

use std::net::{IpAddr, SocketAddr};

use crate::check::Check;

/// What arrived on the local port (`diagnose` listens with a UDP link).
#[derive(Debug, Clone, PartialEq)]
pub struct Zsl1Observation {
    /// The robot's HighLevel address.
    pub robot: SocketAddr,
    /// The local port listened on, or why it could not be bound.
    pub local: Result<u16, String>,
    /// This host's address toward the robot (what the robot's `target_ip` must be).
    pub our_ip: Option<IpAddr>,
    /// How long it listened before asking, seconds.
    pub seconds: f64,
    /// State datagrams from the robot's IP while only listening.
    pub states: u64,
    /// State datagrams from the robot's IP after one idle HighLevel command (`None`: not asked).
    pub answered: Option<u64>,
    /// Datagrams that did not decode as HighLevel state (from anyone).
    pub undecodable: u64,
    /// State datagrams from other addresses, by source (at most [`MAX_SOURCES`]).
    pub others: Vec<(SocketAddr, u64)>,
}

/// How many other sources are told apart.
pub const MAX_SOURCES: usize = 8;

/// The ZSL-1 checks, in order.
pub fn checks(seen: &Zsl1Observation) -> Vec<Check> {
    let robot = seen.robot.ip();
    let port = match &seen.local {
        Ok(port) => *port,
        Err(why) => {
            return vec![Check::fail(
                "ZSL-1 local port",
                format!("cannot listen for the state: {why}"),
                "stop the other ZSL-1 client on this host: the robot's state goes to one port",
            )];
        }
    };
    let mut out = Vec::new();
    let others: Vec<String> = seen.others.iter().map(|(from, n)| format!("{from} ({n})")).collect();
    out.push(match (seen.states, seen.answered) {
        (0, Some(n)) if n > 0 => Check::pass(
            "ZSL-1 state",
            format!("none until asked; after one idle HighLevel command {n} from {robot} on port {port}"),
        ),
        (0, _) => {
            let target = seen.our_ip.map_or_else(|| "this host's address on the robot's subnet".into(), |ip| ip.to_string());
            Check::fail(
                "ZSL-1 state",
                format!(
                    "no state datagram from {robot} on port {port} in {:.1} s, nor after one idle HighLevel command to {}",
                    seen.seconds, seen.robot
                ),
                format!("in the robot's sdk_config.yaml set target_ip: {target} and target_port: {port}, then restart its SDK"),
            )
        }
        (n, _) => Check::pass(
            "ZSL-1 state",
            format!("{n} state datagrams from {robot} on port {port} in {:.1} s ({:.0} Hz)", seen.seconds, n as f64 / seen.seconds.max(1e-3)),
        ),
    });
    let heard = seen.states + seen.answered.unwrap_or(0);
    out.push(if seen.undecodable == 0 {
        Check::pass("ZSL-1 datagrams decode", "no datagram that does not decode as HighLevel state")
    } else {
        Check::fail(
            "ZSL-1 datagrams decode",
            format!("{} datagrams did not decode as HighLevel state ({heard} did)", seen.undecodable),
            "another program sends to this port, or the robot runs another SDK version: see them with robowire decode zsl",
        )
    });
    out.push(match (&seen.others[..], heard) {
        ([], _) => Check::pass("other sources", "no state datagram from another address"),
        (_, 0) => {
            let first = seen.others[0].0.ip();
            Check::fail(
                "other sources",
                format!("state from {}, not from {robot}", others.join(", ")),
                format!("is the robot at {first}? robowire doctor zsl1:{first}"),
            )
        }
        _ => Check::pass("other sources", format!("also state from {}", others.join(", "))),
    });
    out
}

/// What arrived on `port` without an address to ask: who sends ZSL-1 state there (a `?` when
/// nobody does: there may be no ZSL-1).
pub fn overheard(heard: &Result<Vec<(SocketAddr, u64)>, String>, port: u16, seconds: f64) -> Check {
    match heard {
        Err(why) => Check::unknown("ZSL-1", format!("cannot listen on UDP {port}: {why}")),
        Ok(heard) if heard.is_empty() => Check::unknown(
            "ZSL-1",
            format!(
                "no ZSL-1 state on port {port} in {seconds:.1} s (a ZSL-1 sends it to the target_ip and target_port of its sdk_config.yaml)"
            ),
        ),
        Ok(heard) => {
            let listed: Vec<String> = heard.iter().map(|(from, n)| format!("{from} ({n})")).collect();
            Check::pass(
                "ZSL-1",
                format!("state on port {port} from {}: robowire doctor zsl1:{}", listed.join(", "), heard[0].0.ip()),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Verdict;

    fn seen() -> Zsl1Observation {
        Zsl1Observation {
            robot: "192.168.234.1:43997".parse().unwrap(),
            local: Ok(43988),
            our_ip: Some("192.168.234.99".parse().unwrap()),
            seconds: 2.0,
            states: 1000,
            answered: None,
            undecodable: 0,
            others: Vec::new(),
        }
    }

    fn failures(checks: &[Check]) -> Vec<&Check> {
        checks.iter().filter(|c| c.verdict == Verdict::Fail).collect()
    }

    #[test]
    fn a_streaming_robot_passes() {
        let checks = checks(&seen());
        assert!(failures(&checks).is_empty(), "{checks:#?}");
        assert_eq!(checks[0].saw, "1000 state datagrams from 192.168.234.1 on port 43988 in 2.0 s (500 Hz)");
    }

    #[test]
    fn a_robot_sending_elsewhere_gets_its_target_in_the_fix() {
        let silent = Zsl1Observation { states: 0, answered: Some(0), ..seen() };
        let checks = checks(&silent);
        let failed = failures(&checks);
        assert_eq!(failed.len(), 1, "{checks:#?}");
        assert_eq!(
            failed[0].fix.as_deref(),
            Some(
                "in the robot's sdk_config.yaml set target_ip: 192.168.234.99 and target_port: 43988, then restart its SDK"
            )
        );
        let answered = Zsl1Observation { states: 0, answered: Some(12), ..seen() };
        assert!(failures(&super::checks(&answered)).is_empty());
    }

    #[test]
    fn state_overheard_without_an_address_names_its_sender() {
        let heard = Ok(vec![("192.168.234.1:40000".parse().unwrap(), 9)]);
        let check = overheard(&heard, 43988, 2.0);
        assert_eq!(check.saw, "state on port 43988 from 192.168.234.1:40000 (9): robowire doctor zsl1:192.168.234.1");
        assert_eq!(overheard(&Ok(Vec::new()), 43988, 2.0).verdict, Verdict::Unknown);
    }

    #[test]
    fn a_busy_port_noise_and_another_source_fail() {
        let busy = Zsl1Observation { local: Err("Address in use".into()), ..seen() };
        assert_eq!(checks(&busy)[0].saw, "cannot listen for the state: Address in use");
        let noisy = Zsl1Observation { undecodable: 3, ..seen() };
        assert_eq!(failures(&checks(&noisy))[0].saw, "3 datagrams did not decode as HighLevel state (1000 did)");
        let elsewhere = Zsl1Observation {
            states: 0,
            answered: Some(0),
            others: vec![("192.168.234.7:40000".parse().unwrap(), 50)],
            ..seen()
        };
        let checks = checks(&elsewhere);
        assert_eq!(
            failures(&checks)[1].fix.as_deref(),
            Some("is the robot at 192.168.234.7? robowire doctor zsl1:192.168.234.7")
        );
    }
}
