//! [`ClientOptions`]: where a client binds, whom it talks to, and its timing.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::Duration;

use zsl_proto::codec::StateDecoding;
use zsl_proto::udp::{DEFAULT_LOCAL_PORT, HIGH_LEVEL_PORT, LOW_LEVEL_PORT, Model};

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
    /// How state is decoded. Default lenient, like the vendor (see [`StateDecoding`]).
    pub state_decoding: StateDecoding,
    /// Command period. Default 2 ms (the vendor's cadence).
    pub period: Duration,
    /// Silence after which the connection is lost. Default 3 s (the vendor's).
    pub watchdog: Duration,
}

impl ClientOptions {
    /// The robot's address on its own network.
    pub const DEFAULT_DOG_IP: Ipv4Addr = Ipv4Addr::new(192, 168, 234, 1);

    fn new(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr, dog_port: u16) -> Self {
        Self {
            local: SocketAddr::new(local_ip, local_port),
            dog: SocketAddr::new(dog_ip, dog_port),
            model: Model::Zsl1,
            state_decoding: StateDecoding::Lenient,
            period: Duration::from_millis(2),
            watchdog: Duration::from_secs(3),
        }
    }

    /// HighLevel: commands to `dog_ip:43997`.
    pub fn high_level(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr) -> Self {
        Self::new(local_ip, local_port, dog_ip, HIGH_LEVEL_PORT)
    }

    /// LowLevel: commands to `dog_ip:43900`.
    pub fn low_level(local_ip: IpAddr, local_port: u16, dog_ip: IpAddr) -> Self {
        Self::new(local_ip, local_port, dog_ip, LOW_LEVEL_PORT)
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
}

impl Default for ClientOptions {
    /// HighLevel on `0.0.0.0:43988` to `192.168.234.1:43997`.
    fn default() -> Self {
        Self::high_level(Ipv4Addr::UNSPECIFIED.into(), DEFAULT_LOCAL_PORT, Self::DEFAULT_DOG_IP.into())
    }
}
