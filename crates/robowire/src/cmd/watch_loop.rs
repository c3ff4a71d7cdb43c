//! What `zsl1 watch` and `go2 watch` share: a state line ten times a second and the connection's
//! changes, until Ctrl-C.

use std::time::Duration;

use anyhow::Context;
use robowire_core::schedule::Connection;
use tokio::sync::watch;

/// Prints `line()` (when it has one) every 100 ms and every connection change, until Ctrl-C.
pub(crate) async fn watch_until_ctrl_c(
    mut events: watch::Receiver<Connection>,
    line: impl Fn() -> Option<String>,
) -> anyhow::Result<()> {
    let mut ticker = tokio::time::interval(Duration::from_millis(100));
    // One listener for the whole loop: a Ctrl-C between two iterations is not lost.
    let ctrl_c = tokio::signal::ctrl_c();
    tokio::pin!(ctrl_c);
    loop {
        tokio::select! {
            signal = &mut ctrl_c => return signal.context("waiting for Ctrl-C"),
            changed = events.changed() => {
                changed.context("client stopped")?;
                println!("connection: {:?}", *events.borrow_and_update());
            }
            _ = ticker.tick() => {
                if let Some(line) = line() {
                    println!("{line}");
                }
            }
        }
    }
}
