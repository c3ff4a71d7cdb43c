//! Where a command's human-readable output goes: standard output, or standard error when
//! standard output carries JSON (`--json`), so that a script can pipe the JSON and still see the
//! report. A live progress line, when one is shown, is cleared before every report line.

use std::fmt::Display;
use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// The output of one command run.
#[derive(Debug)]
pub(crate) struct Output {
    json: bool,
    /// A live line is on screen and must be cleared before the next report line.
    live_line_shown: AtomicBool,
    /// Where report lines also go as events (`--live`).
    events: std::sync::OnceLock<(robowire_live::LiveEvents, &'static str)>,
}

impl Output {
    /// Human output on stdout; with `json`, on stderr (stdout is for the JSON).
    pub(crate) fn new(json: bool) -> Self {
        Self { json, live_line_shown: AtomicBool::new(false), events: std::sync::OnceLock::new() }
    }

    /// Report lines also go to a live view's log, from `name` (`demo`).
    pub(crate) fn also_to(&self, events: robowire_live::LiveEvents, name: &'static str) {
        let _ = self.events.set((events, name));
    }

    /// Whether the report goes to a terminal (a live line can be redrawn in place).
    pub(crate) fn is_terminal(&self) -> bool {
        if self.json { std::io::stderr().is_terminal() } else { std::io::stdout().is_terminal() }
    }

    /// One report line.
    pub(crate) fn line(&self, text: impl Display) {
        self.clear_live();
        if let Some((events, name)) = self.events.get() {
            let text = text.to_string();
            if !text.trim().is_empty() {
                events.log(robowire_live::Level::Info, name, text.trim());
            }
        }
        if self.json {
            eprintln!("{text}");
        } else {
            println!("{text}");
        }
    }

    /// Text as it is, best effort (a closed stream must not stop a robot's loop).
    pub(crate) fn write(&self, text: &str) {
        let result = if self.json {
            let mut err = std::io::stderr();
            err.write_all(text.as_bytes()).and_then(|()| err.flush())
        } else {
            let mut out = std::io::stdout();
            out.write_all(text.as_bytes()).and_then(|()| out.flush())
        };
        let _ = result;
    }

    /// Replaces the live line with `text` (on a terminal).
    pub(crate) fn live(&self, text: &str) {
        self.write(&format!("\r\x1b[2K{text}"));
        self.live_line_shown.store(true, Ordering::Relaxed);
    }

    /// Clears the live line, if one is shown.
    pub(crate) fn clear_live(&self) {
        if self.live_line_shown.swap(false, Ordering::Relaxed) {
            self.write("\r\x1b[2K");
        }
    }
}
