//! One module per subcommand, as `robowire --help` lists them.

pub(crate) mod captures;
pub(crate) mod dds;
pub(crate) mod dds_args;
pub(crate) mod decode;
pub(crate) mod demo;
pub(crate) mod device;
pub(crate) mod doctor;
pub(crate) mod encode;
pub(crate) mod g1;
pub(crate) mod go2;
pub(crate) mod kmc;
pub(crate) mod plot;
pub(crate) mod policy;
pub(crate) mod record;
pub(crate) mod replay_device;
pub(crate) mod ros2;
pub(crate) mod serve;
pub(crate) mod shm;
pub(crate) mod sim;
pub(crate) mod sim_body;
pub(crate) mod sim_loop;
pub(crate) mod taps;
pub(crate) mod unitree;
pub(crate) mod watch_loop;
pub(crate) mod zsl1;

/// A duration argument in seconds, 0–3600.
pub(crate) fn seconds(name: &str, value: f64) -> anyhow::Result<std::time::Duration> {
    anyhow::ensure!(value.is_finite() && (0.0..=3600.0).contains(&value), "{name} must be 0–3600 s, got {value}");
    Ok(std::time::Duration::from_secs_f64(value))
}
