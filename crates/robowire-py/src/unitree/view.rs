//! Live views into a message's struct image: a nested struct (`cmd.motor_cmd[3]`) or an array
//! (`cmd.motor_cmd`, `state.imu_state.rpy`) reads and writes the message's bytes, so
//! `cmd.motor_cmd[3].q = 0.5` changes `cmd`. Where a field lies, its type and its range come from
//! `unitree_proto::field`; this module turns its places and values into Python objects.

use std::sync::{Arc, Mutex, MutexGuard};

use pyo3::IntoPyObjectExt;
use pyo3::exceptions::{PyAttributeError, PyIndexError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice};
use unitree_proto::field::{Element, PlaceKind};
use unitree_proto::layout::{Scalar, StructLayout};
use unitree_proto::{FieldError, FieldPlace, FieldValue, Message};

use crate::errors::{Kind, error};

/// A message's struct image, shared by the message and every view into it.
pub(crate) type Image = Arc<Mutex<Vec<u8>>>;

pub(crate) fn lock(image: &Image) -> MutexGuard<'_, Vec<u8>> {
    robowire_rt::lock(image)
}

/// A field error as an `ArgumentError` naming the field.
fn argument(path: &str, e: FieldError) -> PyErr {
    error(Kind::Argument, format!("{path}: {e}"))
}

/// A scalar as Python's `int` or `float`.
fn to_py(py: Python<'_>, value: FieldValue) -> PyResult<Bound<'_, PyAny>> {
    match value {
        FieldValue::U8(v) => v.into_bound_py_any(py),
        FieldValue::U16(v) => v.into_bound_py_any(py),
        FieldValue::I16(v) => v.into_bound_py_any(py),
        FieldValue::U32(v) => v.into_bound_py_any(py),
        FieldValue::I32(v) => v.into_bound_py_any(py),
        FieldValue::F32(v) => f64::from(v).into_bound_py_any(py),
    }
}

/// A Python number as a value of `scalar`: a float field takes any number (NaN and infinities
/// too: the codec carries them; a client's command check refuses them), an integer field an
/// `int` (a `float` raises `TypeError`) within its type's range.
fn from_py(path: &str, scalar: Scalar, value: &Bound<'_, PyAny>) -> PyResult<FieldValue> {
    match scalar {
        Scalar::F32 => FieldValue::from_f64(scalar, value.extract()?),
        _ => FieldValue::from_i64(scalar, value.extract()?),
    }
    .map_err(|e| argument(path, e))
}

/// What lies at `place`: a value, or a live view of a struct or an array.
fn read<'py>(py: Python<'py>, image: &Image, place: FieldPlace, path: String) -> PyResult<Bound<'py, PyAny>> {
    match place.kind() {
        PlaceKind::Scalar(_) => {
            let value = place.get(&lock(image)).map_err(|e| argument(&path, e))?;
            to_py(py, value)
        }
        PlaceKind::Struct(layout) => StructView { image: image.clone(), place, layout, path }.into_bound_py_any(py),
        PlaceKind::Array { element, len } => {
            ArrayView { image: image.clone(), place, element, len, path }.into_bound_py_any(py)
        }
    }
}

/// Writes `value` at `place`: a value, a struct (from a view of one or a dict of some of its
/// fields), or an array from a sequence of its exact length.
fn write(image: &Image, place: FieldPlace, value: &Bound<'_, PyAny>, path: &str) -> PyResult<()> {
    match place.kind() {
        PlaceKind::Scalar(scalar) => {
            let value = from_py(path, scalar, value)?;
            place.set(&mut lock(image), value).map_err(|e| argument(path, e))
        }
        PlaceKind::Struct(layout) => assign_struct(image, place, layout, value, path),
        PlaceKind::Array { len, .. } => {
            let items: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
            if items.len() != len {
                return Err(error(Kind::Argument, format!("{path} has {len} elements, {} given", items.len())));
            }
            for (i, item) in items.iter().enumerate() {
                let element = place.index(i).map_err(|e| argument(path, e))?;
                write(image, element, item, &format!("{path}[{i}]"))?;
            }
            Ok(())
        }
    }
}

/// A whole struct from another view of the same struct (copied), or from a dict of some of its
/// fields (the others kept).
fn assign_struct(
    image: &Image,
    place: FieldPlace,
    layout: &'static StructLayout,
    value: &Bound<'_, PyAny>,
    path: &str,
) -> PyResult<()> {
    if let Ok(view) = value.cast::<StructView>() {
        let other = view.get();
        // A copy first: the other view may share this image (and its lock).
        let source = lock(&other.image).clone();
        return place.copy_from(&mut lock(image), &other.place, &source).map_err(|e| argument(path, e));
    }
    let Ok(dict) = value.cast::<PyDict>() else {
        return Err(error(Kind::Argument, format!("{path}: assign a {} or a dict of its fields", layout.name)));
    };
    for (key, item) in dict.iter() {
        let name: String = key.extract()?;
        let field = place.field(&name).map_err(|e| match e {
            FieldError::UnknownField { .. } => {
                error(Kind::Argument, format!("{path} ({}) has no field {name:?}", layout.name))
            }
            e => argument(path, e),
        })?;
        write(image, field, &item, &format!("{path}.{name}"))?;
    }
    Ok(())
}

/// A nested struct of a message (`MotorCmd_`, `IMUState_`, …), or the message itself: its IDL
/// fields as attributes.
#[pyclass(module = "robowire.unitree", frozen)]
pub(crate) struct StructView {
    pub(crate) image: Image,
    place: FieldPlace,
    layout: &'static StructLayout,
    path: String,
}

impl StructView {
    /// The whole message `M` in `image`; `name` starts the paths in error messages.
    pub(crate) fn message<M: Message>(image: Image, name: &str) -> Self {
        Self { image, place: FieldPlace::of::<M>(), layout: M::FIELDS, path: name.into() }
    }

    /// The IDL field `name`, or an `AttributeError` listing the struct's fields.
    fn lookup(&self, name: &str) -> PyResult<FieldPlace> {
        self.place.field(name).map_err(|e| match e {
            FieldError::UnknownField { .. } => PyAttributeError::new_err(format!(
                "{} has no field {name:?} (fields: {})",
                self.layout.name,
                names(self.layout)
            )),
            e => argument(&self.path, e),
        })
    }

    pub(crate) fn get_field<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        read(py, &self.image, self.lookup(name)?, format!("{}.{name}", self.path))
    }

    pub(crate) fn set_field(&self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        write(&self.image, self.lookup(name)?, value, &format!("{}.{name}", self.path))
    }

    /// The struct's bytes (a copy: comparing two views of one image takes its lock once each).
    fn bytes(&self) -> Vec<u8> {
        self.place.bytes(&lock(&self.image)).map(<[u8]>::to_vec).unwrap_or_default()
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
fn names(layout: &StructLayout) -> String {
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
            o.place.kind() == self.place.kind() && o.bytes() == self.bytes()
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
    place: FieldPlace,
    element: Element,
    len: usize,
    path: String,
}

impl ArrayView {
    fn len(&self) -> usize {
        self.len
    }

    /// Python's index (negative counts from the end) as an element's, or an `IndexError`.
    fn index(&self, index: isize) -> PyResult<usize> {
        let n = self.len as isize;
        let i = if index < 0 { index + n } else { index };
        usize::try_from(i)
            .ok()
            .filter(|&i| self.place.index(i).is_ok())
            .ok_or_else(|| PyIndexError::new_err(format!("{}[{index}]: index out of range ({n} elements)", self.path)))
    }

    /// Where element `i` lies.
    fn element(&self, i: usize) -> PyResult<FieldPlace> {
        self.place.index(i).map_err(|e| PyIndexError::new_err(format!("{}[{i}]: {e}", self.path)))
    }

    /// Element `i`: a value, or a view.
    fn item<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyAny>> {
        read(py, &self.image, self.element(i)?, format!("{}[{i}]", self.path))
    }

    /// Writes element `i`.
    fn set_item(&self, i: usize, value: &Bound<'_, PyAny>) -> PyResult<()> {
        write(&self.image, self.element(i)?, value, &format!("{}[{i}]", self.path))
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
                self.set_item(i, &v)?;
            }
            return Ok(());
        }
        let i = self.index(index.extract()?)?;
        self.set_item(i, value)
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
        let Element::Scalar(scalar) = self.element else {
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
