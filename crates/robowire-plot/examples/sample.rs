//! Renders a sample recording's plots (two devices) to the file named by the first argument,
//! `.svg` or `.png`: `cargo run -p robowire-plot --example sample -- target/plot-sample.png`.

use robowire_plot::{Marker, MarkerKind, Page, Panel, Series, Style, render};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args_os().nth(1).ok_or("usage: sample OUT.svg|OUT.png")?;
    render(&[chassis(), dog()], std::path::Path::new(&out))?;
    Ok(())
}

fn times(rate_hz: f64, duration_s: f64) -> impl Iterator<Item = f64> {
    (0..(rate_hz * duration_s) as u32).map(move |i| f64::from(i) / rate_hz)
}

fn chassis() -> Page {
    let commanded = |t: f64| match t {
        t if t < 2.0 => 0.0,
        t if t < 8.0 => 0.8,
        t if t < 12.0 => 0.3,
        _ => 0.0,
    };
    let mut observed = 0.0;
    // No state while the link was silent.
    let observed: Vec<(f64, f64)> = times(50.0, 20.0)
        .map(|t| {
            observed += (commanded(t) - observed) * 0.08;
            (t, observed + 0.01 * (t * 13.0).sin())
        })
        .filter(|&(t, _)| !(9.0..10.5).contains(&t))
        .collect();
    Page {
        title: "kmc:/dev/ttyUSB0".into(),
        panels: vec![
            Panel {
                title: "forward velocity".into(),
                y_label: "velocity (m/s)".into(),
                series: vec![
                    Series {
                        name: "commanded".into(),
                        points: [0.0, 2.0, 8.0, 12.0, 20.0].iter().map(|&t| (t, commanded(t))).collect(),
                        style: Style::Step,
                    },
                    Series { name: "observed".into(), points: observed, style: Style::Line },
                ],
            },
            Panel {
                title: "send loop lateness".into(),
                y_label: "lateness (ms)".into(),
                series: vec![Series {
                    name: "command send".into(),
                    points: times(50.0, 20.0)
                        .map(|t| {
                            (t, 0.05 + 0.04 * (t * 7.1).sin().abs() + if (t - 4.0).abs() < 0.03 { 2.4 } else { 0.0 })
                        })
                        .collect(),
                    style: Style::Dots,
                }],
            },
        ],
        markers: vec![
            Marker { time_s: 9.0, label: "no state for 200 ms".into(), kind: MarkerKind::Disconnect },
            Marker { time_s: 10.5, label: "reconnected".into(), kind: MarkerKind::Note },
        ],
    }
}

fn dog() -> Page {
    let joint = |phase: f64| {
        let target: Vec<(f64, f64)> = times(10.0, 10.0).map(|t| (t, 0.6 * (t + phase).sin())).collect();
        let angle: Vec<(f64, f64)> = times(500.0, 10.0).map(|t| (t, 0.6 * (t - 0.08 + phase).sin())).collect();
        (angle, target)
    };
    let (hip_angle, hip_target) = joint(0.0);
    let (knee_angle, knee_target) = joint(1.5);
    Page {
        title: "go2:eth0".into(),
        panels: vec![
            Panel {
                title: "front right leg".into(),
                y_label: "angle (rad)".into(),
                series: vec![
                    Series { name: "hip angle".into(), points: hip_angle, style: Style::Line },
                    Series { name: "hip target".into(), points: hip_target, style: Style::Step },
                    Series { name: "knee angle".into(), points: knee_angle, style: Style::Line },
                    Series { name: "knee target".into(), points: knee_target, style: Style::Step },
                ],
            },
            Panel {
                title: "rates".into(),
                y_label: "rate (Hz)".into(),
                series: vec![
                    Series {
                        name: "LowState received".into(),
                        points: times(2.0, 10.0).map(|t| (t, if t > 6.0 && t < 7.0 { 310.0 } else { 500.0 })).collect(),
                        style: Style::Step,
                    },
                    Series {
                        name: "LowCmd sent".into(),
                        points: times(2.0, 10.5).map(|t| (t, 498.0)).collect(),
                        style: Style::Step,
                    },
                ],
            },
        ],
        markers: vec![Marker { time_s: 6.2, label: "motor 4 over temperature".into(), kind: MarkerKind::Fault }],
    }
}
