//! A trained locomotion policy on a Unitree robot or its simulator.
//!
//! - [`config`]: unitree_rl_gym's deploy configs (`deploy/deploy_real/configs/*.yaml`) read with
//!   their fields unchanged, and robowire's optional additions;
//! - [`observation`]: the observation built as Unitree's deploy scripts build it, from a
//!   LowState (and a body velocity) and the command;
//! - [`model`]: the ONNX model, checked at load, recurrent state fed back;
//! - [`control`]: `deploy_real.py`'s sequence and safety as a sans-IO machine on caller time;
//! - [`run`]: that sequence on a robot ([`body`]: the G1 and the Go2 through their facades), on
//!   robowire's runner.

pub mod body;
pub mod config;
pub mod control;
pub mod model;
pub mod observation;
pub mod run;
#[cfg(feature = "test-support")]
#[doc(hidden)]
pub mod tiny;

pub use body::Body;
pub use config::{ConfigError, ImuType, MsgType, PolicyConfig};
pub use control::{Controller, Fault, MotorTarget, Phase, Tick};
pub use model::{ModelError, OnnxPolicy};
pub use observation::{Observer, Sensed, Term};
pub use run::{CommandSlot, Ended, RunOptions, Running, StartError, start};
