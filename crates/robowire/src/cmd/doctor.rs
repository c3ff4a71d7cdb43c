//! `robowire doctor`: why a robot does not answer, each check with ✓/✗/? and the fix for a ✗.

use std::process::ExitCode;

use clap::Args;
use robowire_devices::DeviceAddress;
use robowire_doctor::Options;

use crate::output::Output;

#[derive(Debug, Args)]
pub(crate) struct DoctorArgs {
    /// The device (go2:IFACE, g1:IFACE, hg:IFACE, zsl1:IP, zsl1w:IP, kmc:PATH, sim:go2|g1|zsl1|kmc);
    /// without one, whatever speaks DDS on --interface, and the ZSL-1 whose state arrives.
    address: Option<DeviceAddress>,
    /// The network interface (overrides the address's).
    #[arg(long)]
    interface: Option<String>,
    /// DDS domain.
    #[arg(long, default_value_t = 0)]
    domain: u16,
    /// Print the checks as JSON on stdout (the checklist goes to stderr).
    #[arg(long)]
    json: bool,
    /// Seconds to listen on the network (twice that when nobody is heard and domains 0–9 are
    /// listened on).
    #[arg(long, default_value_t = 3.0)]
    timeout: f64,
}

impl DoctorArgs {
    /// Whether it starts a simulator on DDS (which needs multicast on loopback).
    pub(crate) fn simulates_dds(&self) -> bool {
        self.address.as_ref().is_some_and(|a| a.is_simulated() && a.uses_dds())
    }
}

pub(crate) fn run(args: &DoctorArgs) -> anyhow::Result<ExitCode> {
    let options = Options {
        interface: args.interface.clone(),
        domain: args.domain,
        timeout: super::seconds("--timeout", args.timeout)?,
    };
    let (target, _simulator) = robowire_doctor::prepare(args.address.as_ref(), &options)?;
    let report = robowire_doctor::diagnose(&target, &options);
    let out = Output::new(args.json);
    out.line(format!("robowire doctor {}", report.target));
    out.write(&report.to_string());
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    }
    Ok(if report.failed() { ExitCode::FAILURE } else { ExitCode::SUCCESS })
}
