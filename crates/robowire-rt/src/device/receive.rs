//! The one receive-with-watchdog loop every device runs, on a thread of its own.
//!
//! A device's link (a UDP socket, a serial port, a DDS reader) is a [`Receive`]: it yields what
//! arrives and turns each item into the state it publishes. [`Receiving::spawn`] starts a named
//! thread with a single-threaded tokio runtime, opens the link there (so that its sockets belong
//! to that runtime), and runs the loop: every item feeds the [`Watchdog`] and the [`StateFeed`];
//! silence for the watchdog's timeout (or a lost link) publishes `Disconnected` and tells the
//! link; the next item reconnects. [`Receiving::close`] ends the loop and joins the thread:
//! when it returns, whatever the link held (a port, a socket) is closed.

use std::future::Future;
use std::sync::Arc;
use std::sync::mpsc as std_mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

use robowire_core::schedule::{Connection, Event, Time, Watchdog};
use tokio::sync::{broadcast, oneshot, watch};

use super::feed::{FeedStats, Stamped, StateFeed};
use crate::RtError;

/// What one receive gave.
#[derive(Debug)]
pub enum Received<T> {
    /// Something that decoded: a sign of life.
    Item(T),
    /// Bytes that did not decode (the link counts them): not a sign of life.
    Rejected,
    /// The link is gone (a port unplugged): the connection is lost now, not at the timeout.
    Lost,
    /// A transient error (a socket error): the loop backs off briefly before receiving again.
    Failed,
    /// The link ended for good: the loop ends.
    Closed,
}

/// A device's link as the receive loop sees it.
pub trait Receive: 'static {
    /// What a receive yields.
    type Item;
    /// The state the device publishes.
    type State: Clone + Send + Sync + 'static;

    /// Waits for the next item. Cancel-safe: the loop drops it when the watchdog fires.
    fn receive(&mut self) -> impl Future<Output = Received<Self::Item>>;

    /// An item that arrived at `now`: the state to publish, or `None` for a sign of life that
    /// carries none.
    fn on_item(&mut self, now: Time, item: Self::Item) -> Option<Self::State>;

    /// The watchdog expired at `now`, or the link was lost.
    fn on_disconnected(&mut self, now: Time) {
        let _ = now;
    }
}

/// After a transient receive error, wait this long before the next receive.
const FAILED_BACKOFF: Duration = Duration::from_millis(10);

/// The tokio instant of a monotonic-clock time (both are `CLOCK_MONOTONIC`).
fn tokio_instant(at: Time) -> tokio::time::Instant {
    tokio::time::Instant::now() + at.saturating_duration_since(crate::now())
}

async fn run<R: Receive>(mut link: R, feed: &StateFeed<R::State>, mut watchdog: Watchdog) {
    loop {
        let expires = watchdog.poll_timeout();
        let timeout = async {
            match expires {
                Some(at) => tokio::time::sleep_until(tokio_instant(at)).await,
                None => std::future::pending().await,
            }
        };
        tokio::select! {
            received = link.receive() => match received {
                Received::Item(item) => {
                    let now = crate::now();
                    let event = watchdog.feed(now);
                    let state = link.on_item(now, item);
                    feed.on_sign_of_life(now, event, watchdog.counters(), state);
                }
                Received::Rejected => {}
                Received::Lost => {
                    // Expire the watchdog now: the link will not speak before it is back.
                    if watchdog.poll_event(Time::from_nanos(u64::MAX)) == Some(Event::Disconnected) {
                        link.on_disconnected(crate::now());
                        feed.on_disconnected(watchdog.counters());
                    }
                }
                Received::Failed => tokio::time::sleep(FAILED_BACKOFF).await,
                Received::Closed => return,
            },
            () = timeout => {
                let now = crate::now();
                if watchdog.poll_event(now) == Some(Event::Disconnected) {
                    link.on_disconnected(now);
                    feed.on_disconnected(watchdog.counters());
                }
            }
        }
    }
}

/// The receive side of a device: its thread, its loop, its [`StateFeed`]. Dropping it stops the
/// loop and joins the thread, like [`close`](Self::close).
#[derive(Debug)]
pub struct Receiving<S> {
    feed: Arc<StateFeed<S>>,
    runtime: tokio::runtime::Handle,
    stop: Option<oneshot::Sender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl<S: Clone + Send + Sync + 'static> Receiving<S> {
    /// Starts thread `name`; runs `open` there (on its runtime: sockets made there belong to
    /// it), which gives the link and what the caller keeps (`T`: a sender, an address); then the
    /// loop, with `watchdog`, until [`close`](Self::close). An error of `open` is returned and the
    /// thread ends.
    pub fn spawn<R, T, E, F>(
        name: &str,
        watchdog: Watchdog,
        open: impl FnOnce() -> F + Send + 'static,
    ) -> Result<(Self, T), E>
    where
        F: Future<Output = Result<(R, T), E>>,
        R: Receive<State = S>,
        T: Send + 'static,
        E: From<RtError> + Send + 'static,
    {
        let feed = Arc::new(StateFeed::new());
        let (opened_tx, opened) = std_mpsc::sync_channel::<Result<(tokio::runtime::Handle, T), E>>(1);
        let (stop, stopped) = oneshot::channel::<()>();
        let thread_error = |source: std::io::Error| RtError::Thread { name: name.into(), source };
        let thread = std::thread::Builder::new()
            .name(name.into())
            .spawn({
                let feed = feed.clone();
                let name = name.to_owned();
                move || {
                    let runtime = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
                        Ok(runtime) => runtime,
                        Err(source) => {
                            let _ = opened_tx.send(Err(RtError::Thread { name, source }.into()));
                            return;
                        }
                    };
                    let link = match runtime.block_on(open()) {
                        Ok((link, kept)) => {
                            let _ = opened_tx.send(Ok((runtime.handle().clone(), kept)));
                            link
                        }
                        Err(e) => {
                            let _ = opened_tx.send(Err(e));
                            return;
                        }
                    };
                    runtime.block_on(async move {
                        tokio::select! {
                            () = run(link, &feed, watchdog) => {}
                            _ = stopped => {}
                        }
                    });
                }
            })
            .map_err(|e| E::from(thread_error(e)))?;
        let opened = opened
            .recv()
            .unwrap_or_else(|_| Err(E::from(thread_error(std::io::Error::other("the thread died while opening")))));
        match opened {
            Ok((runtime, kept)) => Ok((Self { feed, runtime, stop: Some(stop), thread: Some(thread) }, kept)),
            Err(e) => {
                let _ = thread.join();
                Err(e)
            }
        }
    }

    /// The feed: latest state, every state, connection, counters.
    pub fn feed(&self) -> &Arc<StateFeed<S>> {
        &self.feed
    }

    /// The latest state and when it arrived (`None` before the first).
    pub fn latest(&self) -> Option<Stamped<S>> {
        self.feed.latest()
    }

    /// The latest state as it changes.
    pub fn states(&self) -> watch::Receiver<Option<Stamped<S>>> {
        self.feed.states()
    }

    /// Every state from now on, in order.
    pub fn every_state(&self) -> broadcast::Receiver<Stamped<S>> {
        self.feed.every_state()
    }

    /// The connection now.
    pub fn connection(&self) -> Connection {
        self.feed.connection()
    }

    /// Connection events.
    pub fn connection_events(&self) -> watch::Receiver<Connection> {
        self.feed.connection_events()
    }

    /// Counters and the gaps between states.
    pub fn stats(&self) -> FeedStats {
        self.feed.stats()
    }

    /// The device thread's runtime, for the device's own tasks (service calls, answers).
    pub fn runtime(&self) -> &tokio::runtime::Handle {
        &self.runtime
    }

    /// Waits up to `timeout` for a state that satisfies `accept` (the latest one counts). Any
    /// executor: the wait runs on the device's thread.
    pub async fn wait_for(
        &self,
        timeout: Duration,
        accept: impl Fn(&S) -> bool + Send + Sync + 'static,
    ) -> Option<Stamped<S>> {
        let (tx, rx) = oneshot::channel();
        self.spawn_wait(timeout, accept, move |found| drop(tx.send(found)));
        rx.await.ok().flatten()
    }

    /// [`wait_for`](Self::wait_for), blocking the calling thread (never call it on the device's
    /// own thread).
    pub fn wait_for_blocking(
        &self,
        timeout: Duration,
        accept: impl Fn(&S) -> bool + Send + Sync + 'static,
    ) -> Option<Stamped<S>> {
        let (tx, rx) = std_mpsc::sync_channel(1);
        self.spawn_wait(timeout, accept, move |found| drop(tx.send(found)));
        rx.recv().ok().flatten()
    }

    fn spawn_wait(
        &self,
        timeout: Duration,
        accept: impl Fn(&S) -> bool + Send + Sync + 'static,
        answer: impl FnOnce(Option<Stamped<S>>) + Send + 'static,
    ) {
        let mut states = self.feed.states();
        // A runtime that has shut down drops the task, and with it `answer`: the waiter gets
        // `None`.
        self.runtime.spawn(async move {
            let wait = states.wait_for(|s| s.as_ref().is_some_and(|s| accept(&s.state)));
            let found = tokio::time::timeout(timeout, wait).await.ok().and_then(|s| s.ok().and_then(|s| s.clone()));
            answer(found);
        });
    }
}

impl<S> Receiving<S> {
    /// Ends the loop and joins the thread: when this returns, the link is closed.
    pub fn close(mut self) {
        self.shut_down();
    }

    fn shut_down(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

impl<S> Drop for Receiving<S> {
    fn drop(&mut self) {
        self.shut_down();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Items from a channel: `Some(n)` a state, `None` a lost link.
    struct Scripted(tokio::sync::mpsc::UnboundedReceiver<Option<u32>>);

    impl Receive for Scripted {
        type Item = u32;
        type State = u32;
        async fn receive(&mut self) -> Received<u32> {
            match self.0.recv().await {
                Some(Some(n)) => Received::Item(n),
                Some(None) => Received::Lost,
                None => Received::Closed,
            }
        }
        fn on_item(&mut self, _: Time, n: u32) -> Option<u32> {
            (n != 0).then_some(n)
        }
    }

    fn spawn(timeout: Duration) -> (Receiving<u32>, tokio::sync::mpsc::UnboundedSender<Option<u32>>) {
        let watchdog = Watchdog::new(crate::now(), timeout);
        Receiving::spawn("test-receive", watchdog, move || async {
            let (tx, rx) = tokio::sync::mpsc::unbounded_channel();
            Ok::<_, RtError>((Scripted(rx), tx))
        })
        .expect("the thread")
    }

    #[test]
    fn items_publish_states_and_a_lost_link_disconnects_at_once() {
        let (receiving, items) = spawn(Duration::from_secs(60));
        let mut every = receiving.every_state();
        items.send(Some(1)).unwrap();
        items.send(Some(0)).unwrap(); // a sign of life without a state
        items.send(Some(2)).unwrap();
        let got = receiving.wait_for_blocking(Duration::from_secs(10), |s| *s == 2).map(|s| s.state);
        assert_eq!(got, Some(2));
        assert_eq!((every.try_recv().map(|s| s.state), every.try_recv().map(|s| s.state)), (Ok(1), Ok(2)));
        assert_eq!(receiving.connection(), Connection::Connected);
        let mut events = receiving.connection_events();
        items.send(None).unwrap();
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        rt.block_on(async {
            tokio::time::timeout(Duration::from_secs(10), events.wait_for(|c| *c == Connection::Disconnected))
                .await
                .expect("disconnected within the bound")
                .unwrap();
        });
        assert_eq!(receiving.stats().disconnects, 1);
        items.send(Some(3)).unwrap();
        assert!(receiving.wait_for_blocking(Duration::from_secs(10), |s| *s == 3).is_some());
        assert_eq!((receiving.connection(), receiving.stats().reconnects), (Connection::Connected, 1));
        receiving.close();
        assert!(items.send(Some(4)).is_err(), "the link was dropped with the thread");
    }

    #[test]
    fn silence_expires_the_watchdog() {
        let (receiving, _items) = spawn(Duration::from_millis(20));
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        let mut events = receiving.connection_events();
        rt.block_on(async {
            tokio::time::timeout(Duration::from_secs(10), events.wait_for(|c| *c == Connection::Disconnected))
                .await
                .expect("disconnected within the bound")
                .unwrap();
        });
        assert!(receiving.wait_for_blocking(Duration::from_millis(1), |_| true).is_none(), "no state ever");
    }

    #[test]
    fn a_failed_open_is_returned_and_the_thread_ends() {
        let watchdog = Watchdog::new(crate::now(), Duration::from_secs(1));
        let opened = Receiving::<u32>::spawn("test-fail", watchdog, || async {
            Err::<(Scripted, ()), _>(RtError::LockMemory(std::io::Error::other("no")))
        });
        assert!(matches!(opened, Err(RtError::LockMemory(_))));
    }
}
