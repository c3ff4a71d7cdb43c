#![doc = include_str!("../README.md")]
#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]

pub mod api;
pub mod bms;
mod cdr;
pub mod crc;
#[cfg(feature = "fuzzing")]
#[doc(hidden)]
pub mod decode_roundtrip;
#[cfg(feature = "serde")]
pub mod description;
mod error;
pub mod field;
pub mod g1;
pub mod go2;
pub mod hg;
pub mod idl;
pub mod kinematics;
pub mod layout;
mod message;
pub mod plan;
pub mod robot;
#[cfg(feature = "serde")]
mod serde_impl;
pub mod sport_state;
pub mod stream;

pub use cdr::CdrEncoding;
pub use error::DecodeError;
pub use field::{FieldError, FieldPlace, FieldValue};
pub use go2::{BmsCmd, BmsState, ImuState, LowCmd, LowState, MotorCmd, MotorState};
pub use hg::{HgImuState, HgLowCmd, HgLowState, HgMotorCmd, HgMotorState};
pub use message::{CrcCheck, MAX_IMAGE_LEN, Message, Unverified};
pub use robowire_core::BufferTooSmall;
pub use zerocopy::little_endian::{F32, I16, I32, U16, U32};
pub use zerocopy::{FromZeros, IntoBytes};
