//! Where a robot is on DDS: the arguments of `go2`, `g1`, `dds`, `record`, `replay` and the
//! Unitree simulators.

use clap::Args;

/// Where the robot is on DDS, shared by `go2`, `g1`, `dds` and the Unitree simulators.
#[derive(Debug, Clone, Args)]
pub(crate) struct DdsArgs {
    /// The network interface by name (the robot's network is 192.168.123.x: e.g. eth0, enp3s0).
    #[arg(long)]
    pub(crate) interface: Option<String>,
    /// DDS domain.
    #[arg(long, default_value_t = 0)]
    pub(crate) domain: u16,
}

impl DdsArgs {
    pub(crate) fn participant(&self) -> unitree::ParticipantOptions {
        unitree::ParticipantOptions::new(self.domain, self.interface.as_deref())
    }
}
