//! What a plot shows: pages of panels of series, with markers across a page.

/// One page of the image: a device, with its panels stacked over one time axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Page {
    /// The page's title, drawn large above its panels (e.g. the device's address).
    pub title: String,
    /// The panels, top to bottom; they share the page's time axis. At least one.
    pub panels: Vec<Panel>,
    /// Vertical lines across every panel of the page, each labelled.
    pub markers: Vec<Marker>,
}

/// One plot of a page: series against time, with one y axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The panel's title, drawn above it.
    pub title: String,
    /// The y axis' label, with its unit: `"velocity (m/s)"`.
    pub y_label: String,
    /// The series, each with its own colour and a legend entry.
    pub series: Vec<Series>,
}

/// A named series of `(time_s, value)` points.
///
/// Points with a coordinate that is not finite or beyond ±1e300 are skipped. A series with
/// more points than twice the plot's width in pixels is drawn through the lowest and the
/// highest point of each pixel column.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The legend's name for the series: `"commanded"`.
    pub name: String,
    /// `(time in seconds, value in the panel's unit)`, in time order for lines and steps.
    pub points: Vec<(f64, f64)>,
    /// How the points are drawn.
    pub style: Style,
}

/// How a series' points are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Straight lines between consecutive points.
    Line,
    /// Each value held until the next point's time (a latched command, a target).
    Step,
    /// A dot per point, unconnected (events, sparse samples).
    Dots,
}

/// A labelled vertical line across every panel of a page.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// When, in seconds on the page's time axis.
    pub time_s: f64,
    /// The text beside the line: `"watchdog: no state for 200 ms"`.
    pub label: String,
    /// What happened; sets the line's colour.
    pub kind: MarkerKind,
}

/// What a marker marks; each kind has its own colour (red, orange, grey).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkerKind {
    /// The device reported a fault (red).
    Fault,
    /// The link went silent or was lost (orange).
    Disconnect,
    /// Anything else worth seeing on the time axis (grey).
    Note,
}
