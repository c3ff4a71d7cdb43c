//! ZsiBot's low-level demo with robowire: the two-stage stand on the twelve motors over UDP.
//! Stage 1 moves every leg from where it is to a crouch, stage 2 from the crouch to standing,
//! each a smooth interpolation of the position targets under a PD law; then the pose is held.
//! Against the built-in simulator by default; `--dog-ip`/`--local-ip` for a robot.
//!
//! ```sh
//! cargo run --example zsl_low_level
//! ```

use std::net::{IpAddr, Ipv4Addr};
use std::time::{Duration, Instant};

use anyhow::{Context, ensure};
use clap::Parser;
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
use zsl::udp::{ClientOptions, LowLevel, MotorCommand};

/// ZsiBot ZSL-1 low-level demo.
#[derive(Debug, Parser)]
struct Args {
    /// The robot's address; without it, a simulated dog on loopback.
    #[arg(long)]
    dog_ip: Option<IpAddr>,
    /// This computer's address on the robot's network.
    #[arg(long, default_value = "0.0.0.0")]
    local_ip: IpAddr,
    /// Local port for the LowLevel interface.
    #[arg(long, default_value_t = 43989)]
    local_port: u16,
    /// Seconds per stage.
    #[arg(long, default_value_t = 1.5)]
    stage_s: f64,
}

/// Abad, hip, knee, rad: the crouch of stage 1 and the stand of stage 2.
const CROUCH_RAD: [f32; 3] = [0.0, 1.0, -2.0];
const STAND_RAD: [f32; 3] = [0.0, 0.8, -1.5];
const KP: [f32; 3] = [60.0, 60.0, 60.0];
const KD: [f32; 3] = [1.5, 1.5, 1.5];
/// The vendor demo's control period.
const PERIOD: Duration = Duration::from_millis(2);

/// `from` → `to` at `fraction` (0..=1), smooth-step.
fn blend(from: [[f32; 4]; 3], to: [f32; 3], fraction: f64) -> [[f32; 4]; 3] {
    let s = fraction.clamp(0.0, 1.0) as f32;
    let s = s * s * (3.0 - 2.0 * s);
    std::array::from_fn(|joint| from[joint].map(|q| q + (to[joint] - q) * s))
}

#[tokio::main]
async fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    ensure!(args.stage_s.is_finite() && args.stage_s >= 0.2, "--stage-s must be at least 0.2 s");
    let (_sim, options) = match args.dog_ip {
        Some(dog_ip) => (None, ClientOptions::low_level(args.local_ip, args.local_port, dog_ip)),
        None => {
            let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).context("starting the simulated dog")?;
            let local = Ipv4Addr::LOCALHOST.into();
            let options = ClientOptions { dog: sim.low_level_addr(), ..ClientOptions::low_level(local, 0, local) };
            println!("simulated dog, LowLevel at {}", sim.low_level_addr());
            (Some(sim), options)
        }
    };
    let low = LowLevel::open(options)?;
    ensure!(low.wait_connected(Duration::from_secs(5)).await, "no state from the robot");
    let start = low.motor_state().context("no motor state")?.q_rad;
    println!("legs at abad/hip/knee {:?} rad (FR)", [start[0][0], start[1][0], start[2][0]]);

    let stage = Duration::from_secs_f64(args.stage_s);
    let mut from = start;
    for (name, target) in [("crouch", CROUCH_RAD), ("stand", STAND_RAD)] {
        let began = Instant::now();
        let mut next = Instant::now();
        while began.elapsed() < stage {
            let fraction = began.elapsed().as_secs_f64() / stage.as_secs_f64();
            low.send_motor_command(&MotorCommand::pd_hold(blend(from, target, fraction), KP, KD))?;
            next += PERIOD;
            tokio::time::sleep_until(next.into()).await;
        }
        from = blend(from, target, 1.0);
        let q = low.motor_state().context("state lost")?.q_rad;
        println!("{name:<6} FR abad/hip/knee {:+.2} {:+.2} {:+.2} rad", q[0][0], q[1][0], q[2][0]);
    }
    low.send_motor_command(&MotorCommand::pd_hold(from, KP, KD))?;
    tokio::time::sleep(Duration::from_secs(1)).await;
    let q = low.motor_state().context("state lost")?.q_rad;
    let worst = (0..3).flat_map(|j| q[j].iter().map(move |v| (v - STAND_RAD[j]).abs())).fold(0.0f32, f32::max);
    println!("holding the stand, largest joint error {worst:.3} rad");
    Ok(())
}
