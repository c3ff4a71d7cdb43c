//! `diagnose` against the simulators, as a normal user: the DDS ones in a private network
//! namespace of each test's own (`robowire_dds::netns::with_private_network`; skipped with a line
//! where none can be made), the KMC chassis on a pseudo-terminal.

mod dds;
mod kmc;
