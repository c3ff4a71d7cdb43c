//! A trained locomotion policy on a Unitree robot or its simulator.
//!
//! - [`config`]: unitree_rl_gym's deploy configs (`deploy/deploy_real/configs/*.yaml`) read with
//!   their fields unchanged, and robowire's optional additions;
//! - [`observation`]: the observation built as Unitree's deploy scripts build it, from a
//!   LowState (and a body velocity) and the command;
//! - [`model`]: the ONNX model, checked at load, recurrent state fed back;
//! - [`control`]: `deploy_real.py`'s sequence and safety as a sans-IO machine on caller time;
//! - [`run`]: that sequence on a robot ([`body`]: the G1 and the Go2 through their facades), on
//!   robowire's runner;
//! - [`record`]: each policy step as a frame of a capture's `policy` channel;
//! - `device` (feature `devices`): the addresses a policy drives, and a run on a device opened
//!   by address (`robowire_devices`).
//!
//! ```no_run
//! use std::sync::Arc;
//! use robowire_policy::{CommandSlot, OnnxPolicy, PolicyConfig, RunOptions};
//! use unitree::g1::{G1, G1Options};
//!
//! # async fn walk() -> Result<(), Box<dyn std::error::Error>> {
//! let config = PolicyConfig::load("g1_walk.yaml".as_ref())?;
//! let policy = OnnxPolicy::load(&config.policy_path, config.num_obs, config.num_actions)?;
//! let robot = Arc::new(G1::open(G1Options::on(Some("eth0"), 0))?);
//! let command = CommandSlot::new([0.3, 0.0, 0.0]);
//! let options = RunOptions { command: command.clone(), ..RunOptions::default() };
//! // Stand 2 s, hold 1 s, then the policy every control_dt; any fault damps the robot.
//! let running = robowire_policy::start(robot, |g1| Some(g1), &config, policy, options).await?;
//! command.set([0.0, 0.0, 0.3]); // turn, from the next step on
//! println!("ended: {}", running.ended().await);
//! # Ok(()) }
//! ```

pub mod body;
pub mod config;
pub mod control;
#[cfg(feature = "devices")]
pub mod device;
pub mod model;
pub mod observation;
pub mod record;
pub mod run;
mod term;
#[cfg(feature = "test-support")]
#[doc(hidden)]
pub mod tiny;

pub use body::Body;
pub use config::{ConfigError, ImuType, MsgType, PolicyConfig};
pub use control::{Controller, Fault, MotorTarget, Phase, Tick};
pub use model::{ModelError, OnnxPolicy};
pub use observation::{Observer, Sensed, Term};
pub use run::{CommandSlot, Ended, RunOptions, Running, StartError, start};
