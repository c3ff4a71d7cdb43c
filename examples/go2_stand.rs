//! Unitree's Go2 low-level stand example with robowire: release the sport mode, move the twelve
//! joints from where they are to the stand pose, hold it, damp. Against a simulated Go2 on DDS by
//! default (where the loopback has no multicast: as root in a network namespace of its own, else
//! run again in a user + network namespace); `--interface eth0` for a robot on its
//! 192.168.123.x network.
//!
//! ```sh
//! cargo run --example go2_stand
//! ```

use std::time::Duration;

use anyhow::{Context, ensure};
use clap::Parser;
use robowire_sim::go2::{Go2Sim, Go2SimConfig};
use unitree::trajectory::JointTrajectory;
use unitree::{Go2, LowLevel, LowLevelOptions, ParticipantOptions};

/// Unitree Go2 low-level stand.
#[derive(Debug, Parser)]
struct Args {
    /// The network interface of the robot's network; without it, a simulated Go2 on loopback.
    #[arg(long)]
    interface: Option<String>,
    /// Seconds to move to the stand pose.
    #[arg(long, default_value_t = 2.0)]
    duration: f64,
    /// Seconds to hold it.
    #[arg(long, default_value_t = 2.0)]
    hold: f64,
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    ensure!(args.duration.is_finite() && args.duration >= 0.1, "--duration must be at least 0.1 s");
    ensure!(args.hold.is_finite() && args.hold >= 0.0, "--hold must not be negative");
    match &args.interface {
        Some(interface) => stand(&args, ParticipantOptions::new(0, Some(interface)), None),
        // Multicast on loopback: here, or in a user + network namespace this example runs again in.
        None => robowire_dds::netns::for_this_process()
            .run(|| simulated(&args))
            .context("a simulated Go2 on loopback needs multicast on lo")?,
    }
}

fn simulated(args: &Args) -> anyhow::Result<()> {
    let lo = ParticipantOptions::new(0, Some("lo"));
    let sim = Go2Sim::spawn(Go2SimConfig { participant: lo.clone(), ..Go2SimConfig::default() })
        .context("starting the simulated Go2")?;
    println!("simulated Go2 on DDS, interface lo");
    stand(args, lo, Some(&sim))
}

fn stand(args: &Args, participant: ParticipantOptions, sim: Option<&Go2Sim>) -> anyhow::Result<()> {
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    runtime.block_on(async {
        let robot = LowLevel::<Go2>::open(LowLevelOptions { participant, ..LowLevelOptions::default() })?;
        let first = robot.wait_state(Duration::from_secs(10), |_| true).await.context("no rt/lowstate")?;
        let start: [f32; 12] = std::array::from_fn(|i| first.motor_state[i].q.get());
        let calls = robot.release_sport_mode().await?;
        println!("sport mode released ({calls} ReleaseMode)");
        let (duration, hold) = (Duration::from_secs_f64(args.duration), Duration::from_secs_f64(args.hold));
        // Unitree's stand: from where the joints are to the stand pose, kp 60, kd 5, stepped by
        // robowire's LowCmd stream on its own 2 ms deadlines; then the pose held by the stream.
        let stand = JointTrajectory::stand_up(start, duration);
        robot.follow(stand)?.wait().await?;
        tokio::time::sleep(hold).await;
        let q = robot.joint_positions().context("no state")?;
        let worst = stand.largest_error_rad(&q);
        println!("standing: largest joint error {worst:.3} rad");
        robot.damp();
        tokio::time::sleep(Duration::from_millis(300)).await;
        if let Some(sim) = sim {
            ensure!(worst < 0.05, "the simulated Go2 did not reach the stand pose ({worst:.3} rad)");
            println!("simulator: {} LowCmds accepted", sim.snapshot().lowcmd.accepted);
        }
        println!("damped; done");
        Ok(())
    })
}
