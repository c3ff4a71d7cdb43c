//! Parameter ids (RTPS 2.5 table 9.13 and the DDS-XTypes/security additions robowire meets).

/// PID_PAD.
pub const PAD: u16 = 0x0000;
/// PID_SENTINEL: the end of a list.
pub const SENTINEL: u16 = 0x0001;
