//! The exception hierarchy of `robowire.errors`, raised from Rust.
//!
//! The classes are Python (`robowire/errors.py`), so that they can subclass two builtins at
//! once (`ArgumentError` is a `ValueError` too, `BindError` an `OSError`); they are looked up
//! once per interpreter and cached.

use std::fmt::Display;

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;
use unitree::UnitreeError;

/// A class of `robowire.errors`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// `robowire.Error`: the base, also for what has no finer class.
    Error,
    /// NaN, infinity, out of range, wrong length; nothing was sent (also a `ValueError`).
    Argument,
    /// The object is closed or was never started (`initRobot` not called).
    Closed,
    /// A socket could not be bound (also an `OSError`).
    Bind,
    /// A serial port could not be opened or failed (also an `OSError`).
    Port,
    /// No state from the robot: none yet, or it went silent.
    NoState,
    /// A wait ran out (also the builtin `TimeoutError`).
    Timeout,
    /// Bytes that are not the message (also a `ValueError`).
    Decode,
    /// A DDS service answered with an error code, or not at all.
    Service,
}

impl Kind {
    const ALL: [Kind; 9] = [
        Kind::Error,
        Kind::Argument,
        Kind::Closed,
        Kind::Bind,
        Kind::Port,
        Kind::NoState,
        Kind::Timeout,
        Kind::Decode,
        Kind::Service,
    ];

    fn class_name(self) -> &'static str {
        match self {
            Kind::Error => "Error",
            Kind::Argument => "ArgumentError",
            Kind::Closed => "ClosedError",
            Kind::Bind => "BindError",
            Kind::Port => "PortError",
            Kind::NoState => "NoStateError",
            Kind::Timeout => "TimeoutError",
            Kind::Decode => "DecodeError",
            Kind::Service => "ServiceError",
        }
    }
}

static CLASSES: [PyOnceLock<Py<PyType>>; Kind::ALL.len()] = [const { PyOnceLock::new() }; Kind::ALL.len()];
static CRC_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

fn lookup<'py>(py: Python<'py>, cell: &PyOnceLock<Py<PyType>>, name: &str) -> PyResult<Bound<'py, PyType>> {
    let class = cell.get_or_try_init(py, || -> PyResult<_> {
        Ok(py.import("robowire.errors")?.getattr(name)?.cast_into::<PyType>()?.unbind())
    })?;
    Ok(class.bind(py).clone())
}

/// The exception `kind` with `message`.
pub(crate) fn error(kind: Kind, message: impl Display) -> PyErr {
    let message = message.to_string();
    Python::attach(|py| match lookup(py, &CLASSES[kind as usize], kind.class_name()) {
        Ok(class) => PyErr::from_type(class, message),
        Err(e) => e,
    })
}

/// `robowire.errors.CrcError`: the CRC a message carries (`found`) is not the one its bytes
/// give (`expected`).
pub(crate) fn crc_error(message: impl Display, expected: u32, found: u32) -> PyErr {
    let message = message.to_string();
    Python::attach(|py| match lookup(py, &CRC_ERROR, "CrcError") {
        Ok(class) => PyErr::from_type(class, (message, expected, found)),
        Err(e) => e,
    })
}

/// `robowire.errors.ServiceError` with the service's answer.
pub(crate) fn service_error(message: impl Display, service: &str, api_id: i64, code: i32) -> PyErr {
    let message = message.to_string();
    Python::attach(|py| match lookup(py, &CLASSES[Kind::Service as usize], Kind::Service.class_name()) {
        Ok(class) => PyErr::from_type(class, (message, service.to_string(), api_id, code)),
        Err(e) => e,
    })
}

/// An error and its sources, `: `-joined.
pub(crate) use robowire_devices::error_chain as chain;

/// A `UnitreeError` as the exception a Python user expects.
pub(crate) fn unitree_error(e: UnitreeError) -> PyErr {
    match &e {
        UnitreeError::Command(_) | UnitreeError::Option { .. } => error(Kind::Argument, chain(&e)),
        UnitreeError::Refused { service, api_id, code } => service_error(chain(&e), service, *api_id, *code),
        UnitreeError::Service { service, api_id, .. } => service_error(chain(&e), service, *api_id, -1),
        UnitreeError::NotReleased { .. } | UnitreeError::Unexpected { .. } => {
            service_error(chain(&e), "motion_switcher", 0, -1)
        }
        UnitreeError::Closed => error(Kind::Closed, chain(&e)),
        _ => error(Kind::Error, chain(&e)),
    }
}
