//! Whether an nftables ruleset (`nft list ruleset`'s text) drops UDP to a range of ports.
//!
//! Read conservatively: in the chains hooked at `prerouting`, `input` or `output`, a rule whose
//! verdict is `drop` or `reject` and that matches UDP (`udp dport …`, `th dport …`, `meta
//! l4proto udp`, `ip protocol udp`, or no match at all) on a port of the range; a chain whose
//! policy is `drop` without an `accept` of UDP to that range before it. Negated matches (`!=`)
//! and rules matching on other fields only are not taken as drops.

use std::ops::RangeInclusive;

/// The first rule or policy of `ruleset` that drops UDP to a port of `ports`, described as
/// `table inet filter, chain input: udp dport 7400-7700 drop`.
pub fn udp_drop(ruleset: &str, ports: &RangeInclusive<u16>) -> Option<String> {
    let mut table = String::new();
    let mut chain = String::new();
    let mut hooked = false;
    let mut policy_drop = false;
    let mut accepted = false;
    let mut found = None;
    let close_chain = |chain: &str, table: &str, hooked: bool, policy_drop: bool, accepted: bool| {
        if hooked && policy_drop && !accepted {
            Some(format!("table {table}, chain {chain}: policy drop (no rule accepts UDP {ports:?} first)"))
        } else {
            None
        }
    };
    for line in ruleset.lines().map(str::trim) {
        if let Some(rest) = line.strip_prefix("table ") {
            table = rest.trim_end_matches('{').trim().to_owned();
        } else if let Some(rest) = line.strip_prefix("chain ") {
            chain = rest.trim_end_matches('{').trim().to_owned();
            (hooked, policy_drop, accepted) = (false, false, false);
        } else if line.starts_with("type ") && line.contains(" hook ") {
            hooked = ["prerouting", "input", "output"].iter().any(|h| line.contains(&format!("hook {h} ")));
            policy_drop = line.contains("policy drop");
        } else if line == "}" {
            if !chain.is_empty() {
                if let Some(f) = close_chain(&chain, &table, hooked, policy_drop, accepted) {
                    found.get_or_insert(f);
                }
                chain.clear();
                hooked = false;
            }
        } else if hooked && !line.is_empty() {
            match rule_matches(line, ports) {
                Some(Action::Drop) => {
                    found.get_or_insert(format!("table {table}, chain {chain}: {line}"));
                }
                Some(Action::Accept) => accepted = true,
                None => {}
            }
        }
        if found.is_some() {
            break;
        }
    }
    found
}

enum Action {
    Drop,
    Accept,
}

/// What `rule` does to UDP to a port of `ports`: `None` when it does not apply (or is not read).
fn rule_matches(rule: &str, ports: &RangeInclusive<u16>) -> Option<Action> {
    let words: Vec<&str> = rule.split_whitespace().collect();
    let action = if words.iter().any(|w| *w == "drop" || *w == "reject") {
        Action::Drop
    } else if words.contains(&"accept") {
        Action::Accept
    } else {
        return None;
    };
    if rule.contains("!=") {
        return None;
    }
    let dport = words.windows(2).position(|w| (w[0] == "udp" || w[0] == "th") && w[1] == "dport");
    if let Some(at) = dport {
        return port_spec_hits(&words[at + 2..], ports).then_some(action);
    }
    let udp = rule.contains("l4proto udp") || rule.contains("protocol udp");
    let tcp_only = rule.contains("tcp") && !udp;
    let other_match =
        words.iter().any(|w| ["saddr", "daddr", "iifname", "oifname", "iif", "oif", "ct", "sport"].contains(w));
    if tcp_only || (other_match && !udp) {
        return None;
    }
    // UDP to every port, or no match at all: everything.
    (udp || !other_match).then_some(action)
}

/// Whether the port spec at the start of `words` (`7400`, `7400-7700`, `{ 7400, 7410-7420 }`)
/// names a port of `ports`.
fn port_spec_hits(words: &[&str], ports: &RangeInclusive<u16>) -> bool {
    let spec: Vec<&str> = if words.first() == Some(&"{") {
        words[1..].iter().take_while(|w| **w != "}").copied().collect()
    } else {
        words.first().copied().into_iter().collect()
    };
    spec.iter().map(|w| w.trim_end_matches(',')).filter(|w| !w.is_empty()).any(|item| {
        let (low, high) = item.split_once('-').unwrap_or((item, item));
        match (low.parse::<u16>(), high.parse::<u16>()) {
            (Ok(low), Ok(high)) => low <= *ports.end() && high >= *ports.start(),
            _ => false,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const DDS: RangeInclusive<u16> = 7400..=7700;

    fn ruleset(chain_body: &str) -> String {
        format!(
            "table inet filter {{\n\tchain input {{\n\t\ttype filter hook input priority filter; policy accept;\n{chain_body}\n\t}}\n}}\n"
        )
    }

    #[test]
    fn a_rule_dropping_the_dds_ports_is_found() {
        let found = udp_drop(&ruleset("\t\tudp dport 7400-7700 drop"), &DDS).unwrap();
        assert_eq!(found, "table inet filter, chain input: udp dport 7400-7700 drop");
        assert!(udp_drop(&ruleset("\t\tudp dport { 53, 7410-7411 } counter reject"), &DDS).is_some());
        assert!(udp_drop(&ruleset("\t\tmeta l4proto udp drop"), &DDS).is_some());
        assert!(udp_drop(&ruleset("\t\tcounter packets 0 bytes 0 drop"), &DDS).is_some());
    }

    #[test]
    fn rules_for_other_ports_protocols_or_hooks_are_not() {
        assert_eq!(udp_drop(&ruleset("\t\tudp dport 53 drop"), &DDS), None);
        assert_eq!(udp_drop(&ruleset("\t\ttcp dport 7400 drop"), &DDS), None);
        assert_eq!(udp_drop(&ruleset("\t\tudp dport != 7400 drop"), &DDS), None);
        assert_eq!(udp_drop(&ruleset("\t\tip saddr 10.0.0.1 drop"), &DDS), None);
        assert_eq!(udp_drop(&ruleset("\t\tudp dport 7400 accept"), &DDS), None);
        let forward = "table ip t {\n\tchain c {\n\t\ttype filter hook forward priority 0; policy drop;\n\t\tudp dport 7400 drop\n\t}\n}\n";
        assert_eq!(udp_drop(forward, &DDS), None);
        assert_eq!(udp_drop("", &DDS), None);
    }

    #[test]
    fn a_drop_policy_counts_unless_a_rule_accepts_the_ports() {
        let policy = |body: &str| ruleset(body).replace("policy accept", "policy drop");
        assert!(udp_drop(&policy("\t\tct state established accept"), &DDS).unwrap().contains("policy drop"));
        assert_eq!(udp_drop(&policy("\t\tudp dport 7400-7700 accept"), &DDS), None);
        assert!(udp_drop(&policy("\t\tudp dport 43988 accept"), &(43988..=43988)).is_none());
    }
}
