//! The DDS probe: a participant on the domain and interface, listening; `rt/lowstate` counted
//! once a writer's type is known; the services discovered asked their API version, and
//! motion_switcher which mode owns the motors.

use std::sync::Arc;
use std::sync::atomic::{AtomicU16, Ordering};
use std::time::{Duration, Instant};

use robowire_dds::qos::Qos;
use robowire_dds::{DdsError, Listener, Participant, ParticipantOptions, StatsHandle};
use unitree::services::ServiceClient;
use unitree_proto::api::{self, g1_arm, motion_switcher, sport};
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

/// The services robowire knows how to ask their API version.
const KNOWN_SERVICES: [&str; 3] = [motion_switcher::SERVICE, sport::SERVICE, g1_arm::SERVICE];

/// Each discovered service with its API version (`None` for one robowire does not know), and the
/// sport mode owning the motors as motion_switcher's CheckMode names it ("": none; `None`
/// without a motion_switcher); each an error when it did not answer within `timeout`.
#[allow(clippy::type_complexity, reason = "the observation's own field types")]
fn ask(
    participant: &Participant,
    discovered: &[String],
    timeout: Duration,
) -> (Vec<(String, Option<Result<String, String>>)>, Option<Result<String, String>>) {
    let runtime = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(runtime) => runtime,
        Err(e) => return (discovered.iter().map(|s| (s.clone(), Some(Err(e.to_string())))).collect(), None),
    };
    runtime.block_on(async {
        let call = |service: &'static str, api_id: i64| async move {
            let client = ServiceClient::new(participant, service).map_err(|e| e.to_string())?;
            let answer = client.call(api_id, "{}", timeout).await.map_err(|e| robowire_devices::error_chain(&e))?;
            Ok::<String, String>(answer.data)
        };
        let mut services = Vec::new();
        for name in discovered {
            let known = KNOWN_SERVICES.into_iter().find(|k| k == name);
            let version = match known {
                Some(service) => Some(call(service, api::API_VERSION_ID).await),
                None => None,
            };
            services.push((name.clone(), version));
        }
        let owner = match discovered.iter().any(|s| s == motion_switcher::SERVICE) {
            true => Some(call(motion_switcher::SERVICE, motion_switcher::CHECK_MODE).await.and_then(|data| {
                api::mode_name(&data).map(str::to_owned).ok_or_else(|| format!("an answer without a mode: {data}"))
            })),
            false => None,
        };
        (services, owner)
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
    let (services, motors_owner) = ask(&participant, &services(&endpoints), timeout);
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
        interface_ipv4: Vec::new(),
        loopback: false,
        participants,
        endpoints,
        other_domains,
        lowstate,
        mode_machine,
        services,
        motors_owner,
    })
}
