//! `diagnose` against the simulators in a private network namespace of each test's own (a user +
//! network namespace for a normal user, `robowire_dds::netns::with_loopback_multicast`): no root
//! needed, nothing leaves the namespace. Where the namespace cannot be made, each test skips with
//! a line.

mod dds;
