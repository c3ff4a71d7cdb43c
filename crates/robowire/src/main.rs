#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

mod cmd;
mod hex;
mod output;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// robowire: low-level robot protocols, with built-in simulators.
#[derive(Debug, Parser)]
#[command(name = "robowire", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Drive every simulated device through its client API and report what was seen.
    Demo(cmd::demo::DemoArgs),
    /// Print one state of any device, by address (kmc:PATH, zsl1:IP, zsl1w:IP, go2:IFACE, hg:IFACE, g1:IFACE, sim:KIND).
    Status(cmd::device::StatusArgs),
    /// Print the state of any device live, by address, until Ctrl-C.
    Watch(cmd::device::DeviceArgs),
    /// Stream devices, by address, to Foxglove (ws://ADDR/) and the built-in page (http://ADDR/), until Ctrl-C.
    Serve(cmd::serve::ServeArgs),
    /// Run a device simulator alone, for your own client to talk to.
    #[command(subcommand)]
    Sim(cmd::sim::SimCommand),
    /// Talk to a KMC wheeled chassis over a serial port.
    Kmc(cmd::kmc::KmcArgs),
    /// Drive a ZsiBot ZSL-1 / ZSL-1W over UDP (HighLevel: stand, walk, tricks, status).
    // `dog`: its old name, kept for one release.
    #[command(alias = "dog")]
    Zsl1(cmd::zsl1::Zsl1Args),
    /// Drive a Unitree Go2's low-level interface over DDS (status, watch, release, stand, damp).
    Go2(cmd::go2::Go2Args),
    /// Drive a Unitree G1 humanoid's low-level interface over DDS (status, watch, release, damp, zero).
    G1(cmd::g1::G1Args),
    /// Run a trained locomotion policy (ONNX, unitree_rl_gym's deploy config) on a Unitree robot or its physics simulator.
    #[command(subcommand)]
    Policy(cmd::policy::PolicyCommand),
    /// Inspect DDS: the topics on the network, the samples of one.
    Dds(cmd::dds::DdsCommandArgs),
    /// Every device as a ROS 2 node on the wire (cmd_vel, odom, tf, imu, joint_states, …), no ROS install needed.
    Ros2(cmd::ros2::Ros2Args),
    /// Look at the ZSL-1 spline daemon's shared memory (/spline_shm, /imu_shm).
    #[command(subcommand)]
    Shm(cmd::shm::ShmCommand),
    /// Decode frames or messages from hex and print them, or summarize a capture (--mcap).
    Decode(cmd::decode::DecodeArgs),
    /// Replay an MCAP capture into the decoders, at the recorded pace.
    Replay(cmd::record::ReplayArgs),
    /// Draw a capture: one page per device, commanded against observed, faults and silences marked.
    Plot(cmd::plot::PlotArgs),
    /// Why a robot does not answer: the interface, DDS, the ZSL-1's port or the KMC's line checked, with the fix for each failure.
    Doctor(cmd::doctor::DoctorArgs),
    /// Encode a message from JSON and print its bytes in hex.
    #[command(subcommand)]
    Encode(cmd::encode::EncodeCommand),
}

fn main() -> ExitCode {
    // Die quietly on a closed pipe (`robowire decode … | head`) like other Unix tools, instead of
    // panicking in println!.
    sigpipe::reset();
    let cli = Cli::parse();
    // Before anything else: the demo's Go2 needs multicast on loopback, and a normal user gets
    // it by running the demo again in a user + network namespace of its own (this process then
    // exits with its status).
    let loopback = match &cli.command {
        Command::Demo(args) if args.runs_go2() => Some(robowire_dds::netns::for_this_process()),
        Command::Status(args) if args.device.simulates_dds() => Some(robowire_dds::netns::for_this_process()),
        Command::Watch(args) if args.simulates_dds() => Some(robowire_dds::netns::for_this_process()),
        Command::Serve(args) if args.simulates_dds() => Some(robowire_dds::netns::for_this_process()),
        Command::Doctor(args) if args.simulates_dds() => Some(robowire_dds::netns::for_this_process()),
        Command::Policy(cmd::policy::PolicyCommand::Run(args)) if args.simulates_dds() => {
            Some(robowire_dds::netns::for_this_process())
        }
        _ => None,
    };
    let result = match cli.command {
        Command::Demo(args) => cmd::demo::run(&args, loopback),
        Command::Status(args) => cmd::device::on_loopback(loopback, || cmd::device::status(&args)),
        Command::Watch(args) => cmd::device::on_loopback(loopback, || cmd::device::watch(&args)),
        Command::Serve(args) => cmd::device::on_loopback(loopback, || cmd::serve::serve(&args)),
        Command::Sim(command) => cmd::sim::run(command),
        Command::Kmc(args) => cmd::kmc::run(args),
        Command::Zsl1(args) => cmd::zsl1::run(args),
        Command::Go2(args) => cmd::go2::run(args),
        Command::G1(args) => cmd::g1::run(args),
        Command::Policy(command) => cmd::policy::run(command, loopback),
        Command::Dds(args) => cmd::dds::run(args),
        Command::Ros2(args) => cmd::ros2::run(args),
        Command::Shm(command) => cmd::shm::run(&command),
        Command::Decode(args) => cmd::decode::run(&args),
        Command::Replay(args) => cmd::record::replay(&args),
        Command::Plot(args) => cmd::plot::run(&args),
        Command::Encode(command) => cmd::encode::run(&command),
        Command::Doctor(args) => cmd::device::on_loopback(loopback, || cmd::doctor::run(&args)),
    };
    match result {
        Ok(code) => code,
        Err(error) => {
            // The error and its causes, each once: "cannot open serial port X: No such file …".
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
