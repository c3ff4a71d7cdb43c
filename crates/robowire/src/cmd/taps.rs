//! Where a command's links go: a capture (`--record`), a live view (`--live`), both or neither.

use std::net::SocketAddr;

use anyhow::Context;
use clap::Args;
use robowire_core::json::LinkDescription;
use robowire_live::{LiveEvents, LiveOptions, LiveServer};
use robowire_record::{RecordLinks, Recorder, Tap};

/// The live view's address when `--live` names none.
pub(crate) const DEFAULT_LIVE: &str = "127.0.0.1:8765";

/// `--live [ADDR]` and `--live-rate HZ`.
#[derive(Debug, Clone, Args)]
pub(crate) struct LiveArgs {
    /// Stream every link live: Foxglove connects to ws://ADDR/, a browser opens http://ADDR/
    /// (the built-in page). ADDR defaults to 127.0.0.1:8765; port 0 takes a free one.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = DEFAULT_LIVE)]
    pub(crate) live: Option<SocketAddr>,
    /// With --live: at most this many messages a second per link, direction and message length
    /// go to the viewers (every frame is still counted).
    #[arg(long, value_name = "HZ", default_value_t = 50.0)]
    pub(crate) live_rate: f64,
}

impl LiveArgs {
    /// The live view, if asked for; its addresses said on stderr.
    pub(crate) fn start(&self, command: &str) -> anyhow::Result<Option<LiveServer>> {
        let Some(addr) = self.live else { return Ok(None) };
        let options = LiveOptions {
            rate_hz: self.live_rate,
            plots: crate::cmd::captures::link_plots(),
            robots: unitree_proto::kinematics::ROBOTS.to_vec(),
            name: command.to_owned(),
            ..LiveOptions::default()
        };
        let live = LiveServer::start(addr, options).context("--live")?;
        let at = live.addr();
        eprintln!("live: Foxglove ws://{at}/  page http://{at}/");
        Ok(Some(live))
    }
}

/// A command's capture and live view.
#[derive(Debug, Default)]
pub(crate) struct Taps {
    pub(crate) recorder: Option<Recorder>,
    pub(crate) live: Option<LiveServer>,
}

impl Taps {
    /// Registers the links with the capture, the live view, or both.
    pub(crate) fn links(&self) -> Option<RecordLinks> {
        RecordLinks::either(self.recorder.as_ref().map(Recorder::links), self.live.as_ref().map(LiveServer::links))
    }

    /// A tap for the link `name`, if anything takes its frames.
    pub(crate) fn link(&self, name: &str, description: &'static dyn LinkDescription) -> Option<Tap> {
        self.links().map(|links| links.link(name, description))
    }

    /// Where events go to the live view's viewers.
    pub(crate) fn events(&self) -> Option<LiveEvents> {
        self.live.as_ref().map(LiveServer::events)
    }

    /// Closes the capture and says what it holds; stops the live view and says what it sent.
    pub(crate) fn finish(self) -> anyhow::Result<()> {
        if let Some(live) = self.live {
            let stats = live.stop();
            let (seen, sent) = stats.links.iter().fold((0, 0), |(a, b), l| (a + l.seen, b + l.sent));
            let dropped = stats.viewer_dropped_total;
            eprintln!(
                "live: {seen} frames seen, {sent} sent to viewers ({} dropped by the view's ring, {dropped} by slow viewers)",
                stats.ring_dropped
            );
        }
        finish_recorder(self.recorder)
    }
}

/// Closes the capture and says what it holds.
pub(crate) fn finish_recorder(recorder: Option<Recorder>) -> anyhow::Result<()> {
    if let Some(recorder) = recorder {
        let summary = recorder.finish().context("closing the capture")?;
        eprintln!(
            "record: {} frames written, {} dropped (the writer fell behind), {} oversize, {} not decodable, \
             {} without JSON (the decoder fell behind){}",
            summary.frames,
            summary.dropped,
            summary.oversize,
            summary.decode_errors,
            summary.json_skipped,
            if summary.not_wire > 0 {
                format!(", {} not in their wire encoding (left out)", summary.not_wire)
            } else {
                String::new()
            }
        );
    }
    Ok(())
}
