//! What every device kind implements for [`AnyDevice`](crate::AnyDevice): one trait, one
//! implementation per kind (`kinds/kmc.rs`, `zsl1.rs`, `spline.rs`, `unitree.rs`, `g1.rs`).

use std::any::Any;
use std::future::Future;
use std::pin::Pin;
use std::time::Duration;

use robowire_rt::device::{Connection, Stamped};
use serde_json::Value;
use tokio::sync::{broadcast, watch};

use crate::{DeviceError, Observation};

/// How a device's state reads, for people and for JSON: implemented by every facade
/// (`kmc::Driver`, `zsl::udp::HighLevel`, `unitree::LowLevel<Go2>`, `unitree::LowLevel<Hg>`, `unitree::g1::G1`), so that a
/// command working on a facade prints what `robowire status` prints.
pub trait Describe {
    /// The latest state as JSON (the fields of the device's own status command).
    fn status_json(&self) -> Option<Value>;
    /// The latest state as a few lines of text.
    fn status_text(&self) -> Option<String>;
    /// The latest state as one line (for a live view), with its age.
    fn status_line(&self) -> Option<String>;
    /// The client's counters as one line.
    fn stats_line(&self) -> String;
}

/// What every facade has through its `Device` implementation.
pub(crate) trait Shape {
    /// Connection events.
    fn connection_events(&self) -> watch::Receiver<Connection>;
    /// Wakes at every new state.
    fn changes(&self) -> StateChanges;
    /// How long ago the latest state arrived (`None` before the first).
    fn age(&self) -> Option<Duration>;
}

impl<D: robowire_rt::device::Device> Shape for D {
    fn connection_events(&self) -> watch::Receiver<Connection> {
        robowire_rt::device::Device::connection_events(self)
    }

    fn changes(&self) -> StateChanges {
        StateChanges(Box::new(self.states()))
    }

    fn age(&self) -> Option<Duration> {
        self.latest().map(|s| s.age())
    }
}

/// A device's facade, whatever its kind: what [`AnyDevice`](crate::AnyDevice) calls.
pub(crate) trait Facade: Describe + Shape + Send + Sync + 'static {
    /// Every state from now on, device-neutral.
    fn observations(&self) -> Observations;
    /// The latest state, device-neutral.
    fn observe(&self) -> Option<Observation>;
    /// Drives a mobile base: forward m/s, left m/s, yaw rate rad/s.
    fn drive(&self, _vx_mps: f32, _vy_mps: f32, _yaw_rate_radps: f32) -> Result<(), DeviceError> {
        Err(DeviceError::Unsupported { what: "driving with a velocity" })
    }
    /// Whether [`drive`](Self::drive) is supported.
    fn can_drive(&self) -> bool {
        false
    }
    /// Stops a commanded motion (a bridge's deadman): zero velocity; nothing where nothing was
    /// commanded by velocity.
    fn stop_motion(&self) -> Result<(), DeviceError> {
        Ok(())
    }
    /// A command that is not refreshed goes stale after `timeout` (where the device has such a
    /// timeout; elsewhere the device's own watchdog stays).
    fn set_drive_timeout(&self, _timeout: Duration) -> Result<(), DeviceError> {
        Ok(())
    }
    /// The device's named actions (`stand_up`, …).
    fn services(&self) -> &'static [&'static str] {
        &[]
    }
    /// Runs the named action; what the device said.
    fn call(&self, service: &str) -> Result<String, DeviceError> {
        Err(DeviceError::NoSuchService { service: service.into() })
    }
    /// The facade, for typed access.
    fn as_any(&self) -> &dyn Any;
    /// The device's safe thing, then closed.
    fn close(self: Box<Self>) -> Result<(), DeviceError>;
}

/// Something that resolves when a new state arrived: `false` once the device is gone.
pub(crate) trait Changed: Send {
    fn changed(&mut self) -> Pin<Box<dyn Future<Output = bool> + Send + '_>>;
}

impl<S: Send + Sync> Changed for watch::Receiver<Option<Stamped<S>>> {
    fn changed(&mut self) -> Pin<Box<dyn Future<Output = bool> + Send + '_>> {
        Box::pin(async move { watch::Receiver::changed(self).await.is_ok() })
    }
}

/// Wakes at every new state of a device (coalescing: a slow reader sees the newest).
pub struct StateChanges(pub(crate) Box<dyn Changed>);

impl std::fmt::Debug for StateChanges {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StateChanges").finish_non_exhaustive()
    }
}

impl StateChanges {
    /// Resolves at the next state; `false` once the device is gone.
    pub async fn changed(&mut self) -> bool {
        self.0.changed().await
    }
}

/// Every state of a device, in order, as [`Observation`]s.
pub struct Observations {
    states: Box<dyn NextObservation>,
    missed: u64,
}

impl std::fmt::Debug for Observations {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Observations").field("missed", &self.missed).finish_non_exhaustive()
    }
}

/// What [`Observations`] reads: a device's every-state channel and how its states read.
trait NextObservation: Send {
    fn next(&mut self) -> Pin<Box<dyn Future<Output = Next> + Send + '_>>;
}

/// One step of an every-state channel.
enum Next {
    State(Box<Observation>),
    Missed(u64),
    Closed,
}

struct Every<S, F> {
    states: broadcast::Receiver<Stamped<S>>,
    observe: F,
}

impl<S: Clone + Send + 'static, F: Fn(&S) -> Observation + Send> NextObservation for Every<S, F> {
    fn next(&mut self) -> Pin<Box<dyn Future<Output = Next> + Send + '_>> {
        Box::pin(async move {
            match self.states.recv().await {
                Ok(stamped) => Next::State(Box::new((self.observe)(&stamped.state))),
                Err(broadcast::error::RecvError::Lagged(n)) => Next::Missed(n),
                Err(broadcast::error::RecvError::Closed) => Next::Closed,
            }
        })
    }
}

impl Observations {
    /// Every state of `states`, read by `observe`.
    pub(crate) fn new<S: Clone + Send + 'static>(
        states: broadcast::Receiver<Stamped<S>>,
        observe: impl Fn(&S) -> Observation + Send + 'static,
    ) -> Self {
        Self { states: Box::new(Every { states, observe }), missed: 0 }
    }

    /// The next state; `None` once the device is gone. A reader that fell more than the
    /// channel's capacity behind skips to the oldest state still there (counted in
    /// [`missed`](Self::missed)).
    pub async fn next(&mut self) -> Option<Observation> {
        loop {
            match self.states.next().await {
                Next::State(observation) => return Some(*observation),
                Next::Missed(n) => self.missed += n,
                Next::Closed => return None,
            }
        }
    }

    /// States skipped because the reader fell behind.
    pub fn missed(&self) -> u64 {
        self.missed
    }
}

/// `[a, b, c]` as `+0.123 +0.456 +0.789`.
#[cfg(any(feature = "zsl1", feature = "unitree"))]
pub(crate) fn floats(values: &[f32]) -> String {
    values.iter().map(|x| format!("{x:+.3}")).collect::<Vec<_>>().join(" ")
}
