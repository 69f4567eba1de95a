//! The axes of a figure: the drawn range of the data (padded; on a log axis in
//! decades), the ticks (1–2–5 steps; a log axis labels its decades) and their labels
//! (the shortest exact form of the value: `450`, not `450.0`).

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

/// The ticks drawn at most on a linear axis.
const LINEAR_TICKS: f64 = 10.0;

/// The finite span `lo..hi` of `values`, or `None` without one.
pub fn span(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    (lo <= hi).then_some((lo, hi))
}

/// `lo..hi` widened by 5 % on each side (by 5 % of the value where it is one point).
pub fn padded((lo, hi): (f64, f64)) -> Range<f64> {
    let m = if hi > lo {
        0.05 * (hi - lo)
    } else {
        lo.abs().max(1.0) * 0.05
    };
    (lo - m)..(hi + m)
}

/// The same range on a log axis (values are decades, log10 of the data): 2 % of the
/// span each side, a tenth of a decade where it is one point.
pub fn padded_log((lo, hi): (f64, f64)) -> Range<f64> {
    let m = if hi > lo { 0.02 * (hi - lo) } else { 0.1 };
    (lo - m)..(hi + m)
}

/// A 1, 2 or 5 times a power of ten near `span / LINEAR_TICKS`.
fn step(span: f64) -> f64 {
    let raw = span / LINEAR_TICKS;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

/// Ticks of a linear axis over `r`: the multiples of a 1–2–5 step.
pub fn linear_ticks(r: &Range<f64>) -> Vec<f64> {
    let s = step(r.end - r.start);
    // A span too narrow for its offset to count steps in: its ends.
    if !(s.is_finite() && s > 0.0) || (r.start / s).abs().max((r.end / s).abs()) > 1e15 {
        return vec![r.start, r.end];
    }
    let first = (r.start / s).ceil() as i64;
    let last = (r.end / s).floor() as i64;
    (first..=last).map(|k| k as f64 * s).collect()
}

/// Ticks (labelled) and grid lines of a log axis over `r` (in decades), both in
/// decades: the decades; where fewer than two lie in `r`, the 2s and 5s too, then
/// every digit; on a span narrower still, a linear axis' ticks of the values.
pub fn log_ticks(r: &Range<f64>) -> (Vec<f64>, Vec<f64>) {
    let at = |digits: &[f64]| -> Vec<f64> {
        let (d0, d1) = (r.start.floor() as i64, r.end.ceil() as i64);
        (d0..=d1)
            .flat_map(|d| {
                digits
                    .iter()
                    .map(move |m| (m * 10f64.powi(d as i32)).log10())
            })
            .filter(|v| r.contains(v))
            .collect()
    };
    let every: Vec<f64> = (1..=9).map(f64::from).collect();
    let grid = at(&every);
    for digits in [&[1.0][..], &[1.0, 2.0, 5.0], &every] {
        let ticks = at(digits);
        if ticks.len() >= 2 {
            return (ticks, grid);
        }
    }
    let values = 10f64.powf(r.start)..10f64.powf(r.end);
    let ticks = linear_ticks(&values)
        .into_iter()
        .filter(|v| *v > 0.0)
        .map(f64::log10)
        .collect();
    (ticks, grid)
}

/// The shortest exact label of a tick: rounded to 12 significant digits (a sum of
/// steps' float noise gone), then printed as Rust prints a float, without a `.0`
/// (`450`, `0.5`, `1000`); below 10⁻³ and from 10⁶ in exponent form (`1.5e-5`).
pub fn label(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let r: f64 = format!("{v:.11e}").parse().unwrap_or(v);
    if r == 0.0 {
        return "0".into();
    }
    if r.abs() < 1e-3 || r.abs() >= 1e6 {
        return format!("{r:e}");
    }
    format!("{r}")
}

/// A linear coordinate with the ticks and grid lines given (plotters' own picks its
/// ticks and prints them with a `.0`).
pub struct Ticked {
    pub range: Range<f64>,
    pub ticks: Vec<f64>,
    pub grid: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let span = self.range.end - self.range.start;
        let t = (v - self.range.start) / span;
        if !t.is_finite() {
            return (limit.0 + limit.1) / 2;
        }
        let px = f64::from(limit.1 - limit.0) * t;
        limit.0 + (px + 1e-3).floor().clamp(-1e6, 1e6) as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.grid.clone()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.range.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_are_the_shortest_exact_form() {
        assert_eq!(label(450.0), "450");
        assert_eq!(label(0.5), "0.5");
        assert_eq!(label(3.0 * 0.1), "0.3");
        assert_eq!(label(-0.0), "0");
        assert_eq!(label(10f64.powf(2f64.log10())), "2");
        assert_eq!(label(1.5e-5), "1.5e-5");
        assert_eq!(label(2e6), "2e6");
    }

    #[test]
    fn a_log_axis_ticks_its_decades_and_a_narrow_one_its_digits() {
        let (ticks, grid) = log_ticks(&(0.3..3.2));
        let values: Vec<String> = ticks.iter().map(|t| label(10f64.powf(*t))).collect();
        assert_eq!(values, ["10", "100", "1000"]);
        assert_eq!(grid.len(), 8 + 9 + 9 + 1, "2 … 900 and 1000: {grid:?}");
        let (ticks, _) = log_ticks(&(1.4..1.9));
        let values: Vec<String> = ticks.iter().map(|t| label(10f64.powf(*t))).collect();
        assert_eq!(values, ["30", "40", "50", "60", "70"]);
        let (ticks, _) = log_ticks(&(1.65..1.68));
        assert!(ticks.len() >= 2, "{ticks:?}");
    }

    #[test]
    fn linear_ticks_step_by_one_two_or_five() {
        assert_eq!(
            linear_ticks(&(-0.1..1.05)),
            [0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
        assert_eq!(linear_ticks(&(0.0..1000.0)).len(), 11);
        assert_eq!(linear_ticks(&(1e20..(1e20 + 1e5))), [1e20, 1e20 + 1e5]);
    }
}
