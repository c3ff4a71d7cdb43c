//! `--record FILE.mcap` for the commands that have it, and `robowire replay`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Args;
use robowire_record::{Compression, Recorder, RecorderOptions};

use crate::cmd::captures::descriptions;
use crate::cmd::taps::Taps;

/// `--record FILE.mcap` and `--live [ADDR]`, for the commands that open a device.
#[derive(Debug, Clone, Args)]
pub(crate) struct RecordArgs {
    /// Record every frame of the device's links, both ways, to this MCAP file (Foxglove opens
    /// it; `robowire replay`, `decode --mcap` and `plot` read it).
    #[arg(long, value_name = "FILE.mcap")]
    pub(crate) record: Option<PathBuf>,
    /// How the capture's chunks are compressed (zstd: about 12 times smaller, at some CPU).
    #[arg(long, value_enum, default_value_t = CompressionArg::None, requires = "record")]
    pub(crate) compression: CompressionArg,
    #[command(flatten)]
    pub(crate) live: crate::cmd::taps::LiveArgs,
}

/// `--compression`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum CompressionArg {
    None,
    Zstd,
    Lz4,
}

impl RecordArgs {
    /// The recorder and the live view, each if asked for; `command` names what records in the
    /// capture's metadata and what serves in the live view.
    pub(crate) fn start(&self, command: &str) -> anyhow::Result<Taps> {
        let recorder = start_with(self.record.as_deref(), command, self.compression)?;
        Ok(Taps { recorder, live: self.live.start(command)? })
    }

    /// As [`start`](Self::start), a capture of ROS 2 topics only: the `ros2` profile, no JSON,
    /// nothing but frames in a wire encoding, so that ROS 2 tools read all of it.
    pub(crate) fn start_ros2(&self, command: &str) -> anyhow::Result<Option<Recorder>> {
        let options = RecorderOptions {
            compression: self.compression.into(),
            profile: "ros2",
            json: false,
            wire_only: true,
            ..RecorderOptions::default()
        };
        create(self.record.as_deref(), command, options)
    }

    /// The same arguments for a second file beside the first: `run.mcap` → `run-{suffix}.mcap`.
    pub(crate) fn beside(&self, suffix: &str) -> Self {
        let record = self.record.as_ref().map(|path| {
            let stem = path.file_stem().map_or_else(|| "capture".into(), |s| s.to_string_lossy().into_owned());
            let extension = path.extension().map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
            path.with_file_name(format!("{stem}-{suffix}{extension}"))
        });
        Self { record, ..self.clone() }
    }
}

impl From<CompressionArg> for Compression {
    fn from(arg: CompressionArg) -> Self {
        match arg {
            CompressionArg::None => Compression::None,
            CompressionArg::Zstd => Compression::Zstd,
            CompressionArg::Lz4 => Compression::Lz4,
        }
    }
}

/// A recorder on `path`, if given, its chunks compressed with `compression`.
pub(crate) fn start_with(
    path: Option<&Path>,
    command: &str,
    compression: CompressionArg,
) -> anyhow::Result<Option<Recorder>> {
    create(path, command, RecorderOptions { compression: compression.into(), ..RecorderOptions::default() })
}

fn create(path: Option<&Path>, command: &str, options: RecorderOptions) -> anyhow::Result<Option<Recorder>> {
    path.map(|p| Recorder::create_with(p, command, options).with_context(|| format!("recording to {}", p.display())))
        .transpose()
}

#[derive(Debug, Args)]
pub(crate) struct ReplayArgs {
    /// The capture (`--record FILE.mcap` of another command).
    file: PathBuf,
    /// Playback speed: 2 is twice as fast as recorded.
    #[arg(long, default_value_t = 1.0, conflicts_with = "fast")]
    speed: f64,
    /// As fast as possible.
    #[arg(long)]
    fast: bool,
    /// One JSON object per frame on stdout.
    #[arg(long)]
    json: bool,
    /// Play the device's side of the capture to a live client instead, on the transport of the
    /// link's protocol: ZSL-1 states on UDP (the HighLevel or LowLevel port of --bind), KMC
    /// chassis frames on a pseudo-terminal (its path the first line), Go2 LowStates on DDS
    /// rt/lowstate (--interface, --domain), the spline daemon's states and IMU records on shared
    /// memory (--spline-name, --imu-name).
    #[arg(long)]
    as_device: bool,
    /// With --as-device on a ZSL-1 link: the address to serve on.
    #[arg(long, default_value = "127.0.0.1", requires = "as_device")]
    bind: std::net::IpAddr,
    /// With --as-device: the link to play (default: the link of the first device frame).
    #[arg(long, requires = "as_device")]
    link: Option<String>,
    /// With --as-device on a Go2 link: where to publish.
    #[command(flatten)]
    dds: crate::cmd::dds_args::DdsArgs,
    /// With --as-device on a spline link: the spline object to create (the robot's name).
    #[arg(long, default_value = "/spline_shm", requires = "as_device")]
    spline_name: String,
    /// With --as-device on a spline link: the IMU object to create (the robot's name).
    #[arg(long, default_value = "/imu_shm", requires = "as_device")]
    imu_name: String,
    /// The capture played to a live view at --speed.
    #[command(flatten)]
    live: crate::cmd::taps::LiveArgs,
}

/// Replays a capture into the decoders, at the recorded pace (or `--speed`, or `--fast`).
pub(crate) fn replay(args: &ReplayArgs) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        args.speed.is_finite() && args.speed > 0.0 && args.speed <= 1e6,
        "--speed must be in (0, 1e6], got {}",
        args.speed
    );
    let bytes = std::fs::read(&args.file).with_context(|| format!("reading {}", args.file.display()))?;
    let frames =
        robowire_record::read_frames(&bytes, &descriptions()).with_context(|| format!("{}", args.file.display()))?;
    anyhow::ensure!(
        !(args.as_device && args.live.live.is_some()),
        "--live plays the capture to a live view; with --as-device, look at the client's own --live"
    );
    if args.as_device {
        let target = crate::cmd::replay_device::Target {
            link: args.link.as_deref(),
            bind: args.bind,
            dds: &args.dds,
            shm: (&args.spline_name, &args.imu_name),
            speed: (!args.fast).then_some(args.speed),
        };
        return crate::cmd::replay_device::run(&frames, &target);
    }
    let Some(first) = frames.first().map(|f| f.unix_ns) else {
        eprintln!("{}: no frames", args.file.display());
        return Ok(ExitCode::SUCCESS);
    };
    let live = args.live.start("robowire replay")?;
    let mut taps = std::collections::HashMap::new();
    let started = Instant::now();
    let mut errors = 0u64;
    for frame in &frames {
        let offset_ns = frame.unix_ns.saturating_sub(first);
        if !args.fast {
            let due = Duration::from_nanos((offset_ns as f64 / args.speed) as u64);
            if let Some(wait) = due.checked_sub(started.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        if let Some(live) = &live {
            let tap = taps.entry(frame.link.as_str()).or_insert_with(|| live.links().link(&frame.link, frame.protocol));
            tap.record(frame.direction, &frame.bytes);
        }
        let t = offset_ns as f64 / 1e9;
        let direction = frame.direction.name();
        match frame.decode() {
            Ok(m) if args.json => println!(
                "{}",
                serde_json::json!({ "t_s": t, "link": frame.link, "direction": direction, "message": m.schema, "value": m.value })
            ),
            Ok(m) => println!("{t:10.6} {} {direction:8} {}: {}", frame.link, m.schema, m.value),
            Err(e) => {
                errors += 1;
                eprintln!("{t:10.6} {} {direction:8} {:#}", frame.link, anyhow::Error::from(e));
            }
        }
    }
    eprintln!("replay: {} frames, {errors} not decodable", frames.len());
    Taps { recorder: None, live }.finish()?;
    Ok(ExitCode::SUCCESS)
}

/// `robowire decode --mcap FILE`: channels, counts, rates, gaps, decode errors.
pub(crate) fn summarize(path: &Path, json: bool) -> anyhow::Result<ExitCode> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    let summary = robowire_record::summarize(&bytes, &descriptions()).with_context(|| format!("{}", path.display()))?;
    if json {
        let channels: Vec<_> = summary
            .channels
            .iter()
            .map(|c| {
                serde_json::json!({
                    "topic": c.topic, "encoding": c.encoding, "count": c.count, "rate_hz": c.rate_hz,
                    "first_ns": c.span_ns.0, "last_ns": c.span_ns.1, "max_gap_ns": c.max_gap_ns,
                    "out_of_order": c.out_of_order, "decode_errors": c.decode_errors,
                })
            })
            .collect();
        println!("{}", serde_json::json!({ "metadata": summary.metadata, "channels": channels }));
        return Ok(ExitCode::SUCCESS);
    }
    for (key, value) in &summary.metadata {
        println!("{key}: {value}");
    }
    println!(
        "{:<36} {:>12} {:>8} {:>9} {:>11} {:>6} {:>7}",
        "channel", "encoding", "count", "rate Hz", "max gap ms", "order", "errors"
    );
    for c in &summary.channels {
        println!(
            "{:<36} {:>12} {:>8} {:>9.1} {:>11.2} {:>6} {:>7}",
            c.topic,
            c.encoding,
            c.count,
            c.rate_hz,
            c.max_gap_ns as f64 / 1e6,
            c.out_of_order,
            c.decode_errors
        );
    }
    Ok(ExitCode::SUCCESS)
}
