//! The one device shape (design §18): every facade opens from options, publishes the latest
//! state with the time it arrived ([`Stamped`] in a [`StateFeed`]), connection events and
//! lock-free statistics, closes with [`Device::close`], and does a defined safe thing when
//! dropped. The receive side is one loop for every link ([`Receiving`], [`Receive`]); the stream
//! side is the [`runner`](crate::runner), placed by one [`Placement`](crate::Placement).

mod feed;
mod receive;

pub use feed::{EVERY_STATE_CAPACITY, FeedStats, Stamped, StateFeed};
pub use receive::{Receive, Received, Receiving};
pub use robowire_core::schedule::Connection;
use tokio::sync::{broadcast, watch};

/// What every device facade offers, whatever its link. The latched commands are each device's
/// own (they say what the robot can do); the way it is opened, observed and closed is this.
pub trait Device {
    /// The state it publishes.
    type State: Clone + Send + Sync + 'static;
    /// Its statistics (copied out of atomics: reading them never blocks the device).
    type Stats;
    /// What closing can fail with.
    type Error: std::error::Error + Send + Sync + 'static;

    /// The receive side: latest state, every state, connection, waits.
    fn receiving(&self) -> &Receiving<Self::State>;

    /// Counters and timing.
    fn stats(&self) -> Self::Stats;

    /// Does the device's safe thing (a stop burst, a stop, damping), ends its threads and closes
    /// its link: when this returns, its port or socket can be opened again. Dropping the device
    /// does the same, without the error.
    fn close(self) -> Result<(), Self::Error>
    where
        Self: Sized;

    /// The latest state and when it arrived (`None` before the first).
    fn latest(&self) -> Option<Stamped<Self::State>> {
        self.receiving().latest()
    }

    /// The latest state as it changes (a `watch`: a slow reader sees the newest).
    fn states(&self) -> watch::Receiver<Option<Stamped<Self::State>>> {
        self.receiving().states()
    }

    /// Every state in order, stamped with its arrival, for a reader that must see each one: the
    /// first caller gets every state since the device opened, later callers from now on.
    fn every_state(&self) -> broadcast::Receiver<Stamped<Self::State>> {
        self.receiving().every_state()
    }

    /// The connection as the watchdog sees it.
    fn connection(&self) -> Connection {
        self.receiving().connection()
    }

    /// Connection events: `Waiting` → `Connected` → `Disconnected` → `Connected` ….
    fn connection_events(&self) -> watch::Receiver<Connection> {
        self.receiving().connection_events()
    }
}
