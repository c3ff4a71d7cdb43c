//! The DDS probe: a participant on the domain and interface, listening; `rt/lowstate` counted
//! once a writer's type is known; motion_switcher's CheckMode asked when the service is there.

use std::sync::Arc;
use std::sync::atomic::{AtomicU16, Ordering};
use std::time::{Duration, Instant};

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Listener, Participant, ParticipantOptions, StatsHandle};
use unitree::services::ServiceClient;
use unitree_proto::api::{self, motion_switcher};
use unitree_proto::{HgLowState, LowState, Message};

use crate::dds::{DdsObservation, LOWSTATE, services};

/// A reader of `rt/lowstate` counting what arrives, made once a writer's type is known.
struct LowStateCount {
    stats: StatsHandle,
    since: Instant,
    /// The last HG LowState's `mode_machine`, plus 0x100 (0: none yet).
    mode_machine: Arc<AtomicU16>,
    _listener: Listener,
}

fn count_lowstate(participant: &Participant, type_name: &str) -> Result<LowStateCount, DdsError> {
    let mode_machine = Arc::new(AtomicU16::new(0));
    let (stats, listener) = if type_name == HgLowState::DDS_TYPE_NAME {
        let reader = participant.reader::<HgLowState>(LOWSTATE, Qos::READER)?;
        let seen = mode_machine.clone();
        let stats = reader.stats_handle();
        (stats, reader.listen(move |s| seen.store(0x100 | u16::from(s.value.mode_machine), Ordering::Relaxed)))
    } else if type_name == LowState::DDS_TYPE_NAME {
        let reader = participant.reader::<LowState>(LOWSTATE, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    } else {
        let reader = participant.raw_reader(LOWSTATE, type_name, Qos::READER)?;
        (reader.stats_handle(), reader.listen(|_| {}))
    };
    Ok(LowStateCount { stats, since: Instant::now(), mode_machine, _listener: listener })
}

/// The sport mode owning the motors as motion_switcher's CheckMode names it ("": none), or why
/// it did not answer within `timeout`.
fn motors_owner(participant: &Participant, timeout: Duration) -> Result<String, String> {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().map_err(|e| e.to_string())?;
    runtime.block_on(async {
        let client = ServiceClient::new(participant, motion_switcher::SERVICE).map_err(|e| e.to_string())?;
        let answer = client
            .call(motion_switcher::CHECK_MODE, "{}", timeout)
            .await
            .map_err(|e| robowire_devices::error_chain(&e))?;
        api::mode_name(&answer.data)
            .map(str::to_owned)
            .ok_or_else(|| format!("an answer without a mode: {}", answer.data))
    })
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
    let mode_machine =
        lowstate.as_ref().map(|l| l.mode_machine.load(Ordering::Relaxed)).filter(|m| *m != 0).map(|m| m as u8);
    let lowstate = lowstate.map(|l| (l.stats.get(), l.since.elapsed().as_secs_f64()));
    let participants = participant.discovered_participants();
    let endpoints = participant.discovered_endpoints();
    let motors_owner = services(&endpoints)
        .contains(&motion_switcher::SERVICE.to_owned())
        .then(|| motors_owner(&participant, timeout));
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
        endpoints,
        other_domains,
        lowstate,
        mode_machine,
        motors_owner,
    })
}
