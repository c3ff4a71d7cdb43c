//! How a simulator command runs: until Ctrl-C, its report every so often, its log lines as they
//! come, and (with `--live`) its physics body's pose for the live view.

use std::time::Duration;

use anyhow::Context;

/// Runs until Ctrl-C, reporting every `every_s` seconds (0: never).
pub(crate) fn until_ctrl_c(every_s: f64, mut report: impl FnMut()) -> anyhow::Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    runtime.block_on(async {
        let enabled = every_s.is_finite() && every_s > 0.0;
        let mut ticker = tokio::time::interval(Duration::from_secs_f64(if enabled { every_s } else { 3600.0 }));
        ticker.tick().await;
        // One listener for the whole loop: a Ctrl-C between two iterations is not lost.
        let ctrl_c = tokio::signal::ctrl_c();
        tokio::pin!(ctrl_c);
        loop {
            tokio::select! {
                signal = &mut ctrl_c => {
                    signal.context("waiting for Ctrl-C")?;
                    return Ok(());
                }
                _ = ticker.tick(), if enabled => report(),
            }
        }
    })
}

/// Runs a simulator that keeps a log until Ctrl-C: its log lines on stdout as they come (every
/// 20 ms; with `live`, also to the live view, with the body's base), the line `report()` gives
/// on stderr every `every_s` seconds (0: never), the last log lines once stopped.
pub(crate) fn until_ctrl_c_with_log(
    every_s: f64,
    take_log: impl Fn() -> Vec<String>,
    report: impl Fn() -> String,
    live: Option<LiveBody<'_>>,
) -> anyhow::Result<()> {
    let print_log = || {
        for line in take_log() {
            if let Some(live) = &live {
                live.events.log(robowire_live::Level::Info, live.device, &line);
            }
            println!("{line}");
        }
    };
    print_log();
    let mut last_report = std::time::Instant::now();
    // 50 times a second: the base's pose for the live view.
    until_ctrl_c(0.02, || {
        if let Some(live) = &live
            && let Some(base) = (live.base)()
        {
            live.events.base_pose(live.device, base.position_m.map(f64::from), base.rpy_rad.map(f64::from));
        }
        print_log();
        if every_s.is_finite() && every_s > 0.0 && last_report.elapsed().as_secs_f64() >= every_s {
            last_report = std::time::Instant::now();
            eprintln!("{}", report());
        }
    })?;
    print_log();
    Ok(())
}

/// A simulated robot as the live view shows it: its log lines as events, its physics body's base
/// as its frame.
pub(crate) struct LiveBody<'a> {
    pub(crate) events: robowire_live::LiveEvents,
    pub(crate) device: &'static str,
    pub(crate) base: &'a dyn Fn() -> Option<robowire_sim::go2::BasePose>,
}
