//! The policy's ONNX model on tract (pure Rust), checked once at load.
//!
//! The model takes the observation on its input `obs` (else its first input) and gives the
//! actions on its output `actions` (else its first output). Every other input is recurrent state
//! paired with an output: `h_in` with `h_out` by name, else in order among the rest. The state
//! starts at zeros ([`OnnxPolicy::reset`]) and each step's outputs are the next step's inputs.
//!
//! A step allocates: tract makes a new tensor for every node's output on every run.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use tract_onnx::prelude::*;
use tract_onnx::tract_hir::infer::Factoid;
use tract_onnx::tract_hir::internal::DimLike;

/// Why a model cannot be loaded or run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// tract could not read, type or plan the model.
    #[error("{path}: {message}")]
    Load {
        /// The model's path.
        path: PathBuf,
        /// tract's error chain, on one line.
        message: String,
    },
    /// The model's inputs or outputs disagree with the config.
    #[error("{path}: {why}")]
    Shape {
        /// The model's path.
        path: PathBuf,
        /// Which input or output, and the config's field it disagrees with.
        why: String,
    },
    /// Inference failed.
    #[error("inference: {0}")]
    Run(String),
    /// An observation of the wrong length.
    #[error("the observation has {found} values, the model takes {expected}")]
    Observation {
        /// The model's.
        expected: usize,
        /// Given.
        found: usize,
    },
}

/// An input of the model: its name, shape and values now.
#[derive(Debug)]
struct Input {
    name: String,
    /// The values fed in on the next step (zeros for recurrent state at start).
    tensor: Tensor,
    /// For recurrent state: the output that feeds it.
    fed_by: Option<usize>,
}

/// A loaded policy: observation in, actions out, recurrent state carried.
#[derive(Debug)]
pub struct OnnxPolicy {
    state: TypedSimpleState,
    inputs: Vec<Input>,
    obs_input: usize,
    action_output: usize,
    actions: Vec<f32>,
}

impl OnnxPolicy {
    /// Loads the model at `path` for an observation of `num_obs` and `num_actions` actions,
    /// checks its shapes, and runs it once on zeros.
    pub fn load(path: &Path, num_obs: usize, num_actions: usize) -> Result<Self, ModelError> {
        let load = |e: TractError| ModelError::Load { path: path.to_owned(), message: one_line(&e) };
        let shape = |why: String| ModelError::Shape { path: path.to_owned(), why };
        let mut model = onnx().model_for_path(path).map_err(load)?;
        let input_names: Vec<String> =
            model.input_outlets().map_err(load)?.iter().map(|o| model.node(o.node).name.clone()).collect();
        let obs_input = input_names.iter().position(|n| n == "obs").unwrap_or(0);
        if input_names.is_empty() {
            return Err(shape("the model has no input".into()));
        }
        let declared = model.input_fact(obs_input).map_err(load)?;
        if let Some(len) = declared.shape.dims().last().and_then(|d| d.concretize()).and_then(|d| d.to_usize().ok())
            && len != num_obs
        {
            return Err(shape(format!(
                "num_obs: the config says {num_obs}, input {} takes {len}",
                input_names[obs_input]
            )));
        }
        // The observation's batch of one, whatever the model declares for its batch axis.
        model.set_input_fact(obs_input, f32::fact([1, num_obs]).into()).map_err(load)?;
        let model = model.into_optimized().map_err(load)?;
        let output_names: Vec<String> = model
            .output_outlets()
            .map_err(load)?
            .iter()
            .map(|&o| model.outlet_label(o).map_or_else(|| model.node(o.node).name.clone(), str::to_owned))
            .collect();
        let concrete = |fact: &TypedFact, what: &str| -> Result<Vec<usize>, ModelError> {
            fact.shape
                .as_concrete()
                .map(<[usize]>::to_vec)
                .ok_or_else(|| shape(format!("{what} has shape {:?}, not fixed", fact.shape)))
        };
        let action_output = output_names.iter().position(|n| n == "actions" || n == "action").unwrap_or(0);
        let action_shape = match model.output_outlets().map_err(load)?.get(action_output) {
            Some(&outlet) => {
                concrete(model.outlet_fact(outlet).map_err(load)?, &format!("output {}", output_names[action_output]))?
            }
            None => return Err(shape("the model has no output".into())),
        };
        if action_shape.iter().product::<usize>() != num_actions {
            return Err(shape(format!(
                "num_actions: the config says {num_actions}, output {} has shape {action_shape:?}",
                output_names[action_output]
            )));
        }
        // The recurrent pairs: by name (`h_in` → `h_out`), else in order.
        let mut free_outputs: Vec<usize> = (0..output_names.len()).filter(|&o| o != action_output).collect();
        let mut inputs = Vec::with_capacity(input_names.len());
        for (i, name) in input_names.iter().enumerate() {
            let fact = model.input_fact(i).map_err(load)?;
            let dims = concrete(fact, &format!("input {name}"))?;
            let fed_by = if i == obs_input {
                None
            } else {
                let by_name = name.strip_suffix("_in").and_then(|stem| {
                    free_outputs.iter().position(|&o| output_names[o].strip_suffix("_out") == Some(stem))
                });
                let Some(at) = by_name.or((!free_outputs.is_empty()).then_some(0)) else {
                    return Err(shape(format!("input {name} is neither obs nor fed by an output")));
                };
                let output = free_outputs.remove(at);
                let out_dims = concrete(
                    model.outlet_fact(model.output_outlets().map_err(load)?[output]).map_err(load)?,
                    &format!("output {}", output_names[output]),
                )?;
                if out_dims.iter().product::<usize>() != dims.iter().product::<usize>() {
                    return Err(shape(format!(
                        "recurrent input {name} {dims:?} and output {} {out_dims:?} differ in size",
                        output_names[output]
                    )));
                }
                Some(output)
            };
            if fact.datum_type != f32::datum_type() {
                return Err(shape(format!("input {name} is {:?}, not f32", fact.datum_type)));
            }
            inputs.push(Input { name: name.clone(), tensor: Tensor::zero::<f32>(&dims).map_err(load)?, fed_by });
        }
        let plan: Arc<TypedSimplePlan> = model.into_runnable().map_err(load)?;
        let state = TypedSimpleState::new(&plan).map_err(load)?;
        let mut policy = Self { state, inputs, obs_input, action_output, actions: vec![0.0; num_actions] };
        // A test inference: it runs, and gives finite actions for a zero observation.
        let zeros = vec![0.0; num_obs];
        let actions = policy.step(&zeros).map_err(|e| shape(format!("the test inference failed: {e}")))?;
        if actions.iter().any(|a| !a.is_finite()) {
            return Err(shape("the test inference gave actions that are not finite".into()));
        }
        policy.reset();
        Ok(policy)
    }

    /// The observation's length.
    pub fn num_obs(&self) -> usize {
        self.inputs[self.obs_input].tensor.len()
    }

    /// The names of the recurrent inputs, in the model's order.
    pub fn recurrent_inputs(&self) -> impl Iterator<Item = &str> {
        self.inputs.iter().filter(|i| i.fed_by.is_some()).map(|i| i.name.as_str())
    }

    /// Zeroes the recurrent state, as at start.
    pub fn reset(&mut self) {
        for input in self.inputs.iter_mut().filter(|i| i.fed_by.is_some()) {
            if let Ok(mut values) = input.tensor.try_as_plain_ram_mut() {
                values.as_slice_mut::<f32>().map(|v| v.fill(0.0)).ok();
            }
        }
        self.actions.fill(0.0);
    }

    /// The actions for `obs`; the recurrent state moves on.
    pub fn step(&mut self, obs: &[f32]) -> Result<&[f32], ModelError> {
        let run = |e: TractError| ModelError::Run(one_line(&e));
        let expected = self.num_obs();
        if obs.len() != expected {
            return Err(ModelError::Observation { expected, found: obs.len() });
        }
        write(&mut self.inputs[self.obs_input].tensor, obs).map_err(run)?;
        let values: TVec<TValue> = self.inputs.iter().map(|i| i.tensor.clone().into_tvalue()).collect();
        let outputs = self.state.run(values).map_err(run)?;
        let actions = read(&outputs[self.action_output]).map_err(run)?;
        self.actions.copy_from_slice(actions);
        for input in self.inputs.iter_mut() {
            if let Some(output) = input.fed_by {
                write(&mut input.tensor, read(&outputs[output]).map_err(run)?).map_err(run)?;
            }
        }
        Ok(&self.actions)
    }
}

/// A tensor's values.
fn read(tensor: &Tensor) -> TractResult<&[f32]> {
    tensor.try_as_plain_ram()?.as_slice::<f32>()
}

/// `values` into `tensor`, of the same length.
fn write(tensor: &mut Tensor, values: &[f32]) -> TractResult<()> {
    let mut view = tensor.try_as_plain_ram_mut()?;
    let slice = view.as_slice_mut::<f32>()?;
    if slice.len() != values.len() {
        return Err(TractError::msg(format!("{} values for a tensor of {}", values.len(), slice.len())));
    }
    slice.copy_from_slice(values);
    Ok(())
}

/// tract's error chain on one line.
fn one_line(e: &TractError) -> String {
    format!("{e:#}").split_whitespace().collect::<Vec<_>>().join(" ")
}
