//! The named bounds of a participant's memory. Every table the core keeps, and every size read
//! from a datagram that would size memory, is checked against one of these; what exceeds a limit
//! is dropped and counted (`Event`s and counters say which), never grown.

use core::time::Duration;

/// A participant's bounds. `Limits::default()` is sized for a robot's network: a few dozen
/// participants, Unitree's and ROS 2's topics, samples up to a few hundred kilobytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Limits {
    /// Remote participants known at once; the SPDP announcement of one more displaces the one
    /// heard from least recently.
    pub participants: usize,
    /// Remote endpoints (writers and readers) known per remote participant.
    pub endpoints_per_participant: usize,
    /// Local writers and readers of this participant.
    pub local_endpoints: usize,
    /// Locators kept per remote participant or endpoint (unicast and multicast together).
    pub locators_per_endpoint: usize,
    /// Bytes of one discovery parameter list (SPDP or SEDP data) accepted.
    pub parameter_list_bytes: usize,
    /// Bytes of one string or octet sequence inside a parameter list (topic and type names,
    /// USER_DATA, partitions, type information).
    pub parameter_bytes: usize,
    /// Samples in reassembly at once per matched writer (DATA_FRAG).
    pub reassemblies: usize,
    /// Bytes of one sample reassembled from fragments; a larger `sampleSize` is refused.
    pub reassembly_bytes: usize,
    /// Bytes in reassembly at once, all readers and writers together: a reassembly's buffer
    /// is its announced sample size, so this bounds what any number of small DATA_FRAGs can
    /// make the participant hold.
    pub reassembly_bytes_total: usize,
    /// How long an incomplete sample waits for its missing fragments.
    pub reassembly_timeout: Duration,
    /// Samples a writer's history or a reader's queue may hold (KEEP_LAST depth, KEEP_ALL bound).
    pub history_depth: usize,
    /// Bytes of one sample a writer accepts (larger ones are refused, not fragmented beyond this).
    pub sample_bytes: usize,
    /// Events (samples included) queued and not yet polled; more are dropped and counted.
    pub events: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            participants: 64,
            endpoints_per_participant: 512,
            local_endpoints: 256,
            locators_per_endpoint: 16,
            parameter_list_bytes: 64 * 1024,
            parameter_bytes: 16 * 1024,
            reassemblies: 8,
            reassembly_bytes: 1024 * 1024,
            reassembly_bytes_total: 8 * 1024 * 1024,
            reassembly_timeout: Duration::from_secs(2),
            history_depth: 1024,
            sample_bytes: 1024 * 1024,
            events: 4096,
        }
    }
}
