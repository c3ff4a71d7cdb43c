//! [`LowLevelOptions`]: where the client lives on the network, its stream, its watchdog.

use std::time::Duration;

use robowire_core::json::LinkDescription;
use robowire_dds::ParticipantOptions;
use robowire_rt::Placement;
use robowire_tap::{RecordLinks, Tap};
use unitree_proto::stream::StreamConfig;

use crate::UnitreeError;

/// `rt/lowstate` silent for this long: `Disconnected` (the robot sends at 500 Hz: 50 missed
/// states).
pub const STATE_TIMEOUT: Duration = Duration::from_millis(100);

/// How long the first state may take to arrive (DDS discovery) before the watchdog reports
/// `Disconnected`.
pub const FIRST_STATE_TIMEOUT: Duration = Duration::from_secs(3);

/// How a [`LowLevel`](crate::LowLevel) client is set up.
#[derive(Debug, Clone, PartialEq)]
pub struct LowLevelOptions {
    /// DDS domain (0) and network interface by name (`eth0`, `enp3s0`; the robot's network is
    /// 192.168.123.x).
    pub participant: ParticipantOptions,
    /// The LowCmd stream: 2 ms period, 100 ms command timeout to damping, damping kd.
    pub stream: StreamConfig,
    /// Silence after which the connection is lost. Default [`STATE_TIMEOUT`].
    pub state_timeout: Duration,
    /// How long a service call (motion_switcher, sport) may take. Default 5 s (Unitree's examples).
    pub service_timeout: Duration,
    /// Where the LowCmd stream thread runs (priority, CPU, memory lock).
    pub placement: Placement,
    /// Where each `rt/lowcmd` written and `rt/lowstate` taken goes, as its payload (a link
    /// described by `unitree_proto::description::GO2_LOW_LEVEL` or `HG_LOW_LEVEL`).
    pub low_level_tap: Option<Tap>,
    /// Where each service request and answer goes (`unitree_proto::description::API_CLIENT`).
    pub services_tap: Option<Tap>,
}

impl Default for LowLevelOptions {
    /// Domain 0, the library's choice of interface, Unitree's timing.
    fn default() -> Self {
        Self {
            participant: ParticipantOptions::default(),
            stream: StreamConfig::default(),
            state_timeout: STATE_TIMEOUT,
            service_timeout: Duration::from_secs(5),
            placement: Placement::default(),
            low_level_tap: None,
            services_tap: None,
        }
    }
}

impl LowLevelOptions {
    /// Recorded with `links` when given: `rt/lowcmd` written and `rt/lowstate` taken as
    /// `{name}/low_level` (described by `low_level`: `unitree_proto::description::GO2_LOW_LEVEL` or
    /// `HG_LOW_LEVEL`), the service requests and answers as `{name}/api`.
    pub fn recorded(self, links: Option<&RecordLinks>, name: &str, low_level: &'static dyn LinkDescription) -> Self {
        let Some(links) = links else { return self };
        Self {
            low_level_tap: Some(links.link(&format!("{name}/low_level"), low_level)),
            services_tap: Some(links.link(&format!("{name}/api"), &unitree_proto::description::API_CLIENT)),
            ..self
        }
    }

    /// Domain `domain` on interface `interface` (`None`: the library chooses).
    pub fn on(interface: Option<&str>, domain: u16) -> Self {
        Self { participant: ParticipantOptions::new(domain, interface), ..Self::default() }
    }

    pub(crate) fn validate(&self) -> Result<(), UnitreeError> {
        let bad = |name: &'static str, reason: String| Err(UnitreeError::Option { name, reason });
        let s = &self.stream;
        if s.period < Duration::from_micros(100) || s.period > Duration::from_secs(1) {
            return bad("stream.period", format!("{:?} is outside 100 µs..=1 s", s.period));
        }
        if s.command_timeout < s.period {
            return bad("stream.command_timeout", format!("{:?} is shorter than the period", s.command_timeout));
        }
        if !(s.damping_kd.is_finite() && (0.0..=unitree_proto::robot::KD_MAX).contains(&s.damping_kd)) {
            return bad(
                "stream.damping_kd",
                format!("{} is outside 0..={}", s.damping_kd, unitree_proto::robot::KD_MAX),
            );
        }
        if self.state_timeout < s.period {
            return bad("state_timeout", format!("{:?} is shorter than the period", self.state_timeout));
        }
        self.placement.validate()?;
        Ok(())
    }
}
