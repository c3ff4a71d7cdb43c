//! The Unitree G1 humanoid from Rust, over DDS, the way Unitree's own SDKs drive it (`rt/lowcmd`,
//! `rt/lowstate`, `rt/arm_sdk`, the `motion_switcher`, `sport` and `arm` services), interoperable
//! with the robot's CycloneDDS. Built on the family's [`LowLevel<Hg>`](crate::LowLevel); the G1's rules are
//! `unitree_proto::g1`'s.
//!
//! - robowire's one device shape: [`G1::open`] (no runtime needed), [`Device::latest`] (the latest
//!   HG LowState with the time it arrived), [`Device::connection_events`], [`Device::stats`]
//!   ([`G1Stats`]), [`G1::close`].
//! - **`mode_machine`** comes from the robot: it is read from each LowState and copied into every
//!   LowCmd; before the first LowState every command is refused
//!   ([`CommandError::NoModeMachine`]), never sent with a default 0. The variant (29-dof, 23-dof,
//!   waist locked, dual arm) follows from it ([`G1::variant`]; a value not in Unitree's table, such
//!   as a simulator's 0, is treated as the 29-dof G1), or from [`G1Options::variant`].
//! - [`G1::battery`]: the latest `rt/lf/bmsstate` (HG `BmsState_`: state of charge %, cell
//!   voltages mV, current mA), read by a task on the receive thread's runtime and handed over
//!   through a seqlock ([`Battery`]); its topic's counters in [`G1Stats::bmsstate`].
//! - [`G1::release`]: Unitree's G1 sequence through motion_switcher (CheckMode; ReleaseMode while a
//!   mode is reported; bounded attempts). [`G1::select_mode`] gives the motors back to the robot's
//!   controller.
//! - [`G1::set_command`], [`G1::set_joints`], [`G1::hold`] (Unitree's example gains): checked by
//!   `unitree_proto::g1::check_low_cmd` (the robot's `mode_machine`, joint ranges, speeds and
//!   torques, disabled and undriven slots) before anything is sent; streamed at 500 Hz; damping
//!   (keeping `mode_machine`) 100 ms after the last command; [`G1::damp`] damps at once, even before
//!   any command was sent. [`G1::follow`]: a [`Motion`] stepped by the stream on its own grid,
//!   each step checked by the same rules, its final command held.
//! - **`rt/arm_sdk`** ([`G1::set_arm_joints`], [`G1::set_arm_weight`]): the arm and waist targets
//!   blended with the robot's own controller at 50 Hz, the weight (slot 29) ramped at 0.5/s, never
//!   switched; a stale arm command (no update for 500 ms) is ramped out; the stream goes idle at
//!   weight 0 and frees the topic; closing ramps the weight to 0 first (at most 2 s). See
//!   [`arm_stream`].
//! - [`Loco`] (service `sport`): FSM ids, velocity (checked: finite, |vx| ≤ 1 m/s, |vy| ≤ 0.5 m/s,
//!   |yaw| ≤ 1 rad/s), balance mode, stand and swing heights; "LocoState not available" (7301, the
//!   state after a release) is [`G1Error::LocoStateUnavailable`]. [`ArmActions`] (service `arm`):
//!   actions by id, the list, release (99); its refusals (7400, 7401, 7402, 7404) are typed.
//!
//! The network: the G1's computer talks on 192.168.123.x; give the interface of that network by
//! name (`G1Options::on(Some("eth0"), 0)`). On a real robot a LowCmd moves motors: release the
//! controller only with the robot hung or lying safely.
//!
//! ```rust,no_run
//! # async fn demo() -> Result<(), unitree::g1::G1Error> {
//! use std::time::Duration;
//! use unitree::g1::{Device, G1, G1Options, JointCommand, JOINTS, from_fn, hold};
//!
//! let robot = G1::open(G1Options::on(Some("eth0"), 0))?;
//! let first = robot.wait_state(Duration::from_secs(3), |_| true).await.expect("rt/lowstate");
//! println!("mode_machine {} ({:?})", first.mode_machine, robot.variant());
//! let mode = robot.mode().await?; // e.g. "ai": the robot's controller owns the motors
//! robot.release().await?;
//! // Every joint from where it is to 0 rad over 3 s, Unitree's example gains, stepped by the
//! // stream at 500 Hz; then held.
//! let (from, variant) = (robot.joint_positions().expect("a LowState"), robot.variant().expect("a LowState"));
//! let to_zero = from_fn(Duration::from_secs(3), move |elapsed| {
//!     let left = 1.0 - elapsed.as_secs_f32() / 3.0;
//!     hold(&from.map(|q| q * left), first.mode_machine, variant)
//! });
//! robot.follow(to_zero)?.wait().await?;
//! robot.damp()?;
//! robot.select_mode(&mode).await?; // the robot's controller again
//! robot.loco().start().await?;
//! robot.loco().set_velocity(0.2, 0.0, 0.0, 2.0).await?;
//! robot.close();
//! # let _ = (JointCommand::default(), JOINTS);
//! # Ok(()) }
//! ```

mod arm_actions;
mod arm_job;
mod battery;
mod client;
mod error;
mod loco;
mod options;

pub use crate::trajectory::{Motion, from_fn};
pub use crate::{
    Connection, Device, Following, JointCommand, LowLevelOptions, MotionState, ParticipantOptions, Placement, Stamped,
};
pub use arm_actions::ArmActions;
pub use battery::Battery;
pub use client::{ARM_JOINTS, G1, G1Stats};
pub use error::G1Error;
pub use loco::{
    BalanceMode, HEIGHT_MAX_M, Loco, VELOCITY_DURATION_MAX_S, VX_MAX_MPS, VY_MAX_MPS, Velocity, VelocityAsks,
    YAW_RATE_MAX_RADPS,
};
pub use options::G1Options;
pub use unitree_proto::bms::HgBmsState;
pub use unitree_proto::g1::arm_stream;
pub use unitree_proto::g1::{
    ARM_SDK_JOINTS, DEFAULT_GAINS, G1Variant, JOINT_LIMITS, JOINT_NAMES, JOINTS, ModePr, hold, slot,
};
pub use unitree_proto::robot::CommandError;
pub use unitree_proto::{HgLowCmd, HgLowState};
