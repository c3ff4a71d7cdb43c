//! `robowire kmc --port PATH …`: a real (or simulated) chassis.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use clap::{Args, Subcommand};
use kmc::{BlockingUartClient, ChassisFrame, Driver, DriverOptions, SerialPortOptions, SerialTaps};
use robowire_devices::Describe;

#[derive(Debug, Args)]
pub(crate) struct KmcArgs {
    /// Serial device of the chassis, e.g. /dev/ttyUSB0 (or the path `robowire sim kmc` prints).
    #[arg(long)]
    port: PathBuf,
    /// Baud rate.
    #[arg(long, default_value_t = 115_200)]
    baud: u32,
    /// Turn RTS/CTS hardware flow control off (it is on by default, as the chassis expects).
    #[arg(long)]
    no_flow_control: bool,
    /// Record the line's frames, both ways, and the bytes skipped between them.
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
    #[command(subcommand)]
    command: KmcCommand,
}

#[derive(Debug, Subcommand)]
enum KmcCommand {
    /// Stream a command through the Driver and print what comes back.
    Drive(DriveArgs),
    /// Ask for the vehicle speed once.
    Speed(OneShotArgs),
    /// Read the battery voltage once.
    Battery(OneShotArgs),
    /// Read a motor controller's all-state record once.
    AllState(OneShotArgs),
}

#[derive(Debug, Args)]
struct DriveArgs {
    /// Forward velocity, m/s (negative reverses).
    #[arg(long, allow_hyphen_values = true)]
    velocity: f32,
    /// Yaw rate, rad/s (dropped when |velocity| <= 1 mm/s: the chassis cannot turn in place).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0)]
    yaw_rate: f32,
    /// How long to drive, s; then the stop burst.
    #[arg(long, default_value_t = 5.0)]
    duration: f64,
    /// Don't poll the battery (1 Hz) and the all-state records (10 Hz).
    #[arg(long)]
    no_polls: bool,
}

#[derive(Debug, Args)]
struct OneShotArgs {
    /// Motor controller (0 = left, 1 = right).
    #[arg(long, default_value_t = 0)]
    motor: u8,
    /// How long to wait for the answer, ms.
    #[arg(long, default_value_t = 1000)]
    timeout_ms: u64,
}

pub(crate) fn run(args: KmcArgs) -> anyhow::Result<ExitCode> {
    let serial = SerialPortOptions {
        baud_rate: args.baud,
        rts_cts_flow_control: !args.no_flow_control,
        ..SerialPortOptions::default()
    };
    let sinks = args.record.start("robowire kmc")?;
    let taps = sinks.links().map(|l| robowire_devices::kmc_taps(&l, &kmc_proto::description::HOST)).unwrap_or_default();
    let port = &args.port;
    let result = match args.command {
        KmcCommand::Drive(drive) => run_drive(port, DriverOptions { serial, taps, ..Default::default() }, &drive),
        KmcCommand::Speed(one) => {
            one_shot(port, &serial, taps, &one, "vehicle speed", |c, _| c.request_vehicle_speed())
        }
        KmcCommand::Battery(one) => {
            one_shot(port, &serial, taps, &one, "battery voltage", |c, m| c.request_battery_voltage(m))
        }
        KmcCommand::AllState(one) => one_shot(port, &serial, taps, &one, "all-state", |c, m| c.request_all_state(m)),
    };
    // The link is closed by now: the capture holds all it saw, the stop burst too.
    sinks.finish()?;
    result
}

/// Drives with `options` (its serial port and taps), polling as `args` says.
fn run_drive(port: &PathBuf, options: DriverOptions, args: &DriveArgs) -> anyhow::Result<ExitCode> {
    if !(args.duration.is_finite() && args.duration >= 0.0) {
        bail!("--duration must be a finite number of seconds, got {}", args.duration);
    }
    let options = DriverOptions { poll_battery: !args.no_polls, poll_allstate: !args.no_polls, ..options };
    // Validate before the port is even opened.
    Driver::command(args.velocity, args.yaw_rate).context("refusing to drive")?;
    let stop_burst = options.stop_burst_count;
    let driver = Driver::open(port, options).with_context(|| format!("starting the driver on {}", port.display()))?;
    // The command stays fresh until the end; the driver stops the chassis if this process stalls.
    driver.set_command_timeout(Duration::from_secs_f64(args.duration).max(Duration::from_millis(300)))?;
    driver.set_command(args.velocity, args.yaw_rate)?;
    println!(
        "driving {:+.3} m/s at {:+.3} rad/s for {:.1} s on {}",
        args.velocity,
        args.yaw_rate,
        args.duration,
        port.display()
    );
    let end = Instant::now() + Duration::from_secs_f64(args.duration);
    for frame in driver.messages_until(end) {
        print_frame(&frame);
    }
    let stats = driver.stats_line();
    driver.close().context("sending the stop burst")?;
    println!("stopped. stop burst {stop_burst} × (0, 0); {stats}");
    Ok(ExitCode::SUCCESS)
}

fn one_shot(
    port: &PathBuf,
    serial: &SerialPortOptions,
    taps: SerialTaps,
    args: &OneShotArgs,
    what: &str,
    request: impl Fn(&mut BlockingUartClient, u8) -> Result<(), kmc::KmcError>,
) -> anyhow::Result<ExitCode> {
    let mut client = BlockingUartClient::open(port, serial)?;
    client.client_mut().link_mut().set_taps(taps);
    request(&mut client, args.motor)?;
    match client.poll(Duration::from_millis(args.timeout_ms))? {
        Some(frame) => {
            print_frame(&frame);
            Ok(ExitCode::SUCCESS)
        }
        None => bail!("no {what} answer within {} ms", args.timeout_ms),
    }
}

fn print_frame(frame: &ChassisFrame) {
    match frame {
        ChassisFrame::VehicleSpeed(v) => println!("speed      {:+.3} m/s", v.speed_mps),
        ChassisFrame::BatteryVoltage(b) => println!("battery    motor {} {:.2} V", b.motor_id, b.volts),
        ChassisFrame::AllState(s) => println!(
            "all-state  motor {} id {} position {:.1}° speed {:.1} rpm current {:.2} A temperature {:.1} °C error 0x{:08x}",
            s.motor_id, s.id, s.position_deg, s.speed_rpm, s.current_a, s.temperature_c, s.error_code
        ),
        ChassisFrame::Af(raw) => println!("af         {raw:?}"),
    }
}
