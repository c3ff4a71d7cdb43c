//! The KMC chassis driver demo with robowire: drive with (velocity, yaw rate) as the vendor's
//! `setCommand(v, ω)`, then with (velocity, curvature), reading the speed reports and polls, and
//! stop with the stop burst. Against the built-in chassis simulator by default; `--port` for a
//! chassis.
//!
//! ```sh
//! cargo run --example kmc_drive
//! cargo run --example kmc_drive -- --port /dev/ttyUSB0
//! ```

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Parser;
use kmc::{ChassisFrame, Device, Driver, DriverOptions};
use robowire_sim::kmc::{ChassisSim, ChassisSimConfig};

/// KMC chassis drive demo.
#[derive(Debug, Parser)]
struct Args {
    /// The chassis's serial port; without it, a simulated chassis on a pseudo-terminal.
    #[arg(long)]
    port: Option<PathBuf>,
    /// Seconds per phase.
    #[arg(long, default_value_t = 2.0)]
    phase_s: f64,
}

/// Drives with `set(driver)` for `seconds`, refreshing the command every 20 ms (the Driver stops
/// the chassis 300 ms after the last one) and printing what comes back.
fn drive(driver: &Driver, seconds: f64, set: impl Fn(&Driver) -> Result<(), kmc::KmcError>) -> anyhow::Result<()> {
    let end = Instant::now() + Duration::from_secs_f64(seconds);
    let mut last_print = Instant::now();
    while Instant::now() < end {
        set(driver)?;
        for frame in driver.messages_until(Instant::now() + Duration::from_millis(20)) {
            match frame {
                ChassisFrame::VehicleSpeed(v) if last_print.elapsed() > Duration::from_millis(500) => {
                    println!("  speed {:+.3} m/s", v.speed_mps);
                    last_print = Instant::now();
                }
                ChassisFrame::BatteryVoltage(b) => println!("  battery {:.2} V", b.volts),
                _ => {}
            }
        }
    }
    Ok(())
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    anyhow::ensure!(args.phase_s.is_finite() && args.phase_s > 0.0, "--phase-s must be positive");
    let sim = match &args.port {
        Some(_) => None,
        None => Some(ChassisSim::spawn(ChassisSimConfig::default()).context("starting the simulated chassis")?),
    };
    let port = args.port.clone().or_else(|| sim.as_ref().map(ChassisSim::path)).context("no port")?;
    println!("chassis on {}", port.display());
    let driver = Driver::open(&port, DriverOptions { poll_battery: true, ..Default::default() })?;

    println!("setCommand(0.5 m/s, 0.2 rad/s): curvature 0.4 1/m");
    drive(&driver, args.phase_s, |d| d.set_command(0.5, 0.2))?;
    println!("set_command_curvature(0.3 m/s, -1.0 1/m): a tighter turn the other way");
    drive(&driver, args.phase_s, |d| d.set_command_curvature(0.3, -1.0))?;

    let stats = driver.stats();
    if let Some(chassis) = driver.latest() {
        let o = chassis.state.odometry;
        println!("odometry: x {:+.2} m, y {:+.2} m, heading {:+.2} rad", o.x_m, o.y_m, o.heading_rad);
    }
    driver.close()?; // three (0, 0) frames, then the port is closed
    println!(
        "stopped: {} control frames, lateness p50 {} µs p99 {} µs, {} frames received",
        stats.control_frames_sent, stats.control_lateness.p50_us, stats.control_lateness.p99_us, stats.frames_received
    );
    if let Some(sim) = &sim {
        println!("the simulated chassis turned {:+.2} rad", sim.state().heading_rad);
    }
    Ok(())
}
