//! `robowire.Recorder` and the `record=` argument of every client and simulator: the links of a
//! device recorded into an MCAP capture (`robowire_record`), a file of the device's own (a path)
//! or one shared by several devices (a `Recorder`).

use std::path::PathBuf;
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use robowire_record::{Compression, RecordError, RecordLinks, Recorder, RecorderOptions, RecordingSummary};

use crate::errors::{Kind, chain, error};
use crate::owned::Owned;
use crate::stats::dict;

fn create_error(e: &RecordError) -> PyErr {
    error(Kind::Error, chain(e))
}

fn summary_dict<'py>(py: Python<'py>, s: &RecordingSummary) -> PyResult<Bound<'py, PyDict>> {
    Ok(dict!(py, {
        "frames" => s.frames,
        "dropped" => s.dropped,
        "oversize" => s.oversize,
        "decode_errors" => s.decode_errors,
        "json_skipped" => s.json_skipped,
    }))
}

/// An MCAP capture that any number of clients and simulators record their links into
/// (`record=recorder`): every frame both ways, raw, and beside it the decoded message as JSON.
/// Frames are copied into a ring and written by a thread of its own; a full ring drops frames and
/// counts them rather than slowing a link.
///
/// ```python
/// with robowire.Recorder("session.mcap", compression="zstd") as rec:
///     with robowire.open("sim:kmc", record=rec) as chassis:
///         chassis.wait_state(timeout_s=5.0)
/// ```
#[pyclass(name = "Recorder", module = "robowire", frozen)]
pub(crate) struct PyRecorder {
    recorder: Owned<Recorder>,
    /// What `close()` found, returned again by a second `close()`.
    summary: Mutex<Option<RecordingSummary>>,
    path: String,
}

#[pymethods]
impl PyRecorder {
    /// Creates `path` (a str or os.PathLike; replaced if it exists) and starts the writer.
    /// `compression`: `"none"`, `"zstd"` or `"lz4"` (chunks); `json=False` writes the raw frames
    /// only. An unknown compression raises `ArgumentError`, a file that cannot be created
    /// `robowire.Error`.
    #[new]
    #[pyo3(signature = (path, *, compression = "none", json = true))]
    fn new(py: Python<'_>, path: PathBuf, compression: &str, json: bool) -> PyResult<Self> {
        let compression = match compression {
            "none" => Compression::None,
            "zstd" => Compression::Zstd,
            "lz4" => Compression::Lz4,
            other => {
                return Err(error(Kind::Argument, format!("compression = {other:?}: \"none\", \"zstd\" or \"lz4\"")));
            }
        };
        let options = RecorderOptions { compression, json, ..RecorderOptions::default() };
        let recorder = py
            .detach(|| Recorder::create_with(&path, "python: robowire.Recorder", options))
            .map_err(|e| create_error(&e))?;
        Ok(Self {
            recorder: Owned::new("recorder", recorder),
            summary: Mutex::new(None),
            path: path.to_string_lossy().into_owned(),
        })
    }

    /// The capture's path.
    #[getter]
    fn path(&self) -> &str {
        &self.path
    }

    /// Whether `close()` ran.
    #[getter]
    fn closed(&self) -> bool {
        !self.recorder.is_open()
    }

    /// Writes what is still queued and closes the file; what it holds: `frames` (written),
    /// `dropped` (the ring was full), `oversize` (a frame longer than a slot), `decode_errors`
    /// (no JSON for a frame), `json_skipped` (the JSON thread fell behind). Devices still
    /// recording into it drop their frames from then on. A second call returns the same.
    fn close<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        if let Some(recorder) = self.recorder.take() {
            let summary = py.detach(move || recorder.finish()).map_err(|e| create_error(&e))?;
            *robowire_rt::lock(&self.summary) = Some(summary);
        }
        let summary = robowire_rt::lock(&self.summary).clone();
        match summary {
            Some(summary) => summary_dict(py, &summary),
            None => Err(error(Kind::Closed, format!("the capture {} could not be finished", self.path))),
        }
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_exc))]
    fn __exit__(&self, py: Python<'_>, _exc: &Bound<'_, PyTuple>) -> PyResult<()> {
        self.close(py).map(drop)
    }

    fn __repr__(&self) -> String {
        let state = if self.recorder.is_open() { "recording" } else { "closed" };
        format!("Recorder({:?}, {state})", self.path)
    }
}

/// Where a capture of an object's own is, from `record=PATH`.
enum State {
    /// Not recording into a file of its own (no `record`, or a shared `Recorder`).
    Shared,
    /// Recording into it.
    Open(Recorder),
    /// Finished when the object closed.
    Finished,
}

/// The capture a client or simulator made for `record=PATH`: finished when it closes (after the
/// device, whose last frames go into it), or when it is dropped. Declare it after the device's
/// field, so that dropping the object drops the device first.
pub(crate) struct Capture(Mutex<State>);

impl Capture {
    /// Finishes the capture, if the object has one of its own. Idempotent. Raises
    /// `robowire.Error` if the file could not be written.
    pub(crate) fn finish(&self, py: Python<'_>) -> PyResult<()> {
        let recorder = {
            let mut state = robowire_rt::lock(&self.0);
            match std::mem::replace(&mut *state, State::Finished) {
                State::Open(recorder) => Some(recorder),
                other => {
                    *state = other;
                    None
                }
            }
        };
        match recorder {
            Some(recorder) => py.detach(move || recorder.finish()).map(drop).map_err(|e| create_error(&e)),
            None => Ok(()),
        }
    }

    /// Whether the object's own capture was finished (it records nothing more).
    pub(crate) fn is_finished(&self) -> bool {
        matches!(*robowire_rt::lock(&self.0), State::Finished)
    }
}

/// The `record=` argument: `None`, a path (a capture of the object's own, made here with
/// `command` in its metadata) or a `robowire.Recorder` (shared; `ClosedError` if it is closed).
/// The links to register, and the capture to finish when the object closes.
pub(crate) fn record_arg(record: Option<&Bound<'_, PyAny>>, command: &str) -> PyResult<(Option<RecordLinks>, Capture)> {
    let Some(record) = record.filter(|r| !r.is_none()) else { return Ok((None, Capture(Mutex::new(State::Shared)))) };
    if let Ok(shared) = record.cast::<PyRecorder>() {
        let links = shared.get().recorder.with(|r| r.links())?;
        return Ok((Some(links), Capture(Mutex::new(State::Shared))));
    }
    let path: PathBuf = record.extract().map_err(|_| {
        let given = record.repr().map_or_else(|_| "?".into(), |r| r.to_string());
        error(Kind::Argument, format!("record = {given}: a path (str or os.PathLike) or a robowire.Recorder"))
    })?;
    let recorder =
        record.py().detach(|| Recorder::create(&path, &format!("python: {command}"))).map_err(|e| create_error(&e))?;
    Ok((Some(recorder.links()), Capture(Mutex::new(State::Open(recorder)))))
}

/// Adds the class to the extension module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Recorder", m.py().get_type::<PyRecorder>())?;
    Ok(())
}
