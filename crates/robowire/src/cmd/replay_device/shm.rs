//! A spline link's daemon states (and the device's IMU records) published on shared memory by
//! `robowire_sim::replay::SplineReplay`, from the motion controller's first command on. The first
//! line on stdout names the objects, alone, for scripts (as `robowire sim spline` prints them).

use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use robowire_shm::CreateOptions;
use robowire_sim::replay::{Pace, SplineReplay};

/// How often the wait for the controller's first command says it still waits.
const REMIND_EVERY: Duration = Duration::from_secs(10);

/// Plays `states` and `imu` (offsets from the first state, bytes) of `link` on the objects
/// `(spline, imu)`.
pub(super) fn run(
    states: Vec<(Duration, Vec<u8>)>,
    imu: Vec<(Duration, Vec<u8>)>,
    link: &str,
    (spline, imu_name): (&str, &str),
    pace: Pace,
) -> anyhow::Result<ExitCode> {
    let (state_count, imu_count) = (states.len(), imu.len());
    let mut daemon = SplineReplay::create(spline, imu_name, &CreateOptions::default(), states, imu)
        .with_context(|| format!("creating {spline} and {imu_name}"))?;
    println!("{spline} {imu_name}");
    eprintln!(
        "replay: {state_count} daemon states of {link} and {imu_count} IMU records on {spline} and {imu_name}; \
         waiting for the motion controller's first command"
    );
    while !daemon.first_command(REMIND_EVERY)? {
        eprintln!("replay: still waiting for a command on {spline}");
    }
    eprintln!("replay: the controller commanded; playing");
    let summary = daemon.play(pace)?;
    eprintln!("replay: published {} of {} frames; took {} commands", summary.sent, summary.frames, summary.commands);
    Ok(ExitCode::SUCCESS)
}
