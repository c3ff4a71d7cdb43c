//! Live views into a message's struct image, driven by `lowcmd-proto`'s field tables: a
//! nested struct (`cmd.motor_cmd[3]`) or an array (`cmd.motor_cmd`, `state.imu_state.rpy`)
//! reads and writes the message's bytes, so `cmd.motor_cmd[3].q = 0.5` changes `cmd`.

use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use lowcmd_proto::layout::{Field, Scalar, Shape, StructLayout};
use pyo3::IntoPyObjectExt;
use pyo3::exceptions::{PyAttributeError, PyIndexError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice};

use crate::errors::{Kind, error};

/// A message's struct image, shared by the message and every view into it.
pub(crate) type Image = Arc<Mutex<Vec<u8>>>;

pub(crate) fn lock(image: &Image) -> MutexGuard<'_, Vec<u8>> {
    image.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The IDL field `name` of `layout`.
pub(crate) fn field(layout: &'static StructLayout, name: &str) -> Option<&'static Field> {
    layout.idl_fields().find(|f| f.name == name)
}

fn read_scalar<'py>(py: Python<'py>, scalar: Scalar, bytes: &[u8]) -> PyResult<Bound<'py, PyAny>> {
    let b = |n: usize| -> [u8; 4] {
        let mut w = [0u8; 4];
        w[..n].copy_from_slice(&bytes[..n]);
        w
    };
    match scalar {
        Scalar::U8 => bytes[0].into_bound_py_any(py),
        Scalar::U16 => u16::from_le_bytes([bytes[0], bytes[1]]).into_bound_py_any(py),
        Scalar::I16 => i16::from_le_bytes([bytes[0], bytes[1]]).into_bound_py_any(py),
        Scalar::U32 => u32::from_le_bytes(b(4)).into_bound_py_any(py),
        Scalar::I32 => i32::from_le_bytes(b(4)).into_bound_py_any(py),
        Scalar::F32 => f64::from(f32::from_le_bytes(b(4))).into_bound_py_any(py),
    }
}

/// The bytes of `value` as `scalar`: floats any (NaN and infinities too: the codec carries
/// them; a client's command check refuses them), integers within the type's range.
fn scalar_bytes(path: &str, scalar: Scalar, value: &Bound<'_, PyAny>) -> PyResult<([u8; 4], usize)> {
    let int = |min: i64, max: i64| -> PyResult<i64> {
        let v: i64 = value.extract()?;
        if (min..=max).contains(&v) {
            Ok(v)
        } else {
            Err(error(Kind::Argument, format!("{path} = {v} is outside the {} range {min}..={max}", scalar.idl_name())))
        }
    };
    let mut out = [0u8; 4];
    let n = scalar.size();
    match scalar {
        Scalar::U8 => out[0] = int(0, 0xff)? as u8,
        Scalar::U16 => out[..2].copy_from_slice(&(int(0, 0xffff)? as u16).to_le_bytes()),
        Scalar::I16 => out[..2].copy_from_slice(&(int(-0x8000, 0x7fff)? as i16).to_le_bytes()),
        Scalar::U32 => out.copy_from_slice(&(int(0, 0xffff_ffff)? as u32).to_le_bytes()),
        Scalar::I32 => out.copy_from_slice(&(int(-0x8000_0000, 0x7fff_ffff)? as i32).to_le_bytes()),
        Scalar::F32 => out.copy_from_slice(&(value.extract::<f64>()? as f32).to_le_bytes()),
    }
    Ok((out, n))
}

/// Element `i` of `field` at `base` (`base` is the array's start): a value, or a view.
fn element<'py>(
    py: Python<'py>,
    image: &Image,
    field: &'static Field,
    base: usize,
    i: usize,
    path: String,
) -> PyResult<Bound<'py, PyAny>> {
    let at = base + i * field.stride();
    match field.shape {
        Shape::Scalar(scalar) => {
            let bytes = lock(image);
            read_scalar(py, scalar, &bytes[at..at + scalar.size()])
        }
        Shape::Struct(layout) => StructView { image: image.clone(), layout, base: at, path }.into_bound_py_any(py),
        Shape::Pad => Ok(py.None().into_bound(py)),
    }
}

/// Writes `value` into element `i` of `field` at `base`.
fn set_element(
    image: &Image,
    field: &'static Field,
    base: usize,
    i: usize,
    value: &Bound<'_, PyAny>,
    path: &str,
) -> PyResult<()> {
    let at = base + i * field.stride();
    match field.shape {
        Shape::Scalar(scalar) => {
            let (bytes, n) = scalar_bytes(path, scalar, value)?;
            lock(image)[at..at + n].copy_from_slice(&bytes[..n]);
            Ok(())
        }
        Shape::Struct(layout) => assign_struct(image, layout, at, value, path),
        Shape::Pad => Ok(()),
    }
}

/// A whole struct from another view of the same struct (copied), or from a dict of some of its
/// fields (the others kept).
fn assign_struct(
    image: &Image,
    layout: &'static StructLayout,
    base: usize,
    value: &Bound<'_, PyAny>,
    path: &str,
) -> PyResult<()> {
    if let Ok(view) = value.cast::<StructView>() {
        let other = view.get();
        if !std::ptr::eq(other.layout, layout) {
            return Err(error(Kind::Argument, format!("{path} is a {}, not a {}", layout.name, other.layout.name)));
        }
        let bytes = lock(&other.image)[other.base..other.base + layout.size].to_vec();
        lock(image)[base..base + layout.size].copy_from_slice(&bytes);
        return Ok(());
    }
    let Ok(dict) = value.cast::<PyDict>() else {
        return Err(error(Kind::Argument, format!("{path}: assign a {} or a dict of its fields", layout.name)));
    };
    for (key, item) in dict.iter() {
        let name: String = key.extract()?;
        let f = field(layout, &name)
            .ok_or_else(|| error(Kind::Argument, format!("{path} ({}) has no field {name:?}", layout.name)))?;
        assign_field(image, f, base + f.offset, &item, &format!("{path}.{name}"))?;
    }
    Ok(())
}

/// Writes a whole field: a value, a struct, or an array from a sequence of its exact length.
pub(crate) fn assign_field(
    image: &Image,
    f: &'static Field,
    at: usize,
    value: &Bound<'_, PyAny>,
    path: &str,
) -> PyResult<()> {
    let Some(count) = f.count else { return set_element(image, f, at, 0, value, path) };
    let items: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
    if items.len() != count {
        return Err(error(Kind::Argument, format!("{path} has {count} elements, {} given", items.len())));
    }
    for (i, item) in items.iter().enumerate() {
        set_element(image, f, at, i, item, &format!("{path}[{i}]"))?;
    }
    Ok(())
}

/// Reads a whole field: a value, or a view of a struct or an array.
pub(crate) fn read_field<'py>(
    py: Python<'py>,
    image: &Image,
    f: &'static Field,
    at: usize,
    path: String,
) -> PyResult<Bound<'py, PyAny>> {
    match f.count {
        None => element(py, image, f, at, 0, path),
        Some(_) => ArrayView { image: image.clone(), field: f, base: at, path }.into_bound_py_any(py),
    }
}

/// A nested struct of a message (`MotorCmd_`, `IMUState_`, …): its IDL fields as attributes.
#[pyclass(module = "robowire.unitree", frozen)]
pub(crate) struct StructView {
    pub(crate) image: Image,
    pub(crate) layout: &'static StructLayout,
    pub(crate) base: usize,
    pub(crate) path: String,
}

impl StructView {
    /// The IDL field `name`, or an `AttributeError` listing the struct's fields.
    fn lookup(&self, name: &str) -> PyResult<&'static Field> {
        field(self.layout, name).ok_or_else(|| {
            PyAttributeError::new_err(format!(
                "{} has no field {name:?} (fields: {})",
                self.layout.name,
                names(self.layout)
            ))
        })
    }

    pub(crate) fn get_field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let f = self.lookup(name)?;
        read_field(py, &self.image, f, self.base + f.offset, format!("{}.{name}", self.path))
    }

    pub(crate) fn set_field(&self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let f = self.lookup(name)?;
        assign_field(&self.image, f, self.base + f.offset, value, &format!("{}.{name}", self.path))
    }

    /// The struct's fields as plain Python values (nested dicts and lists).
    pub(crate) fn to_plain<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for f in self.layout.idl_fields() {
            d.set_item(f.name, plain(py, self.get_field(py, f.name)?)?)?;
        }
        Ok(d)
    }
}

/// Views turned into dicts and lists, recursively.
fn plain<'py>(py: Python<'py>, value: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    if let Ok(view) = value.cast::<StructView>() {
        return view.get().to_plain(py).map(Bound::into_any);
    }
    if let Ok(array) = value.cast::<ArrayView>() {
        let array = array.get();
        let list = PyList::empty(py);
        for i in 0..array.len() {
            list.append(plain(py, array.item(py, i)?)?)?;
        }
        return Ok(list.into_any());
    }
    Ok(value)
}

/// `"mode, q, dq, …"`.
pub(crate) fn names(layout: &StructLayout) -> String {
    layout.idl_fields().map(|f| f.name).collect::<Vec<_>>().join(", ")
}

#[pymethods]
impl StructView {
    fn __getattr__<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.get_field(py, name)
    }

    fn __setattr__(&self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_field(name, value)
    }

    fn __dir__(&self) -> Vec<&'static str> {
        self.layout.idl_fields().map(|f| f.name).chain(["to_dict"]).collect()
    }

    /// The IDL struct's name (`MotorCmd_`, …).
    #[getter]
    fn __idl_name__(&self) -> &'static str {
        self.layout.name
    }

    /// The fields as plain values (nested dicts and lists; floats as the float32 they hold).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.to_plain(py)
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<StructView>().is_ok_and(|o| {
            let o = o.get();
            std::ptr::eq(o.layout, self.layout)
                && lock(&o.image)[o.base..o.base + o.layout.size].to_vec()
                    == lock(&self.image)[self.base..self.base + self.layout.size]
        })
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("{}({})", self.layout.name.trim_end_matches('_'), self.to_plain(py)?.repr()?))
    }
}

/// An array field of a message: indexable, sliceable, iterable; its elements are values or
/// `StructView`s. Its length is fixed.
#[pyclass(module = "robowire.unitree", frozen, sequence)]
pub(crate) struct ArrayView {
    image: Image,
    field: &'static Field,
    base: usize,
    path: String,
}

impl ArrayView {
    fn len(&self) -> usize {
        self.field.len()
    }

    fn index(&self, index: isize) -> PyResult<usize> {
        let n = self.len() as isize;
        let i = if index < 0 { index + n } else { index };
        usize::try_from(i).ok().filter(|i| *i < self.len()).ok_or_else(|| {
            PyIndexError::new_err(format!("{}[{index}]: index out of range ({} elements)", self.path, n))
        })
    }

    fn item<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyAny>> {
        element(py, &self.image, self.field, self.base, i, format!("{}[{i}]", self.path))
    }

    fn slice(&self, slice: &Bound<'_, PySlice>) -> PyResult<Vec<usize>> {
        let s = slice.indices(self.len() as isize)?;
        let mut picked = Vec::new();
        let mut i = s.start;
        while (s.step > 0 && i < s.stop) || (s.step < 0 && i > s.stop) {
            picked.push(i as usize);
            i += s.step;
        }
        Ok(picked)
    }
}

#[pymethods]
impl ArrayView {
    fn __len__(&self) -> usize {
        self.len()
    }

    fn __getitem__<'py>(&self, py: Python<'py>, index: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        if let Ok(slice) = index.cast::<PySlice>() {
            let items: Vec<Bound<'py, PyAny>> =
                self.slice(slice)?.into_iter().map(|i| self.item(py, i)).collect::<PyResult<_>>()?;
            return PyList::new(py, items)?.into_bound_py_any(py);
        }
        let i = self.index(index.extract()?)?;
        self.item(py, i)
    }

    fn __setitem__(&self, index: &Bound<'_, PyAny>, value: &Bound<'_, PyAny>) -> PyResult<()> {
        if let Ok(slice) = index.cast::<PySlice>() {
            let picked = self.slice(slice)?;
            let values: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
            if values.len() != picked.len() {
                return Err(error(
                    Kind::Argument,
                    format!(
                        "{}: {} values for {} elements (the array's length is fixed)",
                        self.path,
                        values.len(),
                        picked.len()
                    ),
                ));
            }
            for (i, v) in picked.into_iter().zip(values) {
                set_element(&self.image, self.field, self.base, i, &v, &format!("{}[{i}]", self.path))?;
            }
            return Ok(());
        }
        let i = self.index(index.extract()?)?;
        set_element(&self.image, self.field, self.base, i, value, &format!("{}[{i}]", self.path))
    }

    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let items: Vec<Bound<'py, PyAny>> = (0..self.len()).map(|i| self.item(py, i)).collect::<PyResult<_>>()?;
        Ok(PyList::new(py, items)?.try_iter()?.into_any())
    }

    /// The elements as plain values (structs as dicts).
    fn tolist<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let list = PyList::empty(py);
        for i in 0..self.len() {
            list.append(plain(py, self.item(py, i)?)?)?;
        }
        Ok(list.into_any())
    }

    fn __eq__(&self, py: Python<'_>, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        let mine = self.tolist(py)?;
        let theirs = match other.cast::<ArrayView>() {
            Ok(view) => view.get().tolist(py)?,
            Err(_) => match other.try_iter() {
                Ok(iter) => PyList::new(py, iter.collect::<PyResult<Vec<_>>>()?)?.into_any(),
                Err(_) => return Ok(false),
            },
        };
        mine.eq(theirs)
    }

    /// numpy's conversion (`numpy.asarray(a)`) of a numeric array: a copy.
    #[pyo3(signature = (dtype = None, copy = None))]
    fn __array__<'py>(
        &self,
        py: Python<'py>,
        dtype: Option<&Bound<'py, PyAny>>,
        copy: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let Shape::Scalar(scalar) = self.field.shape else {
            return Err(error(Kind::Argument, format!("{} holds structs; it has no numeric array", self.path)));
        };
        if copy == Some(false) {
            return Err(pyo3::exceptions::PyValueError::new_err("an array view cannot be converted without a copy"));
        }
        let numpy = py.import("numpy")?;
        let dtype = match dtype {
            Some(dtype) => dtype.clone(),
            None => numpy.getattr(match scalar {
                Scalar::U8 => "uint8",
                Scalar::U16 => "uint16",
                Scalar::I16 => "int16",
                Scalar::U32 => "uint32",
                Scalar::I32 => "int32",
                Scalar::F32 => "float32",
            })?,
        };
        numpy.call_method1("array", (self.tolist(py)?, dtype))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!("ArrayView({})", self.tolist(py)?.repr()?))
    }
}
