//! [`SplineMonitor`]: the spline daemon's state in robowire's device shape, read as a monitor.
//!
//! The motion controller runs in lockstep with the daemon ([`SplineClient`] in its own 1 kHz
//! loop: wait for fresh state, write the command). A monitor — a status line, a logger, a bridge —
//! only watches: it reads fresh state through `consumer_flags[OTHER]`, so the controller's flag is
//! never consumed, on a receive thread of its own; the latest state with its arrival time, every
//! state in order and the connection (a daemon silent for the stall bound is `Disconnected`) are
//! robowire's one device shape. It commands nothing, so closing it has nothing to stop.

use std::time::Duration;

use robowire_rt::Time;
use robowire_rt::device::{Device, FeedStats, Receive, Received, Receiving};
use robowire_rt::schedule::Watchdog;
use robowire_tap::Tap;
use zsl_proto::shm::{ConsumerIndex, SplineStateBlock};

use super::{SplineClient, SplineError};

/// How a [`SplineMonitor`] watches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SplineMonitorOptions {
    /// The daemon's object (`/spline_shm`).
    pub name: String,
    /// How often the monitor looks for fresh state. Default 1 ms (the daemon's period).
    pub poll: Duration,
    /// No fresh state for this long: `Disconnected`. Default 100 ms.
    pub stall_after: Duration,
    /// Where each fresh state read goes for a recorder (received, its 256 bytes of legs; a link
    /// described by `zsl_proto::description::SPLINE_CLIENT`). Default: nowhere.
    pub tap: Option<Tap>,
}

impl SplineMonitorOptions {
    /// The daemon's object `name`, polled every 1 ms, stalled after 100 ms.
    pub fn new(name: impl Into<String>) -> Self {
        Self { name: name.into(), poll: Duration::from_millis(1), stall_after: Duration::from_millis(100), tap: None }
    }

    /// The same, each state read handed to `tap` ([`tap`](Self::tap)).
    #[must_use]
    pub fn with_tap(mut self, tap: Tap) -> Self {
        self.tap = Some(tap);
        self
    }
}

/// The daemon's state as the receive loop reads it.
struct SplineReceiver {
    client: SplineClient,
    poll: Duration,
}

impl Receive for SplineReceiver {
    type Item = SplineStateBlock;
    type State = SplineStateBlock;

    async fn receive(&mut self) -> Received<SplineStateBlock> {
        loop {
            match self.client.try_read_state() {
                Ok(Some(state)) => return Received::Item(state),
                Ok(None) => tokio::time::sleep(self.poll).await,
                Err(_) => return Received::Failed,
            }
        }
    }

    fn on_item(&mut self, _: Time, state: SplineStateBlock) -> Option<SplineStateBlock> {
        Some(state)
    }
}

/// The spline daemon watched as a device; see the [module](self).
///
/// ```
/// use std::time::Duration;
/// use robowire_sim::spline::{SplineSim, SplineSimConfig};
/// use zsl::spline::{SplineMonitor, SplineMonitorOptions};
/// use zsl::udp::Device;
///
/// let daemon = SplineSim::spawn(SplineSimConfig::private("monitor-doc"))?;
/// let monitor = SplineMonitor::open(SplineMonitorOptions::new(&daemon.config().spline_name))?;
/// let state = monitor.wait_state(Duration::from_secs(5)).expect("the daemon publishes");
/// println!("front-right knee at {} rad", state.state.joint(zsl::Leg::FrontRight, zsl::JointIndex::Knee).p.get());
/// monitor.close();
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct SplineMonitor {
    options: SplineMonitorOptions,
    receiving: Receiving<SplineStateBlock>,
}

impl SplineMonitor {
    /// Opens the daemon's object (never creates it: "spline daemon not running" if absent) and
    /// starts watching.
    pub fn open(options: SplineMonitorOptions) -> Result<Self, SplineError> {
        let watchdog = Watchdog::new(robowire_rt::now(), options.stall_after);
        let (receiving, ()) = Receiving::spawn("spline-monitor", watchdog, {
            let (name, poll, tap) = (options.name.clone(), options.poll, options.tap.clone());
            move || async move {
                let client = SplineClient::open(&name)?.with_consumer(ConsumerIndex::Other);
                let client = match tap {
                    Some(tap) => client.with_tap(tap),
                    None => client,
                };
                Ok::<_, SplineError>((SplineReceiver { client, poll }, ()))
            }
        })?;
        Ok(Self { options, receiving })
    }

    /// Waits up to `timeout` for a fresh state (blocking the calling thread).
    pub fn wait_state(&self, timeout: Duration) -> Option<robowire_rt::device::Stamped<SplineStateBlock>> {
        self.receiving.wait_for_blocking(timeout, |_| true)
    }

    /// The options in force.
    pub fn options(&self) -> &SplineMonitorOptions {
        &self.options
    }

    /// Stops watching. It commands nothing: there is nothing to stop on the robot.
    pub fn close(self) {
        drop(self);
    }
}

impl Device for SplineMonitor {
    type State = SplineStateBlock;
    type Stats = FeedStats;
    type Error = std::convert::Infallible;

    fn receiving(&self) -> &Receiving<SplineStateBlock> {
        &self.receiving
    }

    /// Fresh states read, stalls (disconnects), returns, and the gaps between states.
    fn stats(&self) -> FeedStats {
        self.receiving.stats()
    }

    fn close(self) -> Result<(), std::convert::Infallible> {
        drop(self);
        Ok(())
    }
}
