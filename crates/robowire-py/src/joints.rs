//! Per-joint arguments of the Unitree clients (`robowire.go2`, `robowire.g1`): each one number
//! for every joint, or one value per joint.

use pyo3::prelude::*;
use unitree::JointCommand;

use crate::errors::{Kind, error};

/// `N` values from `value`: a number (put where `applies(i)` holds, 0 elsewhere) or a sequence
/// of `N` numbers. `order` names the `N` in the error (`ArgumentError` for a wrong length).
pub(crate) fn per_joint<const N: usize>(
    name: &str,
    value: &Bound<'_, PyAny>,
    order: &str,
    applies: &impl Fn(usize) -> bool,
) -> PyResult<[f32; N]> {
    if let Ok(v) = value.extract::<f64>() {
        return Ok(std::array::from_fn(|i| if applies(i) { v as f32 } else { 0.0 }));
    }
    let values: Vec<f64> = value.try_iter()?.map(|item| item?.extract::<f64>()).collect::<PyResult<_>>()?;
    <[f64; N]>::try_from(values.as_slice())
        .map(|v| v.map(|x| x as f32))
        .map_err(|_| error(Kind::Argument, format!("{name}: one number or {N} ({order}), {} given", values.len())))
}

/// The joint arguments of a `set_joints` call: position `q` rad, gains `kp`, `kd`, velocity
/// `dq` rad/s, torque `tau` N·m (`dq` and `tau` 0 when not given).
pub(crate) struct JointArgs<'a, 'py> {
    pub(crate) q: &'a Bound<'py, PyAny>,
    pub(crate) kp: &'a Bound<'py, PyAny>,
    pub(crate) kd: &'a Bound<'py, PyAny>,
    pub(crate) dq: Option<&'a Bound<'py, PyAny>>,
    pub(crate) tau: Option<&'a Bound<'py, PyAny>>,
}

impl JointArgs<'_, '_> {
    /// `N` joint commands; a number given for an argument goes to the joints where `applies(i)`
    /// holds (the others stay 0). The values are checked by the facade, not here.
    pub(crate) fn commands<const N: usize>(
        &self,
        order: &str,
        applies: impl Fn(usize) -> bool,
    ) -> PyResult<[JointCommand; N]> {
        let values = |name, value: &Bound<'_, PyAny>| per_joint::<N>(name, value, order, &applies);
        let (q, kp, kd) = (values("q", self.q)?, values("kp", self.kp)?, values("kd", self.kd)?);
        let dq = self.dq.map(|v| values("dq", v)).transpose()?.unwrap_or([0.0; N]);
        let tau = self.tau.map(|v| values("tau", v)).transpose()?.unwrap_or([0.0; N]);
        Ok(std::array::from_fn(|i| JointCommand { q_rad: q[i], dq_radps: dq[i], kp: kp[i], kd: kd[i], tau_nm: tau[i] }))
    }
}
