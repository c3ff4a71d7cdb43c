//! `builtin_interfaces` and `std_msgs/Header`.

use alloc::string::String;

ros_struct! {
    /// `builtin_interfaces/Time`: seconds and nanoseconds since the epoch of the clock used.
    #[derive(Default, Copy, Eq, PartialOrd, Ord, Hash)]
    pub struct Time {
        /// Seconds.
        pub sec: i32,
        /// Nanoseconds, 0 ≤ nanosec < 1e9.
        pub nanosec: u32,
    }
}

impl Time {
    /// `ns` nanoseconds after the epoch, saturating at the i32 seconds range.
    pub fn from_nanos(ns: u64) -> Self {
        let sec = (ns / 1_000_000_000).min(i32::MAX as u64) as i32;
        Self { sec, nanosec: (ns % 1_000_000_000) as u32 }
    }
}

ros_struct! {
    /// `std_msgs/Header`: when and in which frame the data was measured.
    #[derive(Default)]
    pub struct Header {
        /// Measurement time (robowire: the device's receive time).
        pub stamp: Time,
        /// Coordinate frame, e.g. `base_link`.
        pub frame_id: String,
    }
}

ros_message! {
    Header => "std_msgs::msg::dds_::Header_";
}
