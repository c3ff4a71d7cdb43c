//! `diagnostic_msgs/DiagnosticArray`.

use alloc::string::String;
use alloc::vec::Vec;

use crate::builtin::Header;

ros_struct! {
    /// `diagnostic_msgs/KeyValue`.
    #[derive(Default)]
    pub struct KeyValue {
        /// Key.
        pub key: String,
        /// Value.
        pub value: String,
    }
}

ros_struct! {
    /// `diagnostic_msgs/DiagnosticStatus`.
    #[derive(Default)]
    pub struct DiagnosticStatus {
        /// `OK` 0, `WARN` 1, `ERROR` 2, `STALE` 3.
        pub level: u8,
        /// What is diagnosed, e.g. `kmc/motor 1`.
        pub name: String,
        /// Its state in words.
        pub message: String,
        /// The hardware's id.
        pub hardware_id: String,
        /// The figures.
        pub values: Vec<KeyValue>,
    }
}

impl DiagnosticStatus {
    /// Level OK.
    pub const OK: u8 = 0;
    /// Level WARN.
    pub const WARN: u8 = 1;
    /// Level ERROR.
    pub const ERROR: u8 = 2;
    /// Level STALE.
    pub const STALE: u8 = 3;
}

ros_struct! {
    /// `diagnostic_msgs/DiagnosticArray`.
    #[derive(Default)]
    pub struct DiagnosticArray {
        /// Time.
        pub header: Header,
        /// One status per component.
        pub status: Vec<DiagnosticStatus>,
    }
}

ros_message! {
    DiagnosticArray => "diagnostic_msgs::msg::dds_::DiagnosticArray_";
}
