//! A KMC link's chassis frames played on a pseudo-terminal by
//! `robowire_sim::replay::SerialReplay`, from the host's first frame on. The first line on
//! stdout is the pty's path, alone, for scripts (as `robowire sim kmc` prints it).

use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use kmc_proto::HostFrameDecoder;
use robowire_sim::replay::{Pace, SerialReplay};

/// How long the host has to read the last frames before the line hangs up.
const DRAIN: Duration = Duration::from_secs(5);
/// How often the wait for the host's first frame says it still waits.
const REMIND_EVERY: Duration = Duration::from_secs(10);

/// Plays `frames` (offsets from the first, bytes) of `link`.
pub(super) fn run(frames: Vec<(Duration, Vec<u8>)>, link: &str, pace: Pace) -> anyhow::Result<ExitCode> {
    let mut chassis = SerialReplay::open(HostFrameDecoder::new(), frames).context("opening a pseudo-terminal")?;
    let path = chassis.path().display().to_string();
    println!("{path}");
    eprintln!(
        "replay: {} chassis frames of {link} on {path}; waiting for the host's first frame \
         (try: robowire kmc --port {path} drive --velocity 0)",
        chassis.frames()
    );
    while !chassis.first_command(REMIND_EVERY).context("reading the host's frames")? {
        eprintln!("replay: still waiting for the host on {path}");
    }
    eprintln!("replay: the host spoke; playing");
    let summary = chassis.play(pace, DRAIN)?;
    eprintln!(
        "replay: wrote {} of {} chassis frames; received {} host frames ({} rejected candidates)",
        summary.sent, summary.frames, summary.commands, summary.invalid
    );
    Ok(ExitCode::SUCCESS)
}
