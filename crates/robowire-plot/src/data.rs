//! Series made drawable: unplottable points skipped, axis ranges that are never empty or
//! infinite, steps as lines, dense series reduced to what a pixel column can show.

use crate::Style;

/// The largest magnitude drawn; beyond it a coordinate counts as not finite, so that every axis
/// span stays finite.
const MAX_MAGNITUDE: f64 = 1e300;

/// A coordinate that can be drawn: finite and within ±1e300.
pub(crate) fn plottable(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX_MAGNITUDE
}

/// The points of a series that can be drawn, in their order.
pub(crate) fn plottable_points(points: &[(f64, f64)]) -> impl Iterator<Item = (f64, f64)> + '_ {
    points.iter().copied().filter(|&(t, v)| plottable(t) && plottable(v))
}

/// An axis range `(low, high)` holding every plottable value, with `pad` (a fraction of their
/// span) of room each side.
///
/// `low < high`, both finite, always: no value gives `(0, 1)`; one value (or values closer
/// together than a billionth of their size) gives ±10 % of it around it (±1 around 0).
pub(crate) fn axis_range(values: impl IntoIterator<Item = f64>, pad: f64) -> (f64, f64) {
    let mut bounds: Option<(f64, f64)> = None;
    for v in values.into_iter().filter(|&v| plottable(v)) {
        bounds = Some(bounds.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
    }
    let Some((lo, hi)) = bounds else { return (0.0, 1.0) };
    let magnitude = lo.abs().max(hi.abs());
    if hi - lo <= magnitude * 1e-9 {
        let center = lo / 2.0 + hi / 2.0;
        let half = if magnitude < 1e-200 { 1.0 } else { magnitude * 0.1 };
        return (center - half, center + half);
    }
    let pad = (hi - lo) * pad;
    (lo - pad, hi + pad)
}

/// The polyline a series is drawn as: a step series holds each value until the next point's
/// time (a vertical rise there); lines and dots are their points.
pub(crate) fn polyline(points: impl Iterator<Item = (f64, f64)>, style: Style) -> Vec<(f64, f64)> {
    match style {
        Style::Line | Style::Dots => points.collect(),
        Style::Step => {
            let mut line: Vec<(f64, f64)> = Vec::with_capacity(points.size_hint().0 * 2);
            for (t, v) in points {
                if let Some(&(_, held)) = line.last() {
                    line.push((t, held));
                }
                line.push((t, v));
            }
            line
        }
    }
}

/// `points` as at most two per pixel column when there are more than that: each of `columns`
/// equal slices of `time_range` keeps its lowest and its highest point, in time order, so
/// every extreme stays visible. Fewer points come back as they are.
pub(crate) fn decimate(points: Vec<(f64, f64)>, time_range: (f64, f64), columns: usize) -> Vec<(f64, f64)> {
    let columns = columns.max(1);
    if points.len() <= 2 * columns {
        return points;
    }
    let (t0, t1) = time_range;
    let per_s = columns as f64 / (t1 - t0);
    // Each column's (lowest, highest) point.
    type Extremes = Option<((f64, f64), (f64, f64))>;
    let mut extremes: Vec<Extremes> = vec![None; columns];
    for p in points {
        // `as` saturates: a time before `t0` (or NaN) lands in column 0.
        let column = (((p.0 - t0) * per_s) as usize).min(columns - 1);
        let slot = &mut extremes[column];
        match slot {
            None => *slot = Some((p, p)),
            Some((low, high)) => {
                if p.1 < low.1 {
                    *low = p;
                }
                if p.1 > high.1 {
                    *high = p;
                }
            }
        }
    }
    let mut kept = Vec::with_capacity(2 * columns);
    for (low, high) in extremes.into_iter().flatten() {
        let (first, second) = if low.0 <= high.0 { (low, high) } else { (high, low) };
        kept.push(first);
        if second != first {
            kept.push(second);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    #[test]
    fn an_axis_range_is_never_empty_nor_infinite() {
        assert_eq!(axis_range([], 0.05), (0.0, 1.0));
        assert_eq!(axis_range([f64::NAN, f64::INFINITY, f64::NEG_INFINITY, f64::MAX], 0.05), (0.0, 1.0));
        assert_eq!(axis_range([0.0, 0.0], 0.05), (-1.0, 1.0));
        let (lo, hi) = axis_range([5.0], 0.05);
        assert!((lo - 4.5).abs() < 1e-12 && (hi - 5.5).abs() < 1e-12, "{lo}..{hi}");
        let (lo, hi) = axis_range([0.0, 10.0, f64::NAN], 0.05);
        assert!((lo + 0.5).abs() < 1e-12 && (hi - 10.5).abs() < 1e-12, "{lo}..{hi}");
        let (lo, hi) = axis_range([-1e300, 1e300], 0.05);
        assert!(lo.is_finite() && hi.is_finite() && lo < -1e300 && hi > 1e300);
    }

    #[test]
    fn a_step_series_holds_each_value_until_the_next_time() {
        let steps = polyline([(0.0, 1.0), (1.0, 2.0), (3.0, 0.5)].into_iter(), Style::Step);
        assert_eq!(steps, [(0.0, 1.0), (1.0, 1.0), (1.0, 2.0), (3.0, 2.0), (3.0, 0.5)]);
        assert!(polyline(std::iter::empty(), Style::Step).is_empty());
    }

    #[test]
    fn a_sparse_series_is_not_decimated() {
        let points = vec![(0.0, 1.0), (0.5, -1.0), (1.0, 3.0)];
        assert_eq!(decimate(points.clone(), (0.0, 1.0), 2), points);
    }

    #[test]
    fn a_1_khz_ten_minute_series_comes_down_to_two_points_a_column() {
        let points: Vec<_> = (0..600_000).map(|i| (f64::from(i) * 1e-3, (f64::from(i) * 1e-3).sin())).collect();
        let kept = decimate(points, (0.0, 600.0), 1000);
        assert!(kept.len() <= 2000 && kept.len() > 1000, "{}", kept.len());
        assert!(kept.windows(2).all(|w| w[0].0 <= w[1].0), "not in time order");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn decimation_keeps_each_columns_lowest_and_highest_point(
            values in proptest::collection::vec(-1e6f64..1e6, 0..2000),
            columns in 1usize..50,
        ) {
            let points: Vec<(f64, f64)> = values.iter().enumerate().map(|(i, &v)| (i as f64, v)).collect();
            let range = axis_range(points.iter().map(|p| p.0), 0.01);
            let kept = decimate(points.clone(), range, columns);
            prop_assert!(kept.len() <= 2 * columns);
            prop_assert!(kept.iter().all(|p| points.contains(p)), "a point that was not in the series");
            let per_s = columns as f64 / (range.1 - range.0);
            let column_of = |t: f64| (((t - range.0) * per_s) as usize).min(columns - 1);
            for column in 0..columns {
                let inside: Vec<f64> = points.iter().filter(|p| column_of(p.0) == column).map(|p| p.1).collect();
                let kept_inside: Vec<f64> = kept.iter().filter(|p| column_of(p.0) == column).map(|p| p.1).collect();
                if inside.is_empty() {
                    prop_assert!(kept_inside.is_empty());
                    continue;
                }
                let max = |v: &[f64]| v.iter().copied().fold(f64::MIN, f64::max);
                let min = |v: &[f64]| v.iter().copied().fold(f64::MAX, f64::min);
                prop_assert_eq!(max(&kept_inside), max(&inside), "column {}", column);
                prop_assert_eq!(min(&kept_inside), min(&inside), "column {}", column);
            }
        }
    }
}
