//! `robowire status ADDRESS` and `robowire watch ADDRESS`: any device, by address.

use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use robowire_devices::{AnyDevice, DeviceAddress, OpenOptions};
use robowire_record::RecordLinks;

/// A device and how to reach it.
#[derive(Debug, Args)]
pub(crate) struct DeviceArgs {
    /// The device: kmc:/dev/ttyUSB0, zsl1:192.168.234.1, zsl1w:IP, go2:eth0, hg:eth0, g1:eth0,
    /// spline:/spline_shm, or sim:kmc|zsl1|zsl1w|go2|spline for a simulator started here.
    address: DeviceAddress,
    #[command(flatten)]
    reach: ReachArgs,
}

/// How to reach a device given by address.
#[derive(Debug, Args)]
pub(crate) struct ReachArgs {
    /// DDS domain (go2:, hg:, g1:, sim:go2).
    #[arg(long, default_value_t = 0)]
    domain: u16,
    /// Local address of a zsl1:/zsl1w: client: where the robot sends its state (its
    /// sdk_config.yaml target_ip/target_port).
    #[arg(long, default_value = "0.0.0.0:43988")]
    local: std::net::SocketAddr,
    /// Seconds to wait for the device's first state.
    #[arg(long, default_value_t = 5.0)]
    connect_timeout_s: f64,
    /// Record the device's links, both ways, named after the device (`kmc/serial`,
    /// `zsl1/high_level`, `go2/low_level`, `g1/low_level`, `spline/spline`, …).
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
    /// sim:go2's and sim:g1's body: --physics [--model MJCF] [--free-base].
    #[command(flatten)]
    pub(crate) body: crate::cmd::sim_body::SimPhysicsArgs,
}

#[derive(Debug, Args)]
pub(crate) struct StatusArgs {
    #[command(flatten)]
    pub(crate) device: DeviceArgs,
    /// One state as JSON (the same fields as the device's own status command).
    #[arg(long)]
    json: bool,
}

impl DeviceArgs {
    /// A simulator on DDS: it and its client meet on loopback, which needs multicast.
    pub(crate) fn simulates_dds(&self) -> bool {
        self.address.is_simulated() && self.address.uses_dds()
    }

    /// Opens the device (recording it with `--record`), waits for its first state, hands it to
    /// `run`, then prints its statistics and closes it, and the capture after it.
    fn recording<F: Future<Output = anyhow::Result<AnyDevice>>>(
        &self,
        command: &str,
        run: impl FnOnce(AnyDevice) -> F,
    ) -> anyhow::Result<ExitCode> {
        self.reach.recording(&self.address, command, run)
    }
}

impl ReachArgs {
    /// [`DeviceArgs::recording`] for the device at `address`.
    pub(crate) fn recording<F: Future<Output = anyhow::Result<AnyDevice>>>(
        &self,
        address: &DeviceAddress,
        command: &str,
        run: impl FnOnce(AnyDevice) -> F,
    ) -> anyhow::Result<ExitCode> {
        self.recording_with_links(address, command, |device, _| run(device))
    }

    /// As [`recording`](Self::recording), `run` also given the capture's links (`--record`) for
    /// links of its own.
    pub(crate) fn recording_with_links<F: Future<Output = anyhow::Result<AnyDevice>>>(
        &self,
        address: &DeviceAddress,
        command: &str,
        run: impl FnOnce(AnyDevice, Option<RecordLinks>) -> F,
    ) -> anyhow::Result<ExitCode> {
        let taps = self.record.start(&format!("{command} {address}"))?;
        let links = || taps.links();
        let ran = runtime()?.block_on(async {
            let device = run(self.open(address, links()).await?, links()).await?;
            eprintln!("{}", device.stats_line());
            device.close().context("closing the device")
        });
        // The device is closed (or never opened): the capture holds all it saw.
        taps.finish()?;
        ran.map(|()| ExitCode::SUCCESS)
    }

    /// Every device at `addresses` opened and waited for, its links streamed live (`--live`,
    /// 127.0.0.1:8765 unless given) and recorded with `--record`; handed to `run`, then each
    /// device's statistics printed and all closed.
    pub(crate) fn serving<F: Future<Output = anyhow::Result<Vec<AnyDevice>>>>(
        &self,
        addresses: &[DeviceAddress],
        run: impl FnOnce(Vec<AnyDevice>) -> F,
    ) -> anyhow::Result<ExitCode> {
        let mut record = self.record.clone();
        if record.live.live.is_none() {
            record.live.live = Some(crate::cmd::taps::DEFAULT_LIVE.parse()?);
        }
        let taps = record.start("robowire serve")?;
        let ran = runtime()?.block_on(async {
            let mut devices = Vec::new();
            for address in addresses {
                devices.push(self.open(address, taps.links()).await?);
            }
            eprintln!("serving {} device(s); Ctrl-C stops", devices.len());
            for device in run(devices).await? {
                eprintln!("{}", device.stats_line());
                device.close().context("closing the device")?;
            }
            Ok::<(), anyhow::Error>(())
        });
        taps.finish()?;
        ran.map(|()| ExitCode::SUCCESS)
    }

    /// Opens the device at `address`, its links recorded with `record` if given, and waits for
    /// its first state.
    async fn open(&self, address: &DeviceAddress, record: Option<RecordLinks>) -> anyhow::Result<AnyDevice> {
        let timeout = crate::cmd::seconds("--connect-timeout-s", self.connect_timeout_s)?;
        let options = OpenOptions {
            domain: self.domain,
            zsl_local: self.local,
            record,
            sim_physics: self.body.options(),
            ..OpenOptions::default()
        };
        let device = robowire_devices::open(address, &options).with_context(|| format!("opening {address}"))?;
        if !device.wait_state(timeout).await {
            anyhow::bail!("no state from {address} within {:.1} s: {}", timeout.as_secs_f64(), what_to_check(address));
        }
        Ok(device)
    }
}

/// What to check when a device is silent.
fn what_to_check(address: &DeviceAddress) -> &'static str {
    match address {
        DeviceAddress::Kmc(_) => "is the chassis powered and this its serial port?",
        DeviceAddress::Zsl1(_) | DeviceAddress::Zsl1w(_) => {
            "is the robot on, and is its target_ip/target_port (sdk_config.yaml) this host's address, port 43988?"
        }
        DeviceAddress::Go2(_) | DeviceAddress::Hg(_) | DeviceAddress::G1(_) => {
            "is the robot on, and is this the interface of its network (192.168.123.x)?"
        }
        DeviceAddress::Spline(_) => "is the spline daemon running (and publishing)?",
        DeviceAddress::Sim(_) => "the simulator did not start sending",
    }
}

/// Runs `command` where `lo` carries multicast when `loopback` says how (a `sim:` DDS device);
/// else here.
pub(crate) fn on_loopback(
    loopback: Option<robowire_dds::netns::Loopback>,
    command: impl FnOnce() -> anyhow::Result<ExitCode> + Send,
) -> anyhow::Result<ExitCode> {
    match loopback {
        None => command(),
        Some(loopback) => loopback
            .run(command)
            .context("a simulated DDS device and its client meet on loopback, which needs multicast here")?,
    }
}

fn runtime() -> anyhow::Result<tokio::runtime::Runtime> {
    Ok(tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?)
}

/// `robowire status ADDRESS`: one state.
pub(crate) fn status(args: &StatusArgs) -> anyhow::Result<ExitCode> {
    args.device.recording("robowire status", |device| async move {
        if args.json {
            let state = device.status_json().context("no state")?;
            println!("{}", serde_json::to_string_pretty(&state)?);
        } else {
            println!("{}", device.status_text().context("no state")?);
        }
        Ok(device)
    })
}

/// `robowire watch ADDRESS`: the state ten times a second and every connection change, until
/// Ctrl-C.
pub(crate) fn watch(args: &DeviceArgs) -> anyhow::Result<ExitCode> {
    args.recording("robowire watch", |device| async move {
        crate::cmd::watch_loop::watch_until_ctrl_c(device.connection_events(), || device.status_line()).await?;
        Ok(device)
    })
}
