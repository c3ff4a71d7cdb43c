//! A ZSL-1 spline client with robowire: the 1 kHz low-level loop on the motor daemon's shared
//! memory. Waits for each fresh state, writes the next PD targets, moves every leg from lying to
//! standing and holds, and reads the IMU. Against the built-in daemon simulator (private object
//! names) by default; `--name`/`--imu-name` for the robot's `/spline_shm` and `/imu_shm`.
//!
//! ```sh
//! cargo run --example spline_client
//! cargo run --example spline_client -- --name /spline_shm --imu-name /imu_shm   # on the robot
//! ```

use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use robowire_sim::spline::{LYING_POSE_RAD, STANDING_POSE_RAD, SplineSim, SplineSimConfig};
use zsl::{ImuReader, JointControl, JointIndex, Leg, SplineClient, SplineCommandBlock, SplineError, SplineStateBlock};

/// ZSL-1 spline client demo.
#[derive(Debug, Parser)]
struct Args {
    /// The daemon's spline object; without it, a simulated daemon on private names.
    #[arg(long)]
    name: Option<String>,
    /// The IMU object (with --name).
    #[arg(long, default_value = "/imu_shm")]
    imu_name: String,
    /// Seconds to stand up, then as long to hold.
    #[arg(long, default_value_t = 2.0)]
    seconds: f64,
}

const KP: f32 = 60.0;
const KD: f32 = 2.0;

/// Every leg at `pose` (abad, hip, knee) under the PD gains.
fn pose(pose: [f32; 3]) -> SplineCommandBlock {
    let mut command = SplineCommandBlock::default();
    for leg in Leg::ALL {
        for (j, joint) in [JointIndex::Abad, JointIndex::Hip, JointIndex::Knee].into_iter().enumerate() {
            *command.joint_mut(leg, joint) = JointControl::new(pose[j], 0.0, KP, KD, 0.0);
        }
    }
    command
}

/// How long a stalled daemon is waited for before the example gives up.
const STALL_LIMIT: Duration = Duration::from_secs(1);

/// The next fresh state. A stall (no fresh state for 10 ms: the client reports it once) is
/// counted and waited out, up to [`STALL_LIMIT`]; a daemon silent longer ends the example.
fn next_state(client: &mut SplineClient, stalls: &mut u32) -> anyhow::Result<SplineStateBlock> {
    let give_up = Instant::now() + STALL_LIMIT;
    loop {
        match client.wait_state(Duration::from_millis(50)) {
            Ok(state) => return Ok(state),
            Err(SplineError::DaemonStalled { stalled_for }) if Instant::now() < give_up => {
                *stalls += 1;
                eprintln!("daemon stalled: no fresh state for {stalled_for:?}; waiting");
            }
            Err(e) => return Err(e.into()),
        }
    }
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    anyhow::ensure!(args.seconds.is_finite() && args.seconds > 0.0, "--seconds must be positive");
    let sim = match &args.name {
        Some(_) => None,
        None => Some(SplineSim::spawn(SplineSimConfig::private("example")).context("starting the simulated daemon")?),
    };
    let (spline_name, imu_name) = match &sim {
        Some(sim) => (sim.config().spline_name.clone(), sim.config().imu_name.clone()),
        None => (args.name.clone().context("no object name")?, args.imu_name.clone()),
    };
    let mut client = SplineClient::open(&spline_name)?;
    let mut imu = ImuReader::open(&imu_name)?;
    println!("daemon on {spline_name} and {imu_name}");

    // The loop runs on the daemon's clock: each fresh state triggers the next command.
    let mut stalls = 0u32;
    let first = next_state(&mut client, &mut stalls)?;
    let start = [JointIndex::Abad, JointIndex::Hip, JointIndex::Knee].map(|j| first.joint(Leg::FrontRight, j).p.get());
    println!("FR leg at {start:?} rad (lying: {LYING_POSE_RAD:?})");
    let duration = Duration::from_secs_f64(args.seconds);
    let began = Instant::now();
    let mut cycles = 0u64;
    while began.elapsed() < 2 * duration {
        let s = (began.elapsed().as_secs_f32() / duration.as_secs_f32()).min(1.0);
        let s = s * s * (3.0 - 2.0 * s);
        let target = std::array::from_fn(|j| start[j] + (STANDING_POSE_RAD[j] - start[j]) * s);
        client.write_command(&pose(target))?;
        next_state(&mut client, &mut stalls)?;
        cycles += 1;
    }
    let state = next_state(&mut client, &mut stalls)?;
    let knee = state.joint(Leg::FrontRight, JointIndex::Knee).p.get();
    let sample = imu.read()?;
    println!(
        "{cycles} cycles in {:.1} s, {stalls} stalls waited out; FR knee {knee:+.3} rad (target {:+.3}); IMU acc z {:.2} m/s², age {:.2} ms",
        began.elapsed().as_secs_f64(),
        STANDING_POSE_RAD[2],
        sample.acc_mps2[2],
        imu.latest_age()?.as_secs_f64() * 1e3
    );
    Ok(())
}
