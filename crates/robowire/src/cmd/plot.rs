//! `robowire plot FILE.mcap --out FILE.svg|FILE.png`: one page per device of a capture, with the
//! series each codec describes for its links (`LinkPlots`: commanded against observed), each
//! link's frame rates and send intervals, and its faults (frames that do not decode, line noise)
//! and silences marked. Knows no device: what to draw comes from the codecs.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use robowire_core::Direction;
use robowire_core::json::{JsonFrame, LinkPlots};
use robowire_plot::{Marker, MarkerKind, Page, Panel, Series, Style};
use robowire_record::RecordedFrame;

#[derive(Debug, Args)]
pub(crate) struct PlotArgs {
    /// The capture (`--record FILE.mcap` of another command).
    file: PathBuf,
    /// The image to write: .svg or .png (one page per device, stacked).
    #[arg(long, value_name = "FILE.svg|FILE.png")]
    out: PathBuf,
    /// Only this device (the first part of its links' names: kmc, zsl1, go2, spline, …).
    #[arg(long)]
    device: Option<String>,
    /// Seconds from the capture's first frame to start at.
    #[arg(long = "from", value_name = "S")]
    from_s: Option<f64>,
    /// Seconds from the capture's first frame to end at.
    #[arg(long = "to", value_name = "S")]
    to_s: Option<f64>,
}

/// Which frames to draw: one device, a time window (s from the capture's first frame).
#[derive(Debug, Clone, Default)]
pub(crate) struct Selection {
    pub(crate) device: Option<String>,
    pub(crate) from_s: Option<f64>,
    pub(crate) to_s: Option<f64>,
}

pub(crate) fn run(args: &PlotArgs) -> anyhow::Result<ExitCode> {
    for (name, value) in [("--from", args.from_s), ("--to", args.to_s)] {
        anyhow::ensure!(value.is_none_or(|s| s.is_finite() && s >= 0.0), "{name} must be seconds ≥ 0, got {value:?}");
    }
    if let (Some(from), Some(to)) = (args.from_s, args.to_s) {
        anyhow::ensure!(from < to, "--from {from} s is not before --to {to} s");
    }
    let selection = Selection { device: args.device.clone(), from_s: args.from_s, to_s: args.to_s };
    let pages = plot_capture(&args.file, &args.out, &selection)?;
    if pages.is_empty() {
        let bytes = std::fs::read(&args.file)?;
        let frames = robowire_record::read_frames(&bytes, &crate::cmd::captures::descriptions())?;
        let devices: Vec<&str> = devices(&frames).into_keys().collect();
        anyhow::bail!(
            "nothing to plot: the capture's devices are {devices:?}, and none has frames in the window asked for"
        );
    }
    println!("{}: {} page{} ({})", args.out.display(), pages.len(), if pages.len() == 1 { "" } else { "s" }, {
        pages.join(", ")
    });
    Ok(ExitCode::SUCCESS)
}

/// Draws the capture at `file` into `out`; the devices drawn (none: nothing was written).
pub(crate) fn plot_capture(file: &Path, out: &Path, selection: &Selection) -> anyhow::Result<Vec<String>> {
    let bytes = std::fs::read(file).with_context(|| format!("reading {}", file.display()))?;
    let frames = robowire_record::read_frames(&bytes, &crate::cmd::captures::descriptions())
        .with_context(|| format!("{}", file.display()))?;
    let title = file.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let pages = pages(&frames, &title, selection);
    if pages.is_empty() {
        return Ok(Vec::new());
    }
    robowire_plot::render(&pages, out).with_context(|| format!("drawing {}", out.display()))?;
    Ok(pages.into_iter().map(|p| p.title.split(' ').next().unwrap_or_default().to_string()).collect())
}

/// The frames of each device: the first part of their links' names, under the device's current
/// name (an old capture's `dog/…` links are the `zsl1` device's).
fn devices(frames: &[RecordedFrame]) -> BTreeMap<&str, Vec<&RecordedFrame>> {
    let mut devices: BTreeMap<&str, Vec<&RecordedFrame>> = BTreeMap::new();
    for frame in frames {
        devices.entry(crate::cmd::captures::device_of(&frame.link)).or_default().push(frame);
    }
    devices
}

/// A page per device with frames in the selection.
pub(crate) fn pages(frames: &[RecordedFrame], capture: &str, selection: &Selection) -> Vec<Page> {
    let Some(start_ns) = frames.iter().map(|f| f.unix_ns).min() else { return Vec::new() };
    let seconds = |f: &RecordedFrame| f.unix_ns.saturating_sub(start_ns) as f64 / 1e9;
    let inside = |t: f64| selection.from_s.is_none_or(|from| t >= from) && selection.to_s.is_none_or(|to| t <= to);
    let plots = crate::cmd::captures::link_plots();
    let mut pages = Vec::new();
    for (device, frames) in devices(frames) {
        if selection.device.as_deref().is_some_and(|d| crate::cmd::captures::current_device(d) != device) {
            continue;
        }
        let mut links: BTreeMap<&str, Vec<(f64, &RecordedFrame)>> = BTreeMap::new();
        for frame in frames {
            let t = seconds(frame);
            if inside(t) {
                links.entry(frame.link.as_str()).or_default().push((t, frame));
            }
        }
        if links.is_empty() {
            continue;
        }
        let mut page = Page {
            title: format!("{device} ({}) — {capture}", links.keys().copied().collect::<Vec<_>>().join(", ")),
            panels: Vec::new(),
            markers: Vec::new(),
        };
        for (link, frames) in &links {
            draw_link(&mut page, link, frames, &plots);
        }
        if !page.panels.is_empty() {
            pages.push(page);
        }
    }
    pages
}

/// A link's panels and markers onto `page`.
fn draw_link(page: &mut Page, link: &str, frames: &[(f64, &RecordedFrame)], plots: &[&LinkPlots]) {
    let Some((_, first)) = frames.first() else { return };
    let protocol = first.protocol.protocol();
    if protocol == robowire_core::json::SKIPPED_BYTES.name {
        for (t, frame) in frames {
            page.markers.push(marker(*t, format!("line noise: {} B skipped", frame.bytes.len()), MarkerKind::Fault));
        }
        return;
    }
    let decoded: Vec<(f64, Direction, Option<JsonFrame>)> =
        frames.iter().map(|(t, f)| (*t, f.direction, f.decode().ok())).collect();
    page.markers.extend(errors(link, &decoded));
    page.markers.extend(silences(link, frames));
    if let Some(plots) = plots.iter().find(|p| p.protocol == protocol) {
        for spec in plots.panels {
            let series = spec
                .series
                .iter()
                .map(|s| Series {
                    name: s.name.into(),
                    points: decoded
                        .iter()
                        .filter(|(_, direction, _)| *direction == s.direction)
                        .filter_map(|(t, _, json)| Some((*t, s.value(json.as_ref()?)?)))
                        .collect(),
                    style: if s.held { Style::Step } else { Style::Line },
                })
                .collect();
            page.panels.push(Panel { title: format!("{link}: {}", spec.title), y_label: spec.y_label.into(), series });
        }
    }
    page.panels.extend(traffic_panels(link, &decoded));
}

fn marker(time_s: f64, label: String, kind: MarkerKind) -> Marker {
    Marker { time_s, label, kind }
}

/// Frames that did not decode (a CRC failure, a frame of the wrong length), one marker per run
/// of them within 100 ms.
fn errors(link: &str, decoded: &[(f64, Direction, Option<JsonFrame>)]) -> Vec<Marker> {
    let mut markers: Vec<(f64, f64, usize)> = Vec::new();
    for (t, _, json) in decoded {
        if json.is_some() {
            continue;
        }
        match markers.last_mut() {
            Some((_, last, count)) if t - *last < 0.1 => {
                *last = *t;
                *count += 1;
            }
            _ => markers.push((*t, *t, 1)),
        }
    }
    markers
        .into_iter()
        .map(|(t, _, n)| {
            marker(t, format!("{link}: {n} frame{} not decodable", if n == 1 { "" } else { "s" }), MarkerKind::Fault)
        })
        .collect()
}

/// Received frames stopping for ten times their usual interval (and at least 100 ms): marked
/// where the silence began.
fn silences(link: &str, frames: &[(f64, &RecordedFrame)]) -> Vec<Marker> {
    let received: Vec<f64> =
        frames.iter().filter(|(_, f)| f.direction == Direction::Received).map(|(t, _)| *t).collect();
    let mut gaps: Vec<f64> = received.windows(2).map(|w| w[1] - w[0]).collect();
    if gaps.len() < 10 {
        return Vec::new();
    }
    let mut sorted = gaps.clone();
    sorted.sort_by(f64::total_cmp);
    let bound = (sorted[sorted.len() / 2] * 10.0).max(0.1);
    gaps.iter_mut()
        .zip(&received)
        .filter(|(gap, _)| **gap > bound)
        .map(|(gap, t)| marker(*t, format!("{link}: silent {:.0} ms", *gap * 1e3), MarkerKind::Disconnect))
        .collect()
}

/// A link's frame rates each way and, per message type it sent at least 10 of, the intervals
/// between them (a periodic stream's lateness shows as their spread).
fn traffic_panels(link: &str, decoded: &[(f64, Direction, Option<JsonFrame>)]) -> Vec<Panel> {
    const BIN_S: f64 = 0.1;
    let times = |direction: Direction| -> Vec<f64> {
        decoded.iter().filter(|(_, d, _)| *d == direction).map(|(t, _, _)| *t).collect()
    };
    let (sent, received) = (times(Direction::Sent), times(Direction::Received));
    if sent.len().max(received.len()) < 10 {
        return Vec::new();
    }
    // Every bin from the link's first frame to its last, empty ones (a silence) too.
    let bin = |t: f64| (t / BIN_S).floor() as i64;
    let span = decoded.first().zip(decoded.last()).map_or((0, 0), |(a, b)| (bin(a.0), bin(b.0)));
    let rate = |name: &str, times: &[f64]| {
        let mut counts: BTreeMap<i64, u32> = (span.0..=span.1).map(|b| (b, 0)).collect();
        for t in times {
            *counts.entry(bin(*t)).or_default() += 1;
        }
        let points = counts.into_iter().map(|(b, n)| ((b as f64 + 0.5) * BIN_S, f64::from(n) / BIN_S)).collect();
        Series { name: name.into(), points, style: Style::Line }
    };
    let mut panels = vec![Panel {
        title: format!("{link}: frame rate (100 ms bins)"),
        y_label: "rate (frames/s)".into(),
        series: vec![rate("sent", &sent), rate("received", &received)],
    }];
    let mut by_type: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    for (t, _, json) in decoded.iter().filter(|(_, d, _)| *d == Direction::Sent) {
        if let Some(json) = json {
            by_type.entry(json.schema).or_default().push(*t);
        }
    }
    let intervals: Vec<Series> = by_type
        .into_iter()
        .filter(|(_, times)| times.len() >= 10)
        .map(|(schema, times)| Series {
            name: schema.into(),
            points: times.windows(2).map(|w| (w[1], (w[1] - w[0]) * 1e3)).collect(),
            style: Style::Dots,
        })
        .collect();
    if !intervals.is_empty() {
        panels.push(Panel {
            title: format!("{link}: interval between messages sent, by type (the loop's lateness is their spread)"),
            y_label: "interval (ms)".into(),
            series: intervals,
        });
    }
    panels
}
