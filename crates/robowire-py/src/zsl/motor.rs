//! `MotorCommand` and `MotorState` with the vendor's field names, and `JointArray`: one field's
//! four legs (FR, FL, RR, RL), a live view that writes through, as the vendor's numpy arrays do.

use std::sync::{Arc, Mutex, MutexGuard};

use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{PyList, PySlice};
use zsl::udp as facade;

use crate::errors::{Kind, error};

/// Rows of four legs, shared by an object and the views of its fields.
pub(crate) type Rows = Arc<Mutex<Vec<[f32; 4]>>>;

fn lock(rows: &Rows) -> MutexGuard<'_, Vec<[f32; 4]>> {
    robowire_rt::lock(rows)
}

/// Four floats from any sequence of four numbers (list, tuple, `JointArray`, numpy array).
fn four_floats(field: &str, value: &Bound<'_, PyAny>) -> PyResult<[f32; 4]> {
    let values: Vec<f64> = value.try_iter()?.map(|item| item?.extract::<f64>()).collect::<PyResult<_>>()?;
    <[f64; 4]>::try_from(values.as_slice()).map(|v| v.map(|x| x as f32)).map_err(|_| {
        error(Kind::Argument, format!("{field} takes 4 values (legs FR, FL, RR, RL), {} given", values.len()))
    })
}

/// One field of a `MotorCommand` or `MotorState`: the four legs FR, FL, RR, RL, as float32.
///
/// A live view: `cmd.q_des_knee[2] = -1.2` and `cmd.q_des_knee[:] = [...]` change the command.
/// `list(a)`, `a.tolist()` and `numpy.asarray(a)` copy it out.
#[pyclass(module = "robowire.zsl1", frozen, sequence)]
pub(crate) struct JointArray {
    rows: Rows,
    row: usize,
    field: &'static str,
}

impl JointArray {
    fn values(&self) -> [f32; 4] {
        lock(&self.rows)[self.row]
    }

    fn index(&self, index: isize) -> PyResult<usize> {
        let i = if index < 0 { index + 4 } else { index };
        usize::try_from(i).ok().filter(|i| *i < 4).ok_or_else(|| {
            pyo3::exceptions::PyIndexError::new_err(format!("{}[{index}]: index out of range (4 legs)", self.field))
        })
    }
}

#[pymethods]
impl JointArray {
    fn __len__(&self) -> usize {
        4
    }

    fn __getitem__<'py>(&self, py: Python<'py>, index: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let values = self.values();
        if let Ok(slice) = index.cast::<PySlice>() {
            let picked: Vec<f64> = slice_indices(slice)?.into_iter().map(|i| f64::from(values[i])).collect();
            return PyList::new(py, picked)?.into_bound_py_any(py);
        }
        let i = self.index(index.extract()?)?;
        f64::from(values[i]).into_bound_py_any(py)
    }

    fn __setitem__(&self, index: &Bound<'_, PyAny>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        if let Ok(slice) = index.cast::<PySlice>() {
            let indices = slice_indices(slice)?;
            let values: Vec<f64> = value.try_iter()?.map(|item| item?.extract::<f64>()).collect::<PyResult<_>>()?;
            if values.len() != indices.len() {
                return Err(error(
                    Kind::Argument,
                    format!(
                        "{}: {} values for {} legs (a joint array always has 4)",
                        self.field,
                        values.len(),
                        indices.len()
                    ),
                ));
            }
            let mut rows = lock(&self.rows);
            for (i, v) in indices.into_iter().zip(values) {
                rows[self.row][i] = v as f32;
            }
            return Ok(());
        }
        let i = self.index(index.extract()?)?;
        let v: f64 = value.extract()?;
        lock(&self.rows)[self.row][i] = v as f32;
        Ok(())
    }

    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(PyList::new(py, self.tolist())?.try_iter()?.into_any())
    }

    fn __repr__(&self) -> String {
        let [a, b, c, d] = self.values();
        format!("JointArray([{a:?}, {b:?}, {c:?}, {d:?}])")
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        let Ok(iter) = other.try_iter() else { return false };
        let Ok(theirs) = iter.map(|item| item?.extract::<f64>()).collect::<PyResult<Vec<f64>>>() else {
            return false;
        };
        theirs == self.tolist()
    }

    /// The four values as Python floats.
    fn tolist(&self) -> Vec<f64> {
        self.values().map(f64::from).to_vec()
    }

    /// numpy's conversion (`numpy.asarray(a)`): a float32 copy (numpy imported only here).
    #[pyo3(signature = (dtype = None, copy = None))]
    fn __array__<'py>(
        &self,
        py: Python<'py>,
        dtype: Option<&Bound<'py, PyAny>>,
        copy: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if copy == Some(false) {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "a JointArray cannot be viewed without a copy; use numpy.array(a) or a[:] = ... to write",
            ));
        }
        let numpy = py.import("numpy")?;
        let dtype = match dtype {
            Some(dtype) => dtype.clone(),
            None => numpy.getattr("float32")?,
        };
        numpy.call_method1("array", (self.tolist(), dtype))
    }
}

/// The leg indices a slice picks out of four.
fn slice_indices(slice: &Bound<'_, PySlice>) -> PyResult<Vec<usize>> {
    let s = slice.indices(4)?;
    let mut picked = Vec::new();
    let mut i = s.start;
    while (s.step > 0 && i < s.stop) || (s.step < 0 && i > s.stop) {
        picked.push(usize::try_from(i).map_err(|_| pyo3::exceptions::PyIndexError::new_err("slice out of range"))?);
        i += s.step;
    }
    Ok(picked)
}

/// The field accessors and the constructor of a motor struct; every field a [`JointArray`].
macro_rules! motor_struct {
    (
        $(#[$doc:meta])*
        $name:ident, $module:literal, rows = $count:literal {
            $($(#[$field_doc:meta])* $row:literal => $field:ident / $setter:ident;)*
        }
    ) => {
        $(#[$doc])*
        #[pyclass(module = $module, frozen)]
        pub(crate) struct $name {
            pub(crate) rows: Rows,
        }

        impl $name {
            /// Field names in row order.
            pub(crate) const FIELDS: [&'static str; $count] = [$(stringify!($field)),*];

            pub(crate) fn from_rows(rows: [[f32; 4]; $count]) -> Self {
                Self { rows: Arc::new(Mutex::new(rows.to_vec())) }
            }

            pub(crate) fn snapshot(&self) -> [[f32; 4]; $count] {
                let rows = lock(&self.rows);
                std::array::from_fn(|i| rows[i])
            }
        }

        #[pymethods]
        impl $name {
            /// All zeros.
            #[new]
            fn new() -> Self {
                Self::from_rows([[0.0; 4]; $count])
            }

            $(
                $(#[$field_doc])*
                #[getter]
                fn $field(&self) -> JointArray {
                    JointArray { rows: self.rows.clone(), row: $row, field: stringify!($field) }
                }

                #[setter]
                fn $setter(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
                    let values = four_floats(stringify!($field), value)?;
                    lock(&self.rows)[$row] = values;
                    Ok(())
                }
            )*

            fn __repr__(&self) -> String {
                let rows = self.snapshot();
                let fields: Vec<String> =
                    Self::FIELDS.iter().zip(rows).map(|(name, v)| format!("{name}={v:?}")).collect();
                format!("{}({})", stringify!($name), fields.join(", "))
            }

            fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
                other.cast::<Self>().is_ok_and(|other| other.get().snapshot() == self.snapshot())
            }

            /// `{field: [4 floats]}`.
            fn to_dict(&self) -> std::collections::BTreeMap<&'static str, [f64; 4]> {
                Self::FIELDS.into_iter().zip(self.snapshot().map(|r| r.map(f64::from))).collect()
            }
        }
    };
}

motor_struct! {
    /// A LowLevel motor command (the vendor's `MotorCommand`): fifteen fields of four legs (FR,
    /// FL, RR, RL), zero when made. `LowLevel.sendMotorCmd` checks it: every value finite, the
    /// positions within the vendor's bounds (abad −0.7…0.7, hip −1.15…3.0, knee −2.9…−0.65 rad).
    MotorCommand, "robowire.zsl1", rows = 15 {
        /// Abad position targets, rad (−0.7…0.7).
        0 => q_des_abad / set_q_des_abad;
        /// Hip position targets, rad (−1.15…3.0).
        1 => q_des_hip / set_q_des_hip;
        /// Knee position targets, rad (−2.9…−0.65, both ends excluded at float32).
        2 => q_des_knee / set_q_des_knee;
        /// Abad velocity targets, rad/s.
        3 => qd_des_abad / set_qd_des_abad;
        /// Hip velocity targets, rad/s.
        4 => qd_des_hip / set_qd_des_hip;
        /// Knee velocity targets, rad/s.
        5 => qd_des_knee / set_qd_des_knee;
        /// Abad position gains, N·m/rad.
        6 => kp_abad / set_kp_abad;
        /// Hip position gains, N·m/rad.
        7 => kp_hip / set_kp_hip;
        /// Knee position gains, N·m/rad.
        8 => kp_knee / set_kp_knee;
        /// Abad velocity gains, N·m·s/rad.
        9 => kd_abad / set_kd_abad;
        /// Hip velocity gains, N·m·s/rad.
        10 => kd_hip / set_kd_hip;
        /// Knee velocity gains, N·m·s/rad.
        11 => kd_knee / set_kd_knee;
        /// Abad feed-forward torques, N·m.
        12 => tau_abad_ff / set_tau_abad_ff;
        /// Hip feed-forward torques, N·m.
        13 => tau_hip_ff / set_tau_hip_ff;
        /// Knee feed-forward torques, N·m.
        14 => tau_knee_ff / set_tau_knee_ff;
    }
}

motor_struct! {
    /// The twelve motors as the robot reports them (the vendor's `MotorState`), legs FR, FL,
    /// RR, RL. `LowLevel.getMotorState()` returns a new one per call.
    MotorState, "robowire.zsl1", rows = 9 {
        /// Abad positions, rad.
        0 => q_abad / set_q_abad;
        /// Hip positions, rad.
        1 => q_hip / set_q_hip;
        /// Knee positions, rad.
        2 => q_knee / set_q_knee;
        /// Abad velocities, rad/s.
        3 => qd_abad / set_qd_abad;
        /// Hip velocities, rad/s.
        4 => qd_hip / set_qd_hip;
        /// Knee velocities, rad/s.
        5 => qd_knee / set_qd_knee;
        /// Abad torque feedback, N·m.
        6 => tau_abad_fb / set_tau_abad_fb;
        /// Hip torque feedback, N·m.
        7 => tau_hip_fb / set_tau_hip_fb;
        /// Knee torque feedback, N·m.
        8 => tau_knee_fb / set_tau_knee_fb;
    }
}

impl MotorCommand {
    /// The facade's command: rows k = 3·quantity + joint.
    pub(crate) fn to_facade(&self) -> facade::MotorCommand {
        let rows = self.snapshot();
        let quantity = |q: usize| -> [[f32; 4]; 3] { std::array::from_fn(|joint| rows[3 * q + joint]) };
        facade::MotorCommand {
            q_des_rad: quantity(0),
            qd_des_radps: quantity(1),
            kp: quantity(2),
            kd: quantity(3),
            tau_ff_nm: quantity(4),
        }
    }
}

impl From<&facade::MotorState> for MotorState {
    fn from(state: &facade::MotorState) -> Self {
        let quantities = [state.q_rad, state.qd_radps, state.tau_nm];
        Self::from_rows(std::array::from_fn(|k| quantities[k / 3][k % 3]))
    }
}
