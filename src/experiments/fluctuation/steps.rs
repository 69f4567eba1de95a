//! The passes of a record and the steps of the deviation within them: where the
//! unbalance moment overcomes the friction and the table crosses the backlash.

use serde::Serialize;

use super::{
    Record, REVERSAL_THRESHOLD, STEP_LEVEL_SPAN, STEP_LOCATE_HALF_WIDTH, STEP_MIN_FRACTION,
};
use crate::experiments::positioning::iso230::ARCSEC_PER_RAD;
use crate::io::experiment_file::Direction;

/// A step of the deviation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Step {
    /// Change of the deviation across [`STEP_WINDOW`] in the order travelled (later
    /// minus earlier), arc-sec.
    pub size_arcsec: f64,
    /// Table angle at the middle of the window, deg.
    pub angle_deg: f64,
}

/// The advance-only samples of one direction pass (module docs, step 1).
#[derive(Clone, Debug, PartialEq)]
pub struct PassSamples {
    /// +1 up (CCW), −1 down (CW).
    pub sense: f64,
    /// sense·θt, rad, strictly increasing.
    pub x: Vec<f64>,
    /// Deviation θt − θm·ratio there, arc-sec.
    pub deviation_arcsec: Vec<f64>,
}

impl PassSamples {
    /// The direction of the pass.
    pub fn direction(&self) -> Direction {
        if self.sense > 0.0 {
            Direction::Up
        } else {
            Direction::Down
        }
    }
}

/// The passes of a record with at least 4 advancing samples each, in the order run.
pub(crate) fn pass_samples(record: &Record, ratio: f64) -> Vec<PassSamples> {
    let table = &record.table_angle;
    let mut out = Vec::new();
    for (first, last, sense) in passes(table) {
        let (mut x, mut d) = (Vec::new(), Vec::new());
        let motor = &record.motor_angle[first..=last];
        for (&t, &m) in table[first..=last].iter().zip(motor) {
            let xi = sense * t;
            if x.last().map_or(true, |&l| xi > l) {
                x.push(xi);
                d.push((t - ratio * m) * ARCSEC_PER_RAD);
            }
        }
        if x.len() >= 4 {
            out.push(PassSamples {
                sense,
                x,
                deviation_arcsec: d,
            });
        }
    }
    out
}

/// Splits the table angle into passes: (first index, last index, sense ±1), each
/// ending at its extreme angle.
fn passes(table: &[f64]) -> Vec<(usize, usize, f64)> {
    let mut out = Vec::new();
    let (mut start, mut ext, mut sense) = (0, 0, 0.0);
    for (i, &a) in table.iter().enumerate() {
        if sense == 0.0 {
            let d = a - table[0];
            if d.abs() > REVERSAL_THRESHOLD {
                sense = d.signum();
                ext = i;
            }
        } else if sense * (a - table[ext]) > 0.0 {
            ext = i;
        } else if sense * (table[ext] - a) > REVERSAL_THRESHOLD {
            out.push((start, ext, sense));
            start = ext;
            sense = -sense;
            ext = i;
        }
    }
    if sense != 0.0 {
        out.push((start, ext, sense));
    }
    out
}

/// ∫ of the piecewise-linear interpolant of (x, y) over [a, b] (inside [x₀, xₙ]).
fn integral(x: &[f64], y: &[f64], a: f64, b: f64) -> f64 {
    let at = |v: f64| {
        let k = x.partition_point(|&xi| xi < v).clamp(1, x.len() - 1);
        let (x0, x1) = (x[k - 1], x[k]);
        y[k - 1] + (y[k] - y[k - 1]) * (v - x0) / (x1 - x0)
    };
    let lo = x.partition_point(|&xi| xi <= a);
    let hi = x.partition_point(|&xi| xi < b);
    let mut sum = 0.0;
    let (mut px, mut py) = (a, at(a));
    for k in lo..hi {
        sum += 0.5 * (py + y[k]) * (x[k] - px);
        (px, py) = (x[k], y[k]);
    }
    sum + 0.5 * (py + at(b)) * (b - px)
}

/// A step located precisely: in the window `center` ± `half_width` of a pass (in
/// x = sense·θt, clipped to the samples), the levels before and after are the mean
/// deviation over the first and last [`STEP_LEVEL_SPAN`] of it, and the position is
/// where an ideal step between those levels with the same area under the curve would
/// stand: x_a + ∫(after − d)dx / (after − before). Exact for a sharp step on flat
/// levels; the rattle across the backlash averages out instead of deciding it; and it
/// moves continuously with the data (an optimiser can follow it). Returns (position
/// in x, rad; size after − before, arc-sec), `None` when the window holds less than
/// three level spans (each at most half of `half_width`) or the levels are equal.
pub fn locate_step(pass: &PassSamples, center: f64, half_width: f64) -> Option<(f64, f64)> {
    let (x, d) = (&pass.x, &pass.deviation_arcsec);
    let a = (center - half_width).max(x[0]);
    let b = (center + half_width).min(x[x.len() - 1]);
    let span = STEP_LEVEL_SPAN.min(0.5 * half_width);
    if b - a < 3.0 * span {
        return None;
    }
    let before = integral(x, d, a, a + span) / span;
    let after = integral(x, d, b - span, b) / span;
    let size = after - before;
    if size == 0.0 || !size.is_finite() {
        return None;
    }
    let position = a + ((b - a) * after - integral(x, d, a, b)) / size;
    Some((position.clamp(a, b), size))
}

/// The steps of a pass: the changes across [`STEP_WINDOW`] on the uniform grid
/// (`grid_x`, `dev`) of at least [`STEP_MIN_FRACTION`] of the largest, taken greedily
/// from the largest at least 2·[`STEP_LOCATE_HALF_WIDTH`] apart, each then located
/// with [`locate_step`] on the samples; in the order travelled.
pub(super) fn find_steps(pass: &PassSamples, grid_x: &[f64], dev: &[f64], w: usize) -> Vec<Step> {
    let m = dev.len();
    let change: Vec<(f64, f64)> = (0..m - w)
        .map(|j| (0.5 * (grid_x[j] + grid_x[j + w]), dev[j + w] - dev[j]))
        .collect();
    let largest = change.iter().fold(0.0f64, |a, c| a.max(c.1.abs()));
    let mut candidates: Vec<&(f64, f64)> = change
        .iter()
        .filter(|c| largest > 0.0 && c.1.abs() >= STEP_MIN_FRACTION * largest)
        .collect();
    candidates.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
    let mut centres: Vec<f64> = Vec::new();
    for c in candidates {
        if centres
            .iter()
            .all(|&x| (x - c.0).abs() >= 2.0 * STEP_LOCATE_HALF_WIDTH)
        {
            centres.push(c.0);
        }
    }
    centres.sort_by(f64::total_cmp);
    centres
        .into_iter()
        .filter_map(|c| locate_step(pass, c, STEP_LOCATE_HALF_WIDTH))
        .map(|(x, size)| Step {
            size_arcsec: size,
            angle_deg: (pass.sense * x).to_degrees(),
        })
        .collect()
}
