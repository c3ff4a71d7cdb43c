//! A trained locomotion policy on a Unitree robot or its simulator.
//!
//! - [`config`]: unitree_rl_gym's deploy configs (`deploy/deploy_real/configs/*.yaml`) read with
//!   their fields unchanged, and robowire's optional additions;
//! - [`observation`]: the observation built as Unitree's deploy scripts build it, from a
//!   LowState (and a body velocity) and the command;
//! - [`model`]: the ONNX model, checked at load, recurrent state fed back.

pub mod config;
pub mod model;
pub mod observation;

pub use config::{ConfigError, ImuType, MsgType, PolicyConfig};
pub use model::{ModelError, OnnxPolicy};
pub use observation::{Observer, Sensed, Term};
