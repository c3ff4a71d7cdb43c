#![doc = include_str!("../README.md")]

mod decode;
mod demo;
mod dog_cmd;
mod hex;
mod kmc_cmd;
mod lowlevel;
mod shm_cmd;
mod sim;
mod zsl_decode;

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
    Demo(demo::DemoArgs),
    /// Run a device simulator alone, for your own client to talk to.
    #[command(subcommand)]
    Sim(sim::SimCommand),
    /// Talk to a KMC wheeled chassis over a serial port.
    Kmc(kmc_cmd::KmcArgs),
    /// Drive a ZsiBot ZSL-1 / ZSL-1W over UDP (HighLevel: stand, walk, tricks, status).
    Dog(dog_cmd::DogArgs),
    /// Look at the ZSL-1 spline daemon's shared memory (/spline_shm, /imu_shm).
    #[command(subcommand)]
    Shm(shm_cmd::ShmCommand),
    /// Decode frames or messages from hex and print them.
    #[command(subcommand)]
    Decode(decode::DecodeCommand),
    /// Encode a message from JSON and print its bytes in hex.
    #[command(subcommand)]
    Encode(decode::EncodeCommand),
}

fn main() -> ExitCode {
    // Die quietly on a closed pipe (`robowire decode … | head`) like other Unix tools, instead of
    // panicking in println!.
    sigpipe::reset();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Demo(args) => demo::run(&args),
        Command::Sim(command) => sim::run(command),
        Command::Kmc(args) => kmc_cmd::run(args),
        Command::Dog(args) => dog_cmd::run(args),
        Command::Shm(command) => shm_cmd::run(&command),
        Command::Decode(command) => decode::run(&command),
        Command::Encode(command) => decode::run_encode(&command),
    };
    match result {
        Ok(code) => code,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
