//! `robowire ros2`: every device as a ROS 2 node, on the wire, without a ROS installation.

use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context;
use clap::Args;
use robowire_ros2::{BridgeOptions, DeviceAddress, RosDistro};
use serde::Serialize;

#[derive(Debug, Args)]
pub(crate) struct Ros2Args {
    /// A device: kmc:/dev/ttyUSB0, zsl1:192.168.234.1, zsl1w:IP, go2:eth0, g1:eth0, or
    /// sim:kmc|zsl1|zsl1w|go2|g1 for a simulator. Repeat for several devices.
    #[arg(long = "device", required = true, value_name = "ADDRESS")]
    devices: Vec<DeviceAddress>,
    /// Namespace of the topics (several devices: NS/KIND INDEX each).
    #[arg(long)]
    namespace: Option<String>,
    /// DDS domain (ROS_DOMAIN_ID).
    #[arg(long, default_value_t = 0)]
    domain: u16,
    /// Network interface for DDS (e.g. eth0).
    #[arg(long)]
    interface: Option<String>,
    /// Let cmd_vel move the robots. Without it the bridge only publishes.
    #[arg(long)]
    arm: bool,
    /// Seconds after the last cmd_vel at which the robot is stopped.
    #[arg(long, default_value_t = 0.5)]
    deadman: f64,
    /// Publish each topic at most this often, Hz (default: the device's native rate).
    #[arg(long)]
    rate: Option<f64>,
    /// Stop after this many seconds (default: at Ctrl-C or SIGTERM).
    #[arg(long)]
    duration: Option<f64>,
    /// ROS 2 distribution of the peers: humble (24-byte GIDs in ros_discovery_info) or jazzy
    /// (16-byte GIDs: Iron and later). Default: $ROS_DISTRO (humble; iron, jazzy, kilted or
    /// rolling as jazzy), else jazzy.
    #[arg(long, value_name = "humble|jazzy")]
    ros_distro: Option<String>,
    /// At the end, print each device's counters as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Record the ROS 2 topics into FILE.mcap (rosbag2's MCAP: `ros2` profile, `cdr` under
    /// `ros2msg` definitions, on the ROS topics, nothing else: `ros2 bag play` plays it) and every
    /// device's own links beside it, into FILE-devices.mcap.
    #[command(flatten)]
    record: crate::cmd::record::RecordArgs,
    /// The body of the sim:go2 and sim:g1 devices: --physics [--model MJCF] [--free-base]
    /// (then every device must be one of them).
    #[command(flatten)]
    body: crate::cmd::sim_body::SimPhysicsArgs,
}

/// `--ros-distro`, else `$ROS_DISTRO`, else Jazzy.
fn ros_distro(flag: Option<&str>, env: Option<&str>) -> anyhow::Result<RosDistro> {
    match (flag, env) {
        (Some(name), _) => name.parse().context("--ros-distro"),
        (None, Some(name)) => RosDistro::of_environment(name).context("ROS_DISTRO (or give --ros-distro)"),
        (None, None) => Ok(RosDistro::default()),
    }
}

#[derive(Serialize)]
struct DeviceJson {
    device: String,
    namespace: String,
    #[serde(flatten)]
    counters: robowire_ros2::DeviceCounters,
}

pub(crate) fn run(args: Ros2Args) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.deadman.is_finite() && args.deadman > 0.0 && args.deadman <= 60.0,
        "--deadman must be in (0, 60] s, got {}",
        args.deadman
    );
    let duration = match args.duration {
        Some(s) if s.is_finite() && (0.0..=1e6).contains(&s) => Some(Duration::from_secs_f64(s)),
        Some(s) => anyhow::bail!("--duration must be 0–1e6 s, got {s}"),
        None => None,
    };
    let ros_distro = ros_distro(args.ros_distro.as_deref(), std::env::var("ROS_DISTRO").ok().as_deref())?;
    let recorder = args.record.start_ros2("robowire ros2")?;
    // The live view shows the devices' links (the ROS topics are what ROS tools show).
    let devices_taps = args.record.beside("devices").start("robowire ros2")?;
    let options = BridgeOptions {
        namespace: args.namespace.clone(),
        domain: args.domain,
        interface: args.interface.clone(),
        armed: args.arm,
        deadman: Duration::from_secs_f64(args.deadman),
        rate_cap_hz: args.rate,
        record: recorder.as_ref().map(robowire_record::Recorder::links),
        record_devices: devices_taps.links(),
        ros_distro,
        sim_physics: args.body.options(),
        ..BridgeOptions::new(args.devices.clone())
    };
    let runtime = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?;
    let devices = runtime.block_on(async {
        let (stop_tx, stop) = tokio::sync::watch::channel(false);
        let stopper = tokio::spawn(async move {
            let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
            let timeout = async {
                match duration {
                    Some(d) => tokio::time::sleep(d).await,
                    None => std::future::pending().await,
                }
            };
            tokio::select! {
                signal = tokio::signal::ctrl_c() => signal?,
                _ = term.recv() => {}
                () = timeout => {}
            }
            let _ = stop_tx.send(true);
            anyhow::Ok(())
        });
        let armed = if args.arm { "armed: cmd_vel moves the robots" } else { "not armed: publishing only" };
        let devices = robowire_ros2::run(options, stop, |devices| {
            for d in devices {
                let ns = if d.namespace.is_empty() { "/" } else { &d.namespace };
                eprintln!(
                    "ros2: {} as {ns} on domain {} (node {}/{})",
                    d.address,
                    args.domain,
                    ns.trim_end_matches('/'),
                    robowire_ros2::NODE_NAME
                );
            }
            eprintln!("ros2: ready ({armed}; ros_discovery_info for {ros_distro})");
        })
        .await
        .context("the ROS 2 bridge")?;
        stopper.abort();
        anyhow::Ok(devices)
    })?;
    let report: Vec<DeviceJson> = devices
        .iter()
        .map(|d| DeviceJson { device: d.address.to_string(), namespace: d.namespace.clone(), counters: d.counters() })
        .collect();
    for d in &report {
        let c = &d.counters;
        eprintln!(
            "ros2: {} published {} samples, answered {} service calls ({} malformed requests not answered); cmd_vel: {} received, {} applied, {} unarmed, {} invalid, {} refused, {} deadman stops, {} publishers",
            d.device,
            c.published,
            c.service_calls,
            c.malformed_requests,
            c.cmd_vel.received,
            c.cmd_vel.applied,
            c.cmd_vel.unarmed,
            c.cmd_vel.invalid,
            c.cmd_vel.refused,
            c.cmd_vel.deadman_stops,
            c.cmd_vel.publishers
        );
    }
    drop(devices);
    crate::cmd::taps::finish_recorder(recorder)?;
    devices_taps.finish()?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flag_wins_then_ros_distro_then_jazzy() {
        assert_eq!(ros_distro(Some("humble"), Some("jazzy")).unwrap(), RosDistro::Humble);
        assert_eq!(ros_distro(None, Some("humble")).unwrap(), RosDistro::Humble);
        assert_eq!(ros_distro(None, None).unwrap(), RosDistro::Jazzy);
        assert_eq!(ros_distro(None, Some("rolling")).unwrap(), RosDistro::Jazzy, "Iron and later: 16-byte GIDs");
        assert_eq!(ros_distro(None, Some("iron")).unwrap(), RosDistro::Jazzy);
        assert!(ros_distro(Some("rolling"), None).is_err(), "the flag names the layout: humble or jazzy");
        let unknown = ros_distro(None, Some("foxy")).unwrap_err();
        assert!(format!("{unknown:#}").contains("ROS_DISTRO") && format!("{unknown:#}").contains("\"foxy\""));
        assert!(ros_distro(Some("foxy"), Some("humble")).is_err());
    }
}
