#![doc = include_str!("../README.md")]
#![no_std]
#![forbid(unsafe_code)]

extern crate alloc;

use alloc::string::String;
use alloc::vec::Vec;

use robowire_core::cdr::{CdrError, CdrReader, CdrWriter};

#[macro_use]
mod macros;

pub mod builtin;
#[cfg(feature = "fuzzing")]
#[doc(hidden)]
pub mod decode_roundtrip;
pub mod definitions;
#[cfg(feature = "json")]
pub mod description;
pub mod diagnostic;
pub mod geometry;
pub mod nav;
pub mod rmw_dds_common;
pub mod sensor;
pub mod srv;
pub mod tf;

pub use robowire_core::cdr::CdrError as Error;
pub use srv::RequestId;

/// A value in a CDR body: how it is written and read, and the fewest bytes it takes (so that a
/// sequence's count is checked against the body before anything is allocated).
pub trait CdrValue: Sized {
    /// The fewest bytes a value takes, padding aside.
    const MIN_LEN: usize;
    /// Writes the value at the cursor.
    fn write(&self, w: &mut CdrWriter<'_>);
    /// Reads a value at the cursor; `field` names it in errors.
    fn read(r: &mut CdrReader<'_>, field: &'static str) -> Result<Self, CdrError>;
}

macro_rules! primitive {
    ($($ty:ty => $write:ident, $read:ident, $len:expr;)*) => {$(
        impl CdrValue for $ty {
            const MIN_LEN: usize = $len;
            fn write(&self, w: &mut CdrWriter<'_>) {
                w.$write(*self);
            }
            fn read(r: &mut CdrReader<'_>, field: &'static str) -> Result<Self, CdrError> {
                r.$read(field)
            }
        }
    )*};
}

primitive! {
    u8 => u8, u8, 1;
    bool => bool, bool, 1;
    i32 => i32, i32, 4;
    u32 => u32, u32, 4;
    i64 => i64, i64, 8;
    u64 => u64, u64, 8;
    f32 => f32, f32, 4;
    f64 => f64, f64, 8;
}

impl CdrValue for String {
    /// The length word and the NUL.
    const MIN_LEN: usize = 5;
    fn write(&self, w: &mut CdrWriter<'_>) {
        w.string(self);
    }
    fn read(r: &mut CdrReader<'_>, field: &'static str) -> Result<Self, CdrError> {
        r.string(field).map(String::from)
    }
}

impl<T: CdrValue> CdrValue for Vec<T> {
    const MIN_LEN: usize = 4;
    fn write(&self, w: &mut CdrWriter<'_>) {
        w.count(self.len());
        self.iter().for_each(|v| v.write(w));
    }
    fn read(r: &mut CdrReader<'_>, field: &'static str) -> Result<Self, CdrError> {
        let count = r.count(field, T::MIN_LEN)?;
        (0..count).map(|_| T::read(r, field)).collect()
    }
}

impl<T: CdrValue + Copy + Default, const N: usize> CdrValue for [T; N] {
    const MIN_LEN: usize = N * T::MIN_LEN;
    fn write(&self, w: &mut CdrWriter<'_>) {
        self.iter().for_each(|v| v.write(w));
    }
    fn read(r: &mut CdrReader<'_>, field: &'static str) -> Result<Self, CdrError> {
        let mut out = [T::default(); N];
        for v in &mut out {
            *v = T::read(r, field)?;
        }
        Ok(out)
    }
}

/// The DDS topic of the ROS topic `name` in `namespace` (`""` or `/` for the root):
/// `topic("/kmc0", "cmd_vel")` is `rt/kmc0/cmd_vel`.
pub fn topic(namespace: &str, name: &str) -> String {
    alloc::format!("rt{}/{name}", normalize(namespace))
}

/// The request topic of the service `name` in `namespace`: `rq/kmc0/stand_upRequest`.
pub fn request_topic(namespace: &str, name: &str) -> String {
    alloc::format!("rq{}/{name}Request", normalize(namespace))
}

/// The reply topic of the service `name` in `namespace`: `rr/kmc0/stand_upReply`.
pub fn reply_topic(namespace: &str, name: &str) -> String {
    alloc::format!("rr{}/{name}Reply", normalize(namespace))
}

/// `""`, `"/"` → `""`; `"ns"`, `"/ns/"` → `"/ns"`.
fn normalize(namespace: &str) -> String {
    let trimmed = namespace.trim_matches('/');
    if trimmed.is_empty() { String::new() } else { alloc::format!("/{trimmed}") }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_follow_the_ros2_mapping() {
        assert_eq!(topic("", "cmd_vel"), "rt/cmd_vel");
        assert_eq!(topic("/", "odom"), "rt/odom");
        assert_eq!(topic("/zsl1_0/", "joint_states"), "rt/zsl1_0/joint_states");
        assert_eq!(request_topic("kmc0", "stand_up"), "rq/kmc0/stand_upRequest");
        assert_eq!(reply_topic("", "stand_up"), "rr/stand_upReply");
    }
}
