//! ZsiBot's high-level demo with robowire: connect, stand up, walk forward, turn, tilt the body,
//! lie down. Against the built-in simulator by default; `--dog-ip`/`--local-ip` for a robot.
//!
//! ```sh
//! cargo run --example zsl_high_level
//! cargo run --example zsl_high_level -- --dog-ip 192.168.234.1 --local-ip 192.168.234.10
//! ```

use std::net::{IpAddr, Ipv4Addr};
use std::time::Duration;

use anyhow::{Context, ensure};
use clap::Parser;
use robowire_sim::zsl1::{Zsl1Sim, Zsl1SimConfig};
use zsl::udp::{ClientOptions, ControlMode, Device, HighLevel};

/// ZsiBot ZSL-1 high-level demo.
#[derive(Debug, Parser)]
struct Args {
    /// The robot's address; without it, a simulated dog on loopback.
    #[arg(long)]
    dog_ip: Option<IpAddr>,
    /// This computer's address on the robot's network (the robot's configured `target_ip`).
    #[arg(long, default_value = "0.0.0.0")]
    local_ip: IpAddr,
    /// Local port (the robot's configured `target_port`).
    #[arg(long, default_value_t = 43988)]
    local_port: u16,
}

const WAIT: Duration = Duration::from_secs(5);

#[tokio::main]
async fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    // `initRobot(local_ip, local_port, dog_ip)`.
    let (_sim, options) = match args.dog_ip {
        Some(dog_ip) => (None, ClientOptions::high_level(args.local_ip, args.local_port, dog_ip)),
        None => {
            let sim = Zsl1Sim::spawn(Zsl1SimConfig::loopback()).context("starting the simulated dog")?;
            let local = Ipv4Addr::LOCALHOST.into();
            let options = ClientOptions { dog: sim.high_level_addr(), ..ClientOptions::high_level(local, 0, local) };
            println!("simulated dog at {}", sim.high_level_addr());
            (Some(sim), options)
        }
    };
    let dog = HighLevel::open(options)?;
    // `checkConnect()`.
    ensure!(dog.wait_connected(WAIT).await, "no state from the robot: check --dog-ip and --local-ip");
    println!("connected, battery {} %", dog.battery_percent().unwrap_or(0));

    // `standUp()`, then wait until the robot reports it.
    dog.stand_up()?;
    dog.wait_for_state(WAIT, move |s| s.body.mode == ControlMode::Stand && s.body.position_m[2] > 0.25)
        .await
        .context("the robot did not stand up")?;
    println!("standing");

    // `move(0.3, 0, 0)` for 2 s, then turn on the spot at 0.5 rad/s for 2 s.
    for (what, vx, yaw_rate) in [("forward", 0.3, 0.0), ("turning", 0.0, 0.5)] {
        dog.move_velocity(vx, 0.0, yaw_rate)?;
        tokio::time::sleep(Duration::from_secs(2)).await;
        let body = dog.body().context("state lost")?;
        println!(
            "{what:<8} at ({:+.2}, {:+.2}) m, yaw {:+.2} rad",
            body.position_m[0], body.position_m[1], body.imu.rpy_rad[2]
        );
    }
    dog.move_velocity(0.0, 0.0, 0.0)?;
    dog.wait_for_state(WAIT, move |s| {
        s.body.body_velocity_mps[0].abs() < 0.05 && s.body.imu.gyro_radps[2].abs() < 0.05
    })
    .await
    .context("the robot did not stop")?;

    // `attitudeControl(0, 0.3, 0, 0)`: pitch the body for a second, then back.
    dog.attitude_control(0.0, 0.3, 0.0, 0.0)?;
    tokio::time::sleep(Duration::from_secs(1)).await;
    println!("pitched to {:+.2} rad", dog.rpy().map_or(0.0, |r| r[1]));
    dog.attitude_control(0.0, -0.3, 0.0, 0.0)?;
    tokio::time::sleep(Duration::from_secs(1)).await;
    dog.attitude_control(0.0, 0.0, 0.0, 0.0)?;

    // `lieDown()`.
    dog.lie_down()?;
    dog.wait_for_mode(ControlMode::LieDown, WAIT).await.context("the robot did not lie down")?;
    println!("lying down; {} commands sent", dog.stats().link.sent);
    Ok(())
}
