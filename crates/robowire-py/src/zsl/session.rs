//! What the drop-in `HighLevel` and `LowLevel` share: the client behind `initRobot`, replaced
//! by a second `initRobot` and dropped by `close()`; the vendor's return codes with robowire's
//! reason kept in `last_error`; "no state" as an exception instead of the vendor's zeros.

use std::net::{IpAddr, SocketAddr};
use std::sync::{Arc, Mutex, RwLock};
use std::time::Duration;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use robowire_core::json::LinkProtocol;
use zsl::udp::{
    self as facade, CallError, ClientOptions, ClientStats, ConnectError, Connection, Device, Latched, Model, ReturnCode,
};

use crate::errors::{Kind, chain, error};
use crate::record::{Capture, record_arg};
use crate::runtime;
use crate::stats::{dict, lateness};

/// A ZSL-1 UDP client of the `zsl` facade.
pub(crate) trait Facade:
    Device<Stats = ClientStats, Error = std::convert::Infallible> + Send + Sync + Sized + 'static
{
    /// The vendor's name, for messages.
    const NAME: &'static str;
    /// The link it is recorded as, and its description.
    fn link() -> (&'static str, &'static LinkProtocol);
    /// Options for `initRobot(local_ip, local_port, dog_ip)`.
    fn options(local: IpAddr, port: u16, dog: IpAddr) -> ClientOptions;
    /// Binds and starts streaming.
    fn open(options: ClientOptions) -> Result<Self, ConnectError>;
    /// Waits for the first state (any executor).
    fn wait_connected(&self, timeout: Duration) -> impl Future<Output = bool> + Send;
    /// The bound address.
    fn local_addr(&self) -> SocketAddr;
}

macro_rules! facade {
    ($t:ty, $name:literal, $options:path, $link:literal, $description:path) => {
        impl Facade for $t {
            const NAME: &'static str = $name;
            fn link() -> (&'static str, &'static LinkProtocol) {
                ($link, &$description)
            }
            fn options(local: IpAddr, port: u16, dog: IpAddr) -> ClientOptions {
                $options(local, port, dog)
            }
            fn open(options: ClientOptions) -> Result<Self, ConnectError> {
                <$t>::open(options)
            }
            fn wait_connected(&self, timeout: Duration) -> impl Future<Output = bool> + Send {
                <$t>::wait_connected(self, timeout)
            }
            fn local_addr(&self) -> SocketAddr {
                <$t>::local_addr(self)
            }
        }
    };
}

facade!(
    facade::HighLevel,
    "HighLevel",
    ClientOptions::high_level,
    "zsl1/high_level",
    zsl_proto::description::HIGH_LEVEL
);
facade!(facade::LowLevel, "LowLevel", ClientOptions::low_level, "zsl1/low_level", zsl_proto::description::LOW_LEVEL);

/// A `ConnectError` as the exception a Python user expects; `what` says who failed.
pub(crate) fn connect_error(what: &str, e: &ConnectError) -> PyErr {
    match e {
        ConnectError::Link(_) => error(Kind::Bind, format!("{what}: {}", chain(e))),
        ConnectError::Option { .. } => error(Kind::Argument, chain(e)),
        _ => error(Kind::Error, format!("{what}: {}", chain(e))),
    }
}

/// A running client and whom it talks to.
pub(crate) struct Running<T> {
    pub(crate) client: Arc<T>,
    pub(crate) dog: SocketAddr,
}

impl<T> Clone for Running<T> {
    fn clone(&self) -> Self {
        Self { client: self.client.clone(), dog: self.dog }
    }
}

/// The client behind a drop-in object.
pub(crate) struct Session<T> {
    model: Model,
    running: RwLock<Option<Running<T>>>,
    last_error: Mutex<Option<String>>,
    /// Every client `initRobot` opens records its datagrams here.
    tap: Option<robowire_tap::Tap>,
    capture: Capture,
}

fn parse_ip(name: &str, text: &str) -> PyResult<IpAddr> {
    text.parse().map_err(|_| error(Kind::Argument, format!("{name} = {text:?} is not an IP address")))
}

impl<T: Facade> Session<T> {
    /// Not connected; `record` (`None`, a path or a `robowire.Recorder`) records every
    /// client's datagrams.
    pub(crate) fn new(model: Model, record: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let (links, capture) = record_arg(record, &format!("robowire.zsl1.{}", T::NAME))?;
        let (link, description) = T::link();
        let tap = links.map(|r| r.link(link, description));
        Ok(Self { model, running: RwLock::new(None), last_error: Mutex::new(None), tap, capture })
    }

    /// `initRobot`: binds `local_ip:local_port`, streams to `dog_ip`. A second call replaces
    /// the first client (closed first, so the same port can be bound again).
    pub(crate) fn init(&self, py: Python<'_>, local_ip: &str, local_port: i64, dog_ip: &str) -> PyResult<()> {
        let local = parse_ip("local_ip", local_ip)?;
        let dog = parse_ip("dog_ip", dog_ip)?;
        let port = u16::try_from(local_port)
            .map_err(|_| error(Kind::Argument, format!("local_port = {local_port} is outside 0..=65535")))?;
        self.close_client(py);
        if self.capture.is_finished() {
            return Err(error(
                Kind::Closed,
                format!("this {}'s capture was finished by close(): record into a new object", T::NAME),
            ));
        }
        let mut options = T::options(local, port, dog).with_model(self.model);
        options.tap = self.tap.clone();
        let dog = options.dog;
        let client =
            py.detach(|| T::open(options)).map_err(|e| connect_error(&format!("{}.initRobot", T::NAME), &e))?;
        *robowire_rt::sync::write(&self.running) = Some(Running { client: Arc::new(client), dog });
        Ok(())
    }

    /// Stops streaming and frees the port (bound again at once if no other thread is inside a
    /// call on this client), then finishes the capture of `record=PATH`. Idempotent.
    pub(crate) fn close(&self, py: Python<'_>) -> PyResult<()> {
        self.close_client(py);
        self.capture.finish(py)
    }

    /// Stops streaming and frees the port.
    fn close_client(&self, py: Python<'_>) {
        let old = robowire_rt::sync::write(&self.running).take();
        if let Some(Running { client, .. }) = old {
            match Arc::try_unwrap(client) {
                Ok(client) => py.detach(move || Device::close(client)).unwrap_or_else(|never| match never {}),
                Err(shared) => py.detach(move || drop(shared)),
            }
        }
    }

    /// The running client, or `ClosedError`.
    pub(crate) fn running(&self) -> PyResult<Running<T>> {
        robowire_rt::sync::read(&self.running).clone().ok_or_else(|| {
            error(
                Kind::Closed,
                format!("this {} is not connected: call initRobot(local_ip, local_port, dog_ip) first", T::NAME),
            )
        })
    }

    /// The client, if running.
    pub(crate) fn client(&self) -> Option<Arc<T>> {
        robowire_rt::sync::read(&self.running).as_ref().map(|r| r.client.clone())
    }

    /// A getter: the value, or `NoStateError` saying why there is none.
    pub(crate) fn read<R>(&self, get: impl FnOnce(&T) -> Option<R>) -> PyResult<R> {
        let running = self.running()?;
        get(&running.client).ok_or_else(|| no_state(&*running.client, running.dog))
    }

    /// A call's outcome as the vendor's return code, its reason kept for `last_error` when it
    /// is not 0: a refusal (nothing sent), or a call sent that the robot has not acknowledged.
    pub(crate) fn code(&self, outcome: Result<Latched, CallError>) -> u32 {
        let (code, reason) = match outcome {
            Ok(latched) if latched.return_code == ReturnCode::Queued => (0, None),
            Ok(Latched { target, reported, return_code }) => (
                return_code.raw(),
                Some(format!(
                    "the command was sent, but the robot has not acknowledged mode {target:?} (it reports {reported:?})"
                )),
            ),
            Err(e) => (e.return_code().raw(), Some(e.to_string())),
        };
        self.remember(reason);
        code
    }

    /// Whether a call that returns no code went out; the reason kept for `last_error` if not.
    pub(crate) fn accepted(&self, outcome: Result<(), CallError>) -> Result<(), CallError> {
        self.remember(outcome.as_ref().err().map(ToString::to_string));
        outcome
    }

    /// Keeps (or clears) the reason of the last refused call.
    pub(crate) fn remember(&self, reason: Option<String>) {
        *robowire_rt::lock(&self.last_error) = reason;
    }

    /// Why the last call returned a non-zero code, if it did.
    pub(crate) fn last_error(&self) -> Option<String> {
        robowire_rt::lock(&self.last_error).clone()
    }

    /// `checkConnect()`: state within the watchdog's 3 s. False before `initRobot`.
    pub(crate) fn is_connected(&self) -> bool {
        self.client().is_some_and(|c| c.connection() == Connection::Connected)
    }

    /// Waits up to `timeout_s` for the first state (Ctrl-C interrupts).
    pub(crate) fn wait_connected(&self, py: Python<'_>, timeout_s: f64) -> PyResult<bool> {
        let timeout = runtime::seconds("timeout_s", timeout_s)?;
        let client = self.running()?.client;
        Ok(runtime::wait(py, Some(timeout), async move { client.wait_connected(timeout).await })?.unwrap_or(false))
    }

    /// `"waiting"`, `"connected"`, `"disconnected"`, or `"closed"`.
    pub(crate) fn connection(&self) -> &'static str {
        self.client().map_or("closed", |c| c.connection().name())
    }

    /// The bound address as `(ip, port)`.
    pub(crate) fn local_addr(&self) -> PyResult<(String, u16)> {
        let addr = self.running()?.client.local_addr();
        Ok((addr.ip().to_string(), addr.port()))
    }

    /// The client's counters as a dict.
    pub(crate) fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.running()?.client.stats();
        Ok(dict!(py, {
            "commands_sent" => s.link.sent,
            "send_errors" => s.link.send_errors,
            "states_received" => s.link.received,
            "decode_errors" => s.link.decode_errors,
            "foreign_dropped" => s.link.foreign_dropped,
            "receive_errors" => s.link.receive_errors,
            "calls_sent" => s.calls_sent,
            "refreshes_sent" => s.refreshes_sent,
            "missed_ticks" => s.missed_ticks,
            "states" => s.states,
            "short_states" => s.short_states,
            "header_anomalies" => s.header_anomalies,
            "disconnects" => s.disconnects,
            "reconnects" => s.reconnects,
            "stream_lateness_us" => lateness(py, &s.stream_lateness)?,
            "state_gap_us" => lateness(py, &s.state_gap)?,
        }))
    }
}

fn no_state<T: Facade>(client: &T, dog: SocketAddr) -> PyErr {
    let local = client.local_addr();
    let why = match client.connection() {
        Connection::Disconnected => format!("the robot at {} has been silent for 3 s or more", dog.ip()),
        _ => format!(
            "no state from the robot at {} yet (commands go to {dog}; its state must come to {local})",
            dog.ip()
        ),
    };
    error(Kind::NoState, format!("{}: {why}", T::NAME))
}

/// robowire's extras on a drop-in client class (a field `session: Session<_>`), in a
/// `#[pymethods]` block of their own: `last_error`, `connection`, `local_addr`,
/// `wait_connected`, `stats`, `close` and the context manager.
macro_rules! session_methods {
    ($class:ty) => {
        #[pyo3::pymethods]
        impl $class {
            /// robowire: why the last call returned a non-zero code (`None` after a 0).
            #[getter]
            fn last_error(&self) -> Option<String> {
                self.session.last_error()
            }

            /// robowire: `"waiting"` (no state yet), `"connected"`, `"disconnected"` (silent
            /// for 3 s; the latched motion was stopped) or `"closed"`.
            #[getter]
            fn connection(&self) -> &'static str {
                self.session.connection()
            }

            /// robowire: the bound `(ip, port)`.
            #[getter]
            fn local_addr(&self) -> pyo3::PyResult<(String, u16)> {
                self.session.local_addr()
            }

            /// robowire: waits up to `timeout_s` for state; whether it came. Ctrl-C interrupts.
            #[pyo3(signature = (timeout_s = 3.0))]
            fn wait_connected(&self, py: pyo3::Python<'_>, timeout_s: f64) -> pyo3::PyResult<bool> {
                self.session.wait_connected(py, timeout_s)
            }

            /// robowire: the link's and the stream's counters.
            fn stats<'py>(&self, py: pyo3::Python<'py>) -> pyo3::PyResult<pyo3::Bound<'py, pyo3::types::PyDict>> {
                self.session.stats(py)
            }

            /// robowire: stops streaming and frees the port (the robot stops a walk on its own
            /// command timeout), and finishes the capture of `record=PATH`. Idempotent;
            /// `initRobot` connects again (unless it recorded into a path of its own).
            fn close(&self, py: pyo3::Python<'_>) -> pyo3::PyResult<()> {
                self.session.close(py)
            }

            fn __enter__(slf: pyo3::Py<Self>) -> pyo3::Py<Self> {
                slf
            }

            #[pyo3(signature = (*_exc))]
            fn __exit__(
                &self,
                py: pyo3::Python<'_>,
                _exc: &pyo3::Bound<'_, pyo3::types::PyTuple>,
            ) -> pyo3::PyResult<()> {
                self.close(py)
            }
        }
    };
}
pub(crate) use session_methods;
