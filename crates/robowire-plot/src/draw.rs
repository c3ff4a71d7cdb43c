//! Pages drawn on any plotters backend: a title band, then the panels over one time axis, each
//! with a legend column on its right and the page's markers across it.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::data::{axis_range, decimate, plottable, plottable_points, polyline};
use crate::font::FAMILY;
use crate::{Marker, MarkerKind, Page, Panel, Style};

/// The image's width.
pub(crate) const WIDTH_PX: u32 = 1200;
/// The band with a page's title.
const TITLE_PX: u32 = 52;
/// One panel: its title, plot and time ticks.
const PANEL_PX: u32 = 260;
/// Below a page's last panel: the time axis' label.
const TIME_LABEL_PX: u32 = 24;
/// The legend column right of each panel.
const LEGEND_PX: u32 = 230;
/// A legend row.
const LEGEND_ROW_PX: i32 = 20;
/// Room left and right of the page's recorded times, as a fraction of their span.
const TIME_PAD: f64 = 0.01;
/// Room above and below a panel's values, as a fraction of their span.
const VALUE_PAD: f64 = 0.05;

/// At most this many labelled ticks on a time axis.
const TIME_TICKS: usize = 12;
/// At most this many labelled ticks on a value axis.
const VALUE_TICKS: usize = 6;

/// Series colours, in the order of a panel's series; none is a marker's colour.
const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),  // blue
    RGBColor(44, 160, 44),   // green
    RGBColor(148, 103, 189), // purple
    RGBColor(140, 86, 75),   // brown
    RGBColor(23, 190, 207),  // cyan
    RGBColor(227, 119, 194), // pink
    RGBColor(188, 189, 34),  // olive
    RGBColor(0, 0, 0),       // black
];
const GRID_FINE: RGBColor = RGBColor(238, 238, 238);
const GRID_BOLD: RGBColor = RGBColor(210, 210, 210);
const TITLE_BAND: RGBColor = RGBColor(232, 236, 242);

type Drawn<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A page's height in the image.
pub(crate) fn page_height_px(page: &Page) -> u64 {
    u64::from(TITLE_PX) + page.panels.len() as u64 * u64::from(PANEL_PX) + u64::from(TIME_LABEL_PX)
}

/// Draws `pages` one under the other on `root`, which is `WIDTH_PX` wide and as tall as their
/// `page_height_px` together.
pub(crate) fn draw_pages<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, pages: &[Page]) -> Drawn<DB> {
    root.fill(&WHITE)?;
    let mut rest = root.clone();
    for page in pages {
        let (area, below) = rest.split_vertically(page_height_px(page) as u32);
        draw_page(&area, page)?;
        rest = below;
    }
    Ok(())
}

fn text(size: u32) -> TextStyle<'static> {
    TextStyle::from((FAMILY, size).into_font()).color(&BLACK)
}

fn bold(size: u32) -> TextStyle<'static> {
    TextStyle::from((FAMILY, size).into_font().style(FontStyle::Bold)).color(&BLACK)
}

fn draw_page<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, page: &Page) -> Drawn<DB> {
    let (title_area, mut rest) = area.split_vertically(TITLE_PX);
    title_area.fill(&TITLE_BAND)?;
    let title_style = bold(32).pos(Pos::new(HPos::Left, VPos::Center));
    title_area.draw_text(&page.title, &title_style, (16, TITLE_PX as i32 / 2))?;

    let times = page.panels.iter().flat_map(|p| &p.series).flat_map(|s| plottable_points(&s.points).map(|p| p.0));
    let time_range = axis_range(times.chain(page.markers.iter().map(|m| m.time_s)), TIME_PAD);
    let mut markers: Vec<&Marker> = page.markers.iter().filter(|m| plottable(m.time_s)).collect();
    markers.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    let mut kinds: Vec<MarkerKind> = markers.iter().map(|m| m.kind).collect();
    kinds.sort_by_key(|&k| k as u8);
    kinds.dedup();

    for (index, panel) in page.panels.iter().enumerate() {
        let last = index + 1 == page.panels.len();
        let (panel_area, below) = rest.split_vertically(PANEL_PX + if last { TIME_LABEL_PX } else { 0 });
        let (plot_area, legend_area) = panel_area.split_horizontally(WIDTH_PX - LEGEND_PX);
        draw_panel(&plot_area, panel, &markers, time_range, last)?;
        draw_legend(&legend_area, panel, &kinds)?;
        rest = below;
    }
    Ok(())
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    markers: &[&Marker],
    time_range: (f64, f64),
    last: bool,
) -> Drawn<DB> {
    let lines: Vec<Vec<(f64, f64)>> =
        panel.series.iter().map(|s| polyline(plottable_points(&s.points), s.style)).collect();
    let value_range = axis_range(lines.iter().flatten().map(|p| p.1), VALUE_PAD);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, bold(21))
        .margin_top(4)
        .margin_left(8)
        .margin_right(16)
        .x_label_area_size(26 + if last { TIME_LABEL_PX } else { 0 })
        .y_label_area_size(78)
        .build_cartesian_2d(time_range.0..time_range.1, value_range.0..value_range.1)?;
    let time_label = |t: &f64| tick_label(*t, time_range, TIME_TICKS);
    let value_label = |v: &f64| tick_label(*v, value_range, VALUE_TICKS);
    let mut mesh = chart.configure_mesh();
    mesh.y_desc(panel.y_label.as_str())
        .x_labels(TIME_TICKS)
        .y_labels(VALUE_TICKS)
        .x_label_formatter(&time_label)
        .y_label_formatter(&value_label)
        .label_style(text(15))
        .axis_desc_style(text(17))
        .light_line_style(GRID_FINE)
        .bold_line_style(GRID_BOLD);
    if last {
        mesh.x_desc("time (s)");
    }
    mesh.draw()?;

    let plot = chart.plotting_area();
    let columns = plot.dim_in_pixel().0 as usize;
    if lines.iter().all(Vec::is_empty) {
        let centered = text(18).color(&RGBColor(120, 120, 120)).pos(Pos::new(HPos::Center, VPos::Center));
        let middle = (time_range.0 / 2.0 + time_range.1 / 2.0, value_range.0 / 2.0 + value_range.1 / 2.0);
        plot.draw(&Text::new("no data", middle, centered))?;
    }
    for (index, (series, line)) in panel.series.iter().zip(lines).enumerate() {
        let colour = PALETTE[index % PALETTE.len()];
        let line = decimate(line, time_range, columns);
        // A line through one point would not show: it is a dot.
        match series.style {
            Style::Line | Style::Step if line.len() > 1 => {
                chart.draw_series(std::iter::once(PathElement::new(line, colour.stroke_width(2))))?;
            }
            Style::Line | Style::Step | Style::Dots => {
                chart.draw_series(line.into_iter().map(|p| Circle::new(p, 3, colour.filled())))?;
            }
        }
    }
    for marker in markers {
        let line = vec![(marker.time_s, value_range.1), (marker.time_s, value_range.0)];
        chart.draw_series(std::iter::once(PathElement::new(line, marker_style(marker.kind))))?;
    }
    // Each label right of its line near the top (left of it at the right edge), on a white
    // ground; successive markers' labels on three staggered rows.
    let origin = area.get_pixel_range();
    let plot_right = chart.plotting_area().get_pixel_range().0.end - origin.0.start;
    for (row, marker) in markers.iter().enumerate() {
        let colour = marker_colour(marker.kind);
        let label_style = text(14).color(&colour);
        let (width, height) = area.estimate_text_size(&marker.label, &label_style)?;
        let (width, height) = (width as i32, height as i32);
        let (x, y) = chart.backend_coord(&(marker.time_s, value_range.1));
        let (x, y) = (x - origin.0.start, y - origin.1.start);
        let left = if x + 4 + width > plot_right { x - 4 - width } else { x + 4 };
        let top = y + 3 + (row % 3) as i32 * (height + 5);
        let ground =
            Rectangle::new([(left - 2, top - 2), (left + width + 2, top + height + 2)], WHITE.mix(0.6).filled());
        area.draw(&ground)?;
        area.draw_text(&marker.label, &label_style, (left, top))?;
    }
    Ok(())
}

/// A tick's label on an axis over `range` with at most `ticks` ticks: the decimals of the tick
/// step plotters picks (`0`, `2.5`, `0.20`), more if this value needs them; scientific notation
/// from a million up or below a millionth.
fn tick_label(value: f64, range: (f64, f64), ticks: usize) -> String {
    let step = tick_step(range, ticks);
    let step_exponent = step.log10().floor();
    let value = if value.abs() < step * 1e-6 { 0.0 } else { value };
    let magnitude = value.abs();
    if magnitude >= 1e6 || (magnitude > 0.0 && magnitude < 1e-6) || step_exponent < -6.0 {
        let digits = (magnitude.log10().floor() - step_exponent).clamp(0.0, 15.0) as usize;
        return format!("{value:.digits$e}");
    }
    let mut decimals = (-step_exponent).clamp(0.0, 6.0) as i32;
    while decimals < 9 && (value - (value * 10_f64.powi(decimals)).round() / 10_f64.powi(decimals)).abs() > step * 1e-3
    {
        decimals += 1;
    }
    format!("{value:.0$}", decimals as usize)
}

/// The finest 1, 2 or 5 times a power of ten whose multiples in `range` are at most `ticks`.
fn tick_step((low, high): (f64, f64), ticks: usize) -> f64 {
    let span = high - low;
    let span = if span.is_finite() && span > 0.0 { span } else { 1.0 };
    let ticks = ticks.max(2) as f64;
    let decade = 10_f64.powf((span / ticks).log10().floor());
    let fits = |step: f64| (high / step).floor() - (low / step).ceil() + 1.0 <= ticks;
    [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * decade).find(|&step| fits(step)).unwrap_or(10.0 * decade)
}

fn marker_colour(kind: MarkerKind) -> RGBColor {
    match kind {
        MarkerKind::Fault => RGBColor(214, 39, 40),
        MarkerKind::Disconnect => RGBColor(255, 127, 14),
        MarkerKind::Note => RGBColor(127, 127, 127),
    }
}

fn marker_style(kind: MarkerKind) -> ShapeStyle {
    let width = if kind == MarkerKind::Note { 1 } else { 2 };
    marker_colour(kind).stroke_width(width)
}

fn marker_name(kind: MarkerKind) -> &'static str {
    match kind {
        MarkerKind::Fault => "fault",
        MarkerKind::Disconnect => "disconnect",
        MarkerKind::Note => "note",
    }
}

/// What a legend row shows beside its name.
enum Swatch {
    Series(RGBColor, Style),
    Marker(MarkerKind),
}

/// The legend column: each series' colour and name, then the page's marker kinds; as many
/// rows as fit, the last saying how many more there are.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, panel: &Panel, kinds: &[MarkerKind]) -> Drawn<DB> {
    let series = panel
        .series
        .iter()
        .enumerate()
        .map(|(i, s)| (s.name.as_str(), Swatch::Series(PALETTE[i % PALETTE.len()], s.style)));
    let entries: Vec<(&str, Swatch)> =
        series.chain(kinds.iter().map(|&k| (marker_name(k), Swatch::Marker(k)))).collect();
    let first_row_px = 40;
    let rows = ((area.dim_in_pixel().1 as i32 - first_row_px) / LEGEND_ROW_PX).max(1) as usize;
    let shown = if entries.len() > rows { rows - 1 } else { entries.len() };
    let name_style = text(16).pos(Pos::new(HPos::Left, VPos::Center));
    let max_name_px = (LEGEND_PX - 52) as i32;
    for (row, (name, swatch)) in entries.iter().take(shown).enumerate() {
        let y = first_row_px + row as i32 * LEGEND_ROW_PX;
        match *swatch {
            Swatch::Series(colour, Style::Dots) => area.draw(&Circle::new((20, y), 3, colour.filled()))?,
            Swatch::Series(colour, _) => area.draw(&PathElement::new(vec![(6, y), (34, y)], colour.stroke_width(2)))?,
            Swatch::Marker(kind) => area.draw(&PathElement::new(vec![(20, y - 7), (20, y + 7)], marker_style(kind)))?,
        }
        let name = fit(area, name, &name_style, max_name_px)?;
        area.draw_text(&name, &name_style, (42, y))?;
    }
    if shown < entries.len() {
        let y = first_row_px + shown as i32 * LEGEND_ROW_PX;
        area.draw_text(&format!("+{} more", entries.len() - shown), &name_style, (42, y))?;
    }
    Ok(())
}

/// `name`, cut with an ellipsis to at most `max_px` wide.
fn fit<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    name: &str,
    style: &TextStyle,
    max_px: i32,
) -> Result<String, DrawingAreaErrorKind<DB::ErrorType>> {
    let fits = |s: &str| area.estimate_text_size(s, style).map(|(w, _)| w as i32 <= max_px);
    if fits(name)? {
        return Ok(name.to_owned());
    }
    let mut cut = String::new();
    for c in name.chars().take(200) {
        cut.push(c);
        cut.push('…');
        let fitted = fits(&cut)?;
        cut.pop();
        if !fitted {
            cut.pop();
            break;
        }
    }
    cut.push('…');
    Ok(cut)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_labels_have_the_decimals_of_their_step() {
        let labels =
            |values: &[f64], range, ticks| values.iter().map(|&v| tick_label(v, range, ticks)).collect::<Vec<_>>();
        assert_eq!(labels(&[0.0, 2.0, 20.0], (-0.1, 20.1), 12), ["0", "2", "20"]);
        assert_eq!(labels(&[0.0, 0.5, 1.0, 2.5], (-0.12, 2.58), 6), ["0.0", "0.5", "1.0", "2.5"]);
        assert_eq!(labels(&[-0.5, 0.0, 0.5], (-0.55, 0.55), 6), ["-0.5", "0.0", "0.5"]);
        assert_eq!(labels(&[0.0, 0.02, 0.04], (0.0, 0.05), 6), ["0.00", "0.02", "0.04"]);
        // A finer step than expected still labels each tick exactly.
        assert_eq!(labels(&[0.5, 1.0], (0.0, 10.0), 6), ["0.5", "1"]);
        assert_eq!(labels(&[1e-17], (0.0, 1.0), 6), ["0.0"]);
        assert_eq!(labels(&[2.5e6, 1e-7], (0.0, 1e6), 6), ["2.5e6", "0"]);
        assert_eq!(labels(&[1e-7, 1.5e-7], (1e-7, 2e-7), 6), ["1.0e-7", "1.5e-7"]);
    }
}
