//! `robowire serve ADDRESS…`: devices opened by address, only streamed to a live view (Foxglove
//! and the built-in page) until Ctrl-C or `--duration`.

use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use robowire_devices::DeviceAddress;

#[derive(Debug, Args)]
pub(crate) struct ServeArgs {
    /// The devices, by address (as `robowire watch` takes one): kmc:PATH, zsl1:IP, go2:IFACE,
    /// g1:IFACE, spline:NAME, sim:KIND.
    #[arg(required = true, value_name = "ADDRESS")]
    addresses: Vec<DeviceAddress>,
    /// Seconds to serve (default: until Ctrl-C).
    #[arg(long, value_name = "S")]
    duration: Option<f64>,
    /// How to reach the devices; `--live` defaults to 127.0.0.1:8765 here.
    #[command(flatten)]
    reach: crate::cmd::device::ReachArgs,
}

impl ServeArgs {
    /// A simulator on DDS among the devices: it and its client meet on loopback.
    pub(crate) fn simulates_dds(&self) -> bool {
        self.addresses.iter().any(|a| a.is_simulated() && a.uses_dds())
    }
}

/// Opens every device, each waited for, and serves until Ctrl-C or the duration.
pub(crate) fn serve(args: &ServeArgs) -> anyhow::Result<ExitCode> {
    let duration = args.duration.map(|s| crate::cmd::seconds("--duration", s)).transpose()?;
    args.reach.serving(&args.addresses, |devices| async move {
        match duration {
            Some(duration) => tokio::time::sleep(duration).await,
            None => tokio::signal::ctrl_c().await.context("waiting for Ctrl-C")?,
        }
        Ok(devices)
    })
}
