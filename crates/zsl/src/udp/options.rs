//! [`ClientOptions`]: where a client binds, whom it talks to, and its timing.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::Duration;

use robowire_rt::Placement;
use zsl_proto::codec::StateDecoding;
use zsl_proto::stream::{COMMAND_PERIOD, WATCHDOG_TIMEOUT};
use zsl_proto::udp::{DEFAULT_LOCAL_PORT, HIGH_LEVEL_PORT, LOW_LEVEL_PORT, Model};

use super::ConnectError;

/// Where a client binds and whom it talks to (the vendor's `initRobot(local_ip, local_port, dog_ip)`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClientOptions {
    /// Local address to bind; state arrives here. The robot sends to its configured target
    /// (`target_ip`/`target_port` in its `sdk_config.yaml`, port 43988 by default).
    pub local: SocketAddr,
    /// The robot's address: commands go here; state from any other IP is dropped.
    pub dog: SocketAddr,
    /// Model: ZSL-1 commands carry magic `0x5AA5`, ZSL-1W `0x5AA6`.
    pub model: Model,
    /// How state is decoded (see [`StateDecoding`]). HighLevel: lenient by default, as the
    /// vendor's HighLevel client merges short states; LowLevel: strict (a motor command must
    /// never be computed from half a state).
    pub state_decoding: StateDecoding,
    /// Command period. Default 2 ms (the vendor's cadence).
    pub period: Duration,
    /// Silence after which the connection is lost. Default 3 s (the vendor's).
    pub watchdog: Duration,
    /// Where the stream thread runs (priority, CPU, memory lock). Default: normal scheduling.
    pub placement: Placement,
    /// Hand every datagram sent and received to a recorder (`robowire-record`). Default `None`.
    pub tap: Option<robowire_tap::Tap>,
}

/// Shortest accepted command period.
pub const MIN_PERIOD: Duration = Duration::from_micros(100);

impl ClientOptions {
    /// The robot's address on its own network.
    pub const DEFAULT_DOG_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 234, 1);

    fn new(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr, dog_port: u16, state_decoding: StateDecoding) -> Self {
        Self {
            local: SocketAddr::new(local_ip, local_port),
            dog: SocketAddr::new(dog_ip, dog_port),
            model: Model::Zsl1,
            state_decoding,
            period: COMMAND_PERIOD,
            watchdog: WATCHDOG_TIMEOUT,
            placement: Placement::default(),
            tap: None,
        }
    }

    /// HighLevel: commands to `dog_ip:43997`; state decoded leniently, like the vendor.
    pub fn high_level(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr) -> Self {
        Self::new(local_ip, local_port, dog_ip, HIGH_LEVEL_PORT, StateDecoding::Lenient)
    }

    /// LowLevel: commands to `dog_ip:43900`; state decoded strictly.
    pub fn low_level(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr) -> Self {
        Self::new(local_ip, local_port, dog_ip, LOW_LEVEL_PORT, StateDecoding::Strict)
    }

    /// The same options, every datagram handed to `tap`.
    pub fn with_tap(mut self, tap: robowire_tap::Tap) -> Self {
        self.tap = Some(tap);
        self
    }

    /// Sets the model.
    pub fn with_model(mut self, model: Model) -> Self {
        self.model = model;
        self
    }

    /// Sets the state decoding.
    pub fn with_state_decoding(mut self, decoding: StateDecoding) -> Self {
        self.state_decoding = decoding;
        self
    }

    /// Sets the watchdog timeout.
    pub fn with_watchdog(mut self, watchdog: Duration) -> Self {
        self.watchdog = watchdog;
        self
    }

    /// Runs the stream thread `SCHED_FIFO` at `priority` (1..=99), pinned to `cpu` if given.
    pub fn with_realtime(mut self, priority: u8, cpu: Option<usize>) -> Self {
        self.placement = Placement::realtime(priority, cpu);
        self
    }

    pub(super) fn validate(&self) -> Result<(), ConnectError> {
        let bad = |name: &'static str, reason: String| Err(ConnectError::Option { name, reason });
        if self.period < MIN_PERIOD {
            return bad("period", format!("{:?} is shorter than {MIN_PERIOD:?}", self.period));
        }
        if self.watchdog <= self.period {
            return bad("watchdog", format!("{:?} is not longer than the period {:?}", self.watchdog, self.period));
        }
        self.placement.validate()?;
        Ok(())
    }
}

impl Default for ClientOptions {
    /// HighLevel on `0.0.0.0:43988` to `192.168.234.1:43997`.
    fn default() -> Self {
        Self::high_level(Ipv4Addr::UNSPECIFIED.into(), DEFAULT_LOCAL_PORT, Self::DEFAULT_DOG_IP.into())
    }
}
