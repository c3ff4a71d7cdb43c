//! An object a Python class owns until `close()`: shared by calls on any thread, dropped once.

use std::sync::{Mutex, MutexGuard};

use pyo3::prelude::*;

use crate::errors::{Kind, error};

/// `T` until closed.
pub(crate) struct Owned<T> {
    what: &'static str,
    inner: Mutex<Option<T>>,
}

impl<T> Owned<T> {
    /// Owns `value`; `what` names it in `ClosedError`.
    pub(crate) fn new(what: &'static str, value: T) -> Self {
        Self { what, inner: Mutex::new(Some(value)) }
    }

    fn lock(&self) -> MutexGuard<'_, Option<T>> {
        robowire_rt::lock(&self.inner)
    }

    /// Runs `f` on the value, or raises `ClosedError`.
    pub(crate) fn with<R>(&self, f: impl FnOnce(&mut T) -> R) -> PyResult<R> {
        match self.lock().as_mut() {
            Some(value) => Ok(f(value)),
            None => Err(error(Kind::Closed, format!("the {} is closed", self.what))),
        }
    }

    /// Takes the value out (it is dropped by the caller, outside the lock). Idempotent.
    pub(crate) fn take(&self) -> Option<T> {
        self.lock().take()
    }

    /// Whether `close()` has not run.
    pub(crate) fn is_open(&self) -> bool {
        self.lock().is_some()
    }
}

/// `close()`, `__enter__` and `__exit__` for `$class`, whose field `$field` is an [`Owned`]:
/// closing drops the value with the GIL released, then finishes the capture in `$capture` (a
/// [`crate::record::Capture`]) if given; leaving a `with` block closes.
macro_rules! closeable {
    ($class:ty, $field:ident $(, $capture:ident)?, $doc:literal) => {
        #[pyo3::pymethods]
        impl $class {
            #[doc = $doc]
            fn close(&self, py: pyo3::Python<'_>) -> pyo3::PyResult<()> {
                let value = self.$field.take();
                py.detach(move || drop(value));
                $(self.$capture.finish(py)?;)?
                Ok(())
            }

            fn __enter__(slf: pyo3::Py<Self>) -> pyo3::Py<Self> {
                slf
            }

            #[pyo3(signature = (*_exc))]
            fn __exit__(&self, py: pyo3::Python<'_>, _exc: &pyo3::Bound<'_, pyo3::types::PyTuple>) -> pyo3::PyResult<()> {
                self.close(py)
            }
        }
    };
}

pub(crate) use closeable;
