//! Rendering pages to SVG and PNG: the text a reader needs is there, the image decodes, bad
//! input is a typed error and odd series never panic.

use std::path::Path;

use proptest::prelude::*;
use robowire_plot::{Marker, MarkerKind, Page, Panel, PlotError, Series, Style, render, render_png, render_svg};

fn series(name: &str, points: Vec<(f64, f64)>, style: Style) -> Series {
    Series { name: name.into(), points, style }
}

fn panel(title: &str, y_label: &str, series: Vec<Series>) -> Panel {
    Panel { title: title.into(), y_label: y_label.into(), series }
}

/// A sine and the step-held target it follows, the joint's angle over its lateness, one marker
/// of each kind.
fn two_panel_page() -> Page {
    let sine = (0..=1000).map(|i| f64::from(i) * 0.01).map(|t| (t, t.sin())).collect();
    let target = (0..=10).map(f64::from).map(|t| (t, (t + 0.5).sin())).collect();
    let lateness = (0..=100).map(|i| (f64::from(i) * 0.1, f64::from(i % 7) * 0.05)).collect();
    Page {
        title: "sim:go2".into(),
        panels: vec![
            panel(
                "front right hip",
                "angle (rad)",
                vec![series("hip angle", sine, Style::Line), series("hip target", target, Style::Step)],
            ),
            panel("control loop", "lateness (ms)", vec![series("send lateness", lateness, Style::Dots)]),
        ],
        markers: vec![
            Marker { time_s: 2.0, label: "motor 3 overheated".into(), kind: MarkerKind::Fault },
            Marker { time_s: 5.0, label: "no state for 200 ms".into(), kind: MarkerKind::Disconnect },
            Marker { time_s: 7.5, label: "stand up".into(), kind: MarkerKind::Note },
        ],
    }
}

fn decode(png: &[u8]) -> (png::OutputInfo, Vec<u8>) {
    let mut reader = png::Decoder::new(std::io::Cursor::new(png)).read_info().expect("a PNG header");
    let mut pixels = vec![0; reader.output_buffer_size().expect("a buffer size")];
    let info = reader.next_frame(&mut pixels).expect("a PNG frame");
    pixels.truncate(info.buffer_size());
    (info, pixels)
}

#[test]
fn the_svg_has_the_titles_units_legend_and_marker_labels_as_text() {
    let svg = render_svg(&[two_panel_page()]).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(80)]);
    for text in [
        "sim:go2",
        "front right hip",
        "control loop",
        "angle (rad)",
        "lateness (ms)",
        "time (s)",
        "hip angle",
        "hip target",
        "send lateness",
        "motor 3 overheated",
        "no state for 200 ms",
        "stand up",
        "fault",
        "disconnect",
        "note",
    ] {
        assert!(svg.contains(&format!(">\n{text}\n<")), "no text {text:?} in the SVG");
    }
    assert!(svg.contains("width=\"1200\""), "not 1200 px wide");
}

#[test]
fn the_png_decodes_with_the_layout_size_and_shows_series_and_markers() {
    let png = render_png(&[two_panel_page()]).unwrap();
    let (info, pixels) = decode(&png);
    assert_eq!((info.width, info.height), (1200, 52 + 2 * 260 + 24));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    let colours: std::collections::BTreeSet<[u8; 3]> = pixels.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    assert!(colours.len() > 50, "only {} colours", colours.len());
    for (what, colour) in [("the first series' blue", [31, 119, 180]), ("the fault's red", [214, 39, 40])] {
        assert!(colours.contains(&colour), "no pixel of {what}");
    }
}

#[test]
fn pages_stack_one_under_the_other() {
    let mut second = two_panel_page();
    second.title = "sim:kmc".into();
    second.panels.push(panel("battery", "voltage (V)", vec![series("battery", vec![(0.0, 24.1)], Style::Line)]));
    let (info, _) = decode(&render_png(&[two_panel_page(), second]).unwrap());
    assert_eq!(info.height, (52 + 2 * 260 + 24) + (52 + 3 * 260 + 24));
    let svg = render_svg(&[two_panel_page(), second_page_titled("sim:kmc")]).unwrap();
    assert!(svg.contains(">\nsim:go2\n<") && svg.contains(">\nsim:kmc\n<"));
}

fn second_page_titled(title: &str) -> Page {
    Page { title: title.into(), ..two_panel_page() }
}

#[test]
fn render_picks_the_format_by_extension_and_writes_the_file() {
    let dir = std::env::temp_dir().join(format!("robowire-plot-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pages = [two_panel_page()];
    let svg = dir.join("plot.SVG");
    render(&pages, &svg).unwrap();
    assert!(std::fs::read_to_string(&svg).unwrap().contains(">\nhip target\n<"));
    let png = dir.join("plot.png");
    render(&pages, &png).unwrap();
    assert_eq!(decode(&std::fs::read(&png).unwrap()).0.width, 1200);

    let jpg = dir.join("plot.jpg");
    let error = render(&pages, &jpg).unwrap_err();
    assert!(matches!(&error, PlotError::UnknownExtension { path } if path == &jpg), "{error:?}");
    assert!(!jpg.exists(), "wrote a .jpg");
    assert!(matches!(render(&pages, Path::new("plot")), Err(PlotError::UnknownExtension { .. })));

    let missing = dir.join("no such directory").join("plot.svg");
    let error = render(&pages, &missing).unwrap_err();
    assert!(matches!(&error, PlotError::Write { path, .. } if path == &missing), "{error:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn no_page_or_a_page_without_panels_is_an_error() {
    assert!(matches!(render_svg(&[]), Err(PlotError::NoPages)));
    assert!(matches!(render_png(&[]), Err(PlotError::NoPages)));
    let empty = Page { title: "sim:zsl1".into(), panels: vec![], markers: vec![] };
    let error = render_png(&[two_panel_page(), empty.clone()]).unwrap_err();
    assert!(matches!(&error, PlotError::EmptyPage { index: 1, title } if title == "sim:zsl1"), "{error:?}");
    assert!(matches!(render_svg(&[empty]), Err(PlotError::EmptyPage { index: 0, .. })));
}

#[test]
fn more_panels_than_an_image_holds_is_an_error() {
    let page = Page { panels: vec![panel("p", "v (m)", vec![]); 200], ..two_panel_page() };
    let error = render_png(&[page]).unwrap_err();
    assert!(matches!(error, PlotError::TooLarge { panels: 200, .. }), "{error:?}");
}

#[test]
fn a_1_khz_ten_minute_series_renders() {
    let observed = (0..600_000).map(|i| f64::from(i) * 1e-3).map(|t| (t, (t * 3.0).sin() + (t * 0.01).cos())).collect();
    let page = Page {
        title: "sim:zsl1".into(),
        panels: vec![panel("body velocity", "velocity (m/s)", vec![series("observed", observed, Style::Step)])],
        markers: vec![],
    };
    let svg = render_svg(std::slice::from_ref(&page)).unwrap();
    // Two points a pixel column at most, not 1.2 million.
    assert!(svg.len() < 200_000, "{} bytes of SVG", svg.len());
    decode(&render_png(&[page]).unwrap());
}

#[test]
fn odd_series_and_markers_render() {
    let odd = vec![
        series("empty", vec![], Style::Line),
        series("one point", vec![(3.0, 1.0)], Style::Step),
        series("constant", vec![(0.0, 2.5), (1.0, 2.5), (2.0, 2.5)], Style::Line),
        series("not finite", vec![(f64::NAN, 1.0), (1.0, f64::INFINITY), (2.0, f64::NEG_INFINITY)], Style::Dots),
        series("huge", vec![(0.0, f64::MAX), (1.0, -1e300), (2.0, 1e300), (f64::MIN_POSITIVE, 5e-324)], Style::Line),
        series("backwards in time", vec![(5.0, 1.0), (1.0, 2.0), (3.0, 0.0)], Style::Step),
        series("a name far too long to fit in the legend column beside the panel, cut", vec![], Style::Dots),
    ];
    let markers = vec![
        Marker { time_s: f64::NAN, label: "never".into(), kind: MarkerKind::Fault },
        Marker { time_s: 1e6, label: "far later".into(), kind: MarkerKind::Disconnect },
        Marker { time_s: 1.0, label: "<&>\"".into(), kind: MarkerKind::Note },
    ];
    let pages = [
        Page { title: "odd".into(), panels: vec![panel("odd series", "value (1)", odd)], markers },
        Page {
            title: String::new(),
            panels: vec![
                panel("", "", vec![]),
                panel("only NaN", "x", vec![series("nan", vec![(f64::NAN, f64::NAN)], Style::Line)]),
            ],
            markers: vec![],
        },
    ];
    let svg = render_svg(&pages).unwrap();
    assert!(svg.contains("&lt;&amp;&gt;"), "the marker label is not escaped");
    assert!(svg.contains(">\nno data\n<"));
    assert!(!svg.contains(">\nnever\n<"), "a marker at NaN was drawn");
    decode(&render_png(&pages).unwrap());
}

#[test]
fn a_line_of_one_point_shows_as_a_dot() {
    let page = Page {
        title: "one".into(),
        panels: vec![panel("battery", "voltage (V)", vec![series("battery", vec![(1.0, 24.1)], Style::Line)])],
        markers: vec![],
    };
    let (_, pixels) = decode(&render_png(&[page]).unwrap());
    // Beyond the legend's swatch (right of x = 970), the series' blue is the dot.
    let blue_in_plot =
        pixels.chunks_exact(3).enumerate().filter(|(i, p)| i % 1200 < 960 && p == &[31, 119, 180]).count();
    assert!(blue_in_plot > 5, "{blue_in_plot} blue pixels in the plot");
}

/// A coordinate that is mostly ordinary, sometimes not finite, huge or tiny.
fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => -100.0..100.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => proptest::num::f64::ANY,
        1 => Just(0.0),
        1 => Just(1e-310),
    ]
}

fn any_series() -> impl Strategy<Value = Series> {
    let style = prop_oneof![Just(Style::Line), Just(Style::Step), Just(Style::Dots)];
    (proptest::collection::vec((coordinate(), coordinate()), 0..60), style)
        .prop_map(|(points, style)| series("s", points, style))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn any_series_renders_without_panic(
        panels in proptest::collection::vec(proptest::collection::vec(any_series(), 0..4), 1..3),
        marker_times in proptest::collection::vec(coordinate(), 0..4),
    ) {
        let panels = panels.into_iter().map(|s| panel("p", "v (1)", s)).collect();
        let markers = marker_times.into_iter().map(|time_s| Marker { time_s, label: "m".into(), kind: MarkerKind::Note }).collect();
        let pages = [Page { title: "random".into(), panels, markers }];
        prop_assert!(render_svg(&pages).is_ok());
        let (info, _) = decode(&render_png(&pages).unwrap());
        prop_assert_eq!(info.width, 1200);
    }
}
