//! The DDS probe: a participant on the domain and interface, listening.

use std::time::{Duration, Instant};

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Listener, Participant, ParticipantOptions, StatsHandle};
use unitree_proto::{HgLowState, LowState, Message};

use crate::dds::{DdsObservation, LOWSTATE};

/// A reader of `rt/lowstate` counting what arrives, made once a writer's type is known.
struct LowStateCount {
    stats: StatsHandle,
    since: Instant,
    _listener: Listener,
}

fn count_lowstate(participant: &Participant, type_name: &str) -> Result<LowStateCount, DdsError> {
    let (stats, listener) = if type_name == HgLowState::DDS_TYPE_NAME {
        let reader = participant.reader::<HgLowState>(LOWSTATE, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    } else if type_name == LowState::DDS_TYPE_NAME {
        let reader = participant.reader::<LowState>(LOWSTATE, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    } else {
        let reader = participant.raw_reader(LOWSTATE, type_name, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    };
    Ok(LowStateCount { stats, since: Instant::now(), _listener: listener })
}

/// What DDS shows on `domain` over `interface` within `timeout`; when nobody is heard there,
/// also who is heard on the other domains of 0–9 within another `timeout`.
pub(crate) fn listen(domain: u16, interface: &str, timeout: Duration) -> Result<DdsObservation, DdsError> {
    const POLL: Duration = Duration::from_millis(50);
    let participant = Participant::new(ParticipantOptions::new(domain, Some(interface)))?;
    let start = Instant::now();
    let mut lowstate = None;
    while start.elapsed() < timeout {
        if lowstate.is_none()
            && let Some(topic) =
                participant.discovered_topics().into_iter().find(|t| t.name == LOWSTATE && t.writers > 0)
        {
            lowstate = Some(count_lowstate(&participant, &topic.type_name)?);
        }
        std::thread::sleep(POLL.min(timeout.saturating_sub(start.elapsed())));
    }
    let seconds = start.elapsed().as_secs_f64();
    let lowstate = lowstate.map(|l| (l.stats.get(), l.since.elapsed().as_secs_f64()));
    let participants = participant.discovered_participants();
    let mut other_domains = Vec::new();
    if participants.is_empty() {
        let others: Vec<(u16, Participant)> = (0..10u16)
            .filter(|d| *d != domain)
            .filter_map(|d| Participant::new(ParticipantOptions::new(d, Some(interface))).ok().map(|p| (d, p)))
            .collect();
        std::thread::sleep(timeout);
        other_domains = others.iter().map(|(d, p)| (*d, p.discovered_participants().len())).collect();
    }
    Ok(DdsObservation {
        domain,
        seconds,
        interface: (Vec::new(), false),
        participants,
        endpoints: participant.discovered_endpoints(),
        other_domains,
        lowstate,
    })
}
