//! Accuracy and repeatability of positioning of a rotary axis after ISO 230-2 — the
//! evaluation of the paper's third test (docs/experiments.md (positioning), paper §4.3 and Table 2).
//!
//! The paper cites ISO 230-2:1997. The quantities below are defined identically in the
//! 1997, 2006 and 2014 editions; each is given by the name of its entry in the
//! standard's terms-and-definitions clause (clause 3 of the 2006 and 2014 editions),
//! with the formula as implemented. Sub-clause numbers are not quoted: they differ
//! between editions and were not checked against the standard's text.
//!
//! Notation: target positions `Pi`, i = 1…m, sorted ascending; run j = 1…n in each
//! direction; ↑ = approach in the positive (CCW) sense, ↓ = in the negative sense.
//!
//! ```text
//! positional deviation                          xij   = Pij − Pi           (measured − target; the input)
//! mean unidirectional positional deviation
//!   at a position                               x̄i↑  = (1/n↑)·Σj xij↑      (likewise x̄i↓)
//! estimator for the unidirectional standard
//!   uncertainty of positioning at a position    si↑  = √( Σj (xij↑ − x̄i↑)² / (n↑ − 1) )   (likewise si↓)
//! reversal value at a position                  Bi   = x̄i↑ − x̄i↓
//! mean bidirectional positional deviation
//!   at a position                               x̄i   = (x̄i↑ + x̄i↓)/2
//! unidirectional repeatability of
//!   positioning at a position                   Ri↑  = 4·si↑               (likewise Ri↓)
//! bidirectional repeatability of positioning
//!   at a position                               Ri   = max(2·si↑ + 2·si↓ + |Bi|, Ri↑, Ri↓)
//!
//! reversal value of an axis                     B    = max_i |Bi|
//! mean reversal value of an axis                B̄    = (1/m)·Σi Bi         (signed)
//! unidirectional repeatability of positioning
//!   of an axis                                  R↑   = max_i Ri↑           (likewise R↓)
//! bidirectional repeatability of positioning
//!   of an axis                                  R    = max_i Ri
//! unidirectional systematic positional
//!   deviation of an axis                        E↑   = max_i x̄i↑ − min_i x̄i↑   (likewise E↓)
//! bidirectional systematic positional
//!   deviation of an axis                        E    = max_i(x̄i↑, x̄i↓) − min_i(x̄i↑, x̄i↓)
//! mean bidirectional positional deviation
//!   of an axis                                  M    = max_i x̄i − min_i x̄i
//! unidirectional accuracy of positioning
//!   of an axis                                  A↑   = max_i(x̄i↑ + 2·si↑) − min_i(x̄i↑ − 2·si↑)   (likewise A↓)
//! bidirectional accuracy of positioning
//!   of an axis                                  A    = max_i(x̄i↑ + 2·si↑, x̄i↓ + 2·si↓)
//!                                                    − min_i(x̄i↑ − 2·si↑, x̄i↓ − 2·si↓)
//! ```
//!
//! Every axis value is taken over **all** targets, and these follow from the
//! definitions (the tests check them on random data): R ≥ Ri ≥ Ri↑, Ri↓, |Bi| for every
//! i, so R ≥ R↑, R↓, B; E's extremes run over a superset of E↑'s and E↓'s, so E ≥ E↑,
//! E↓; x̄i lies between x̄i↑ and x̄i↓, so M ≤ E; likewise A ≥ A↑, A↓ and A ≥ E; and
//! B ≥ |B̄|. An evaluation that breaks one of these has taken an axis value from one
//! target or one direction — one open-source ISO 230-2 report generator we looked at
//! gives R = max(R↑, R↓) and an E smaller than its own E↓.
//!
//! Conventions:
//! - Angles are rad in and out; [`AxisStats::in_arcsec`] and [`TargetStats::in_arcsec`]
//!   convert for reports, which use arc-seconds like the paper.
//! - B is reported as the magnitude max|Bi| (as ISO 230-2 defines it); the sign of each
//!   Bi is in [`TargetStats::reversal`], and B̄ keeps its sign. Backlash in a
//!   semi-closed loop leaves the table short of every target, below it on the way up
//!   and above it on the way down, so Bi ≈ −(total free play) < 0: the paper's Table 2
//!   "B" (its B̄, 32.8″ for the worm) is a magnitude, to be compared with |B̄|.
//! - Targets are grouped by value: targets within [`SAME_TARGET_RAD`] of the smallest
//!   target of a group belong to it, and the group's target is their mean. Angles are
//!   not wrapped: 0 and 2π are different targets, as in a test that measures both.
//! - ISO 230-2 prescribes 5 runs per direction at every target; this evaluation
//!   accepts any n ≥ 2 per direction, not necessarily equal (s is undefined for n = 1).
//!   Run numbers only identify runs: a run repeated at one target and direction is an
//!   error.
//! - Means and s are computed about the first value of each series, so a series of
//!   equal values has exactly that mean and s = 0.

use serde::{Deserialize, Serialize};

/// Arc-seconds per radian, 180·3600/π.
pub const ARCSEC_PER_RAD: f64 = 648_000.0 / std::f64::consts::PI;

/// The units a report uses, as the field does: targets in degrees and deviations in
/// arc-seconds on a rotary axis, millimetres and micrometres on a linear one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReportUnits {
    /// Report unit per SI unit (rad or m) of a target.
    pub target_per_si: f64,
    /// `°` or `mm`.
    pub target: &'static str,
    /// The column-name suffix of a target (`deg`, `mm`).
    pub target_key: &'static str,
    /// Report unit per SI unit of a deviation.
    pub deviation_per_si: f64,
    /// `″` or `µm`.
    pub deviation: &'static str,
    /// The column-name suffix of a deviation (`arcsec`, `um`).
    pub deviation_key: &'static str,
    /// The deviation unit in words, for headings (`arc-seconds`, `µm`).
    pub deviation_name: &'static str,
}

impl ReportUnits {
    pub const ROTARY: ReportUnits = ReportUnits {
        target_per_si: 180.0 / std::f64::consts::PI,
        target: "°",
        target_key: "deg",
        deviation_per_si: ARCSEC_PER_RAD,
        deviation: "″",
        deviation_key: "arcsec",
        deviation_name: "arc-seconds",
    };
    pub const LINEAR: ReportUnits = ReportUnits {
        target_per_si: 1e3,
        target: "mm",
        target_key: "mm",
        deviation_per_si: 1e6,
        deviation: "µm",
        deviation_key: "um",
        deviation_name: "µm",
    };

    /// The units of an axis.
    pub fn of(axis: crate::model::Axis) -> ReportUnits {
        match axis {
            crate::model::Axis::Rotary => ReportUnits::ROTARY,
            crate::model::Axis::Linear => ReportUnits::LINEAR,
        }
    }
}

/// Targets closer than this (rad) are one target position (about 2e-4″).
pub const SAME_TARGET_RAD: f64 = 1e-9;

/// The sense in which a target was approached (defined with the experiment files).
pub use crate::io::experiment_file::Direction;

/// One positioning of the table: where it was sent and how far off it stopped.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// Target position Pi, rad.
    pub target: f64,
    /// Sense of the approach.
    pub direction: Direction,
    /// Run number j (1…n in the standard; only used to tell runs apart).
    pub run: u32,
    /// Positional deviation xij = measured − target, rad.
    pub deviation: f64,
}

/// The statistics at one target position (all rad).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TargetStats {
    /// Target position Pi.
    pub target: f64,
    /// Number of runs approaching ↑.
    pub n_up: usize,
    /// Number of runs approaching ↓.
    pub n_down: usize,
    /// Mean unidirectional positional deviation x̄i↑.
    pub mean_up: f64,
    /// Mean unidirectional positional deviation x̄i↓.
    pub mean_down: f64,
    /// Estimator for the unidirectional standard uncertainty si↑ (n − 1 denominator).
    pub s_up: f64,
    /// Estimator for the unidirectional standard uncertainty si↓.
    pub s_down: f64,
    /// Reversal value Bi = x̄i↑ − x̄i↓ (signed).
    pub reversal: f64,
    /// Mean bidirectional positional deviation x̄i = (x̄i↑ + x̄i↓)/2.
    pub mean_bidirectional: f64,
    /// Unidirectional repeatability Ri↑ = 4·si↑.
    pub repeat_up: f64,
    /// Unidirectional repeatability Ri↓ = 4·si↓.
    pub repeat_down: f64,
    /// Bidirectional repeatability Ri = max(2si↑ + 2si↓ + |Bi|, Ri↑, Ri↓).
    pub repeat: f64,
}

impl TargetStats {
    /// The same statistics with every deviation-valued field in arc-seconds; `target`
    /// stays in rad and the counts are unchanged.
    pub fn in_arcsec(&self) -> TargetStats {
        self.scaled(ARCSEC_PER_RAD)
    }

    /// The same statistics with every deviation-valued field times `k` (a report's
    /// unit per SI unit: [`ReportUnits::deviation_per_si`]); `target` unchanged.
    pub fn scaled(&self, k: f64) -> TargetStats {
        TargetStats {
            mean_up: self.mean_up * k,
            mean_down: self.mean_down * k,
            s_up: self.s_up * k,
            s_down: self.s_down * k,
            reversal: self.reversal * k,
            mean_bidirectional: self.mean_bidirectional * k,
            repeat_up: self.repeat_up * k,
            repeat_down: self.repeat_down * k,
            repeat: self.repeat * k,
            ..*self
        }
    }
}

/// The values of the axis, over all targets (rad). JSON keys are the ISO symbols.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AxisStats {
    /// Reversal value of the axis B = max|Bi| (a magnitude).
    #[serde(rename = "B")]
    pub b: f64,
    /// Mean reversal value B̄ = mean of Bi (signed; the paper's Table 2 "B").
    #[serde(rename = "B_mean")]
    pub b_mean: f64,
    /// Unidirectional repeatability R↑ = max Ri↑.
    #[serde(rename = "R_up")]
    pub r_up: f64,
    /// Unidirectional repeatability R↓ = max Ri↓.
    #[serde(rename = "R_down")]
    pub r_down: f64,
    /// Bidirectional repeatability R = max Ri.
    #[serde(rename = "R")]
    pub r: f64,
    /// Unidirectional systematic positional deviation E↑ = max x̄i↑ − min x̄i↑.
    #[serde(rename = "E_up")]
    pub e_up: f64,
    /// Unidirectional systematic positional deviation E↓ = max x̄i↓ − min x̄i↓.
    #[serde(rename = "E_down")]
    pub e_down: f64,
    /// Bidirectional systematic positional deviation E, over x̄i↑ and x̄i↓ together.
    #[serde(rename = "E")]
    pub e: f64,
    /// Mean bidirectional positional deviation M = max x̄i − min x̄i.
    #[serde(rename = "M")]
    pub m: f64,
    /// Unidirectional accuracy A↑ = max(x̄i↑ + 2si↑) − min(x̄i↑ − 2si↑).
    #[serde(rename = "A_up")]
    pub a_up: f64,
    /// Unidirectional accuracy A↓ = max(x̄i↓ + 2si↓) − min(x̄i↓ − 2si↓).
    #[serde(rename = "A_down")]
    pub a_down: f64,
    /// Bidirectional accuracy A, over both directions together.
    #[serde(rename = "A")]
    pub a: f64,
}

impl AxisStats {
    /// The same values in arc-seconds.
    pub fn in_arcsec(&self) -> AxisStats {
        self.scaled(ARCSEC_PER_RAD)
    }

    /// The same values times `k` (a report's unit per SI unit).
    pub fn scaled(&self, k: f64) -> AxisStats {
        AxisStats {
            b: self.b * k,
            b_mean: self.b_mean * k,
            r_up: self.r_up * k,
            r_down: self.r_down * k,
            r: self.r * k,
            e_up: self.e_up * k,
            e_down: self.e_down * k,
            e: self.e * k,
            m: self.m * k,
            a_up: self.a_up * k,
            a_down: self.a_down * k,
            a: self.a * k,
        }
    }

    /// The values of several evaluations combined field by field: each field is `f`
    /// of that field's values in `all`, in order (an ensemble's mean, spread, …).
    pub fn fieldwise(all: &[AxisStats], f: impl Fn(&[f64]) -> f64) -> AxisStats {
        let of = |get: fn(&AxisStats) -> f64| f(&all.iter().map(get).collect::<Vec<_>>());
        AxisStats {
            b: of(|s| s.b),
            b_mean: of(|s| s.b_mean),
            r_up: of(|s| s.r_up),
            r_down: of(|s| s.r_down),
            r: of(|s| s.r),
            e_up: of(|s| s.e_up),
            e_down: of(|s| s.e_down),
            e: of(|s| s.e),
            m: of(|s| s.m),
            a_up: of(|s| s.a_up),
            a_down: of(|s| s.a_down),
            a: of(|s| s.a),
        }
    }

    /// The axis values from the per-target statistics (at least one target).
    fn from_targets(t: &[TargetStats]) -> AxisStats {
        let max = |f: &dyn Fn(&TargetStats) -> f64| t.iter().map(f).fold(f64::MIN, f64::max);
        let min = |f: &dyn Fn(&TargetStats) -> f64| t.iter().map(f).fold(f64::MAX, f64::min);
        let max_up = max(&|t| t.mean_up);
        let min_up = min(&|t| t.mean_up);
        let max_down = max(&|t| t.mean_down);
        let min_down = min(&|t| t.mean_down);
        let high_up = max(&|t| t.mean_up + 2.0 * t.s_up);
        let low_up = min(&|t| t.mean_up - 2.0 * t.s_up);
        let high_down = max(&|t| t.mean_down + 2.0 * t.s_down);
        let low_down = min(&|t| t.mean_down - 2.0 * t.s_down);
        AxisStats {
            b: max(&|t| t.reversal.abs()),
            b_mean: t.iter().map(|t| t.reversal).sum::<f64>() / t.len() as f64,
            r_up: max(&|t| t.repeat_up),
            r_down: max(&|t| t.repeat_down),
            r: max(&|t| t.repeat),
            e_up: max_up - min_up,
            e_down: max_down - min_down,
            e: max_up.max(max_down) - min_up.min(min_down),
            m: max(&|t| t.mean_bidirectional) - min(&|t| t.mean_bidirectional),
            a_up: high_up - low_up,
            a_down: high_down - low_down,
            a: high_up.max(high_down) - low_up.min(low_down),
        }
    }
}

/// The evaluation of a positioning test: targets ascending, and the axis values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Iso230Report {
    /// One entry per target position, ascending.
    pub targets: Vec<TargetStats>,
    /// The values of the axis, over all targets.
    pub axis: AxisStats,
}

/// Measurements that ISO 230-2 cannot evaluate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Iso230Error {
    #[error("no measurements to evaluate")]
    Empty,
    #[error("measurement #{index}: {field} = {value} rad is not a finite number")]
    NotFinite {
        /// Position in the input slice, from 0.
        index: usize,
        field: &'static str,
        value: f64,
    },
    #[error("target {}° was approached only in the {measured} direction; ISO 230-2 needs both (reversal value, bidirectional statistics)", deg(.target_deg))]
    OneDirection {
        target_deg: f64,
        measured: Direction,
    },
    #[error("target {}°, direction {direction}: {runs} run; the standard uncertainty estimator s needs at least 2", deg(.target_deg))]
    TooFewRuns {
        target_deg: f64,
        direction: Direction,
        runs: usize,
    },
    #[error("target {}°, direction {direction}: run {run} appears more than once", deg(.target_deg))]
    DuplicateRun {
        target_deg: f64,
        direction: Direction,
        run: u32,
    },
}

/// An angle in degrees for messages, to 1e-6° (90, not 90.00000000000001).
fn deg(x: &f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// Evaluates a positioning test: the statistics of every target (ascending) and of
/// the axis, all in rad. The order of `measurements` does not matter.
pub fn evaluate(measurements: &[Measurement]) -> Result<Iso230Report, Iso230Error> {
    if measurements.is_empty() {
        return Err(Iso230Error::Empty);
    }
    for (index, m) in measurements.iter().enumerate() {
        for (field, value) in [("target", m.target), ("deviation", m.deviation)] {
            if !value.is_finite() {
                return Err(Iso230Error::NotFinite {
                    index,
                    field,
                    value,
                });
            }
        }
    }
    let mut sorted: Vec<&Measurement> = measurements.iter().collect();
    sorted.sort_by(|a, b| a.target.total_cmp(&b.target));
    let mut targets = Vec::new();
    let mut rest = &sorted[..];
    while let Some(first) = rest.first() {
        let len = rest
            .iter()
            .position(|m| m.target - first.target > SAME_TARGET_RAD)
            .unwrap_or(rest.len());
        let (group, tail) = rest.split_at(len);
        targets.push(target_stats(group)?);
        rest = tail;
    }
    let axis = AxisStats::from_targets(&targets);
    Ok(Iso230Report { targets, axis })
}

/// The statistics of one target from its measurements (non-empty, finite).
fn target_stats(group: &[&Measurement]) -> Result<TargetStats, Iso230Error> {
    let target = group.iter().map(|m| m.target).sum::<f64>() / group.len() as f64;
    let target_deg = target.to_degrees();
    let mut runs: Vec<(bool, u32)> = group
        .iter()
        .map(|m| (m.direction == Direction::Up, m.run))
        .collect();
    runs.sort_unstable();
    if let Some(w) = runs.windows(2).find(|w| w[0] == w[1]) {
        return Err(Iso230Error::DuplicateRun {
            target_deg,
            direction: if w[0].0 {
                Direction::Up
            } else {
                Direction::Down
            },
            run: w[0].1,
        });
    }
    let series = |d: Direction| -> Vec<f64> {
        group
            .iter()
            .filter(|m| m.direction == d)
            .map(|m| m.deviation)
            .collect()
    };
    let (up, down) = (series(Direction::Up), series(Direction::Down));
    for (measured, other) in [(Direction::Up, &down), (Direction::Down, &up)] {
        if other.is_empty() {
            return Err(Iso230Error::OneDirection {
                target_deg,
                measured,
            });
        }
    }
    for (direction, x) in [(Direction::Up, &up), (Direction::Down, &down)] {
        if x.len() < 2 {
            return Err(Iso230Error::TooFewRuns {
                target_deg,
                direction,
                runs: x.len(),
            });
        }
    }
    let (mean_up, s_up) = mean_and_s(&up);
    let (mean_down, s_down) = mean_and_s(&down);
    let reversal = mean_up - mean_down;
    let (repeat_up, repeat_down) = (4.0 * s_up, 4.0 * s_down);
    Ok(TargetStats {
        target,
        n_up: up.len(),
        n_down: down.len(),
        mean_up,
        mean_down,
        s_up,
        s_down,
        reversal,
        mean_bidirectional: 0.5 * (mean_up + mean_down),
        repeat_up,
        repeat_down,
        repeat: (2.0 * s_up + 2.0 * s_down + reversal.abs())
            .max(repeat_up)
            .max(repeat_down),
    })
}

/// Mean and sample standard deviation (n − 1 denominator) of `x` (n ≥ 2), computed
/// about x[0]: equal values give exactly their value and 0.
fn mean_and_s(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let shift = x[0];
    let d_mean = x.iter().map(|v| v - shift).sum::<f64>() / n;
    let ss = x.iter().map(|v| (v - shift - d_mean).powi(2)).sum::<f64>();
    (shift + d_mean, (ss / (n - 1.0)).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use Direction::{Down, Up};

    /// Measurements from deviations in arc-seconds: `(target_deg, direction, [x_j])`,
    /// runs numbered 1…n.
    fn measurements(series: &[(f64, Direction, &[f64])]) -> Vec<Measurement> {
        series
            .iter()
            .flat_map(|&(target_deg, direction, x)| {
                x.iter().enumerate().map(move |(j, &x)| Measurement {
                    target: target_deg.to_radians(),
                    direction,
                    run: j as u32 + 1,
                    deviation: x / ARCSEC_PER_RAD,
                })
            })
            .collect()
    }

    fn close(got: f64, want: f64, what: &str) {
        assert!(
            (got - want).abs() <= 1e-9 * want.abs().max(1.0),
            "{what}: got {got}, want {want}"
        );
    }

    /// Hand-worked example, deviations in arc-seconds. Each series of three is
    /// {c − d, c, c + d}, so x̄ = c and s = √((d² + 0 + d²)/2) = d exactly.
    ///
    /// ```text
    ///            ↑ runs       x̄↑  s↑   ↓ runs          x̄↓  s↓   Bi=x̄↑−x̄↓  x̄i=(x̄↑+x̄↓)/2
    /// P1 =   0°  1, 2, 3       2   1    −7, −6, −5      −6   1      8          −2
    /// P2 = 120°  4, 6, 8       6   2    2.5, 4, 5.5      4   1.5    2           5
    /// P3 = 240°  −2, −1, 0    −1   1    −2, 0, 2         0   2     −1          −0.5
    ///
    ///            Ri↑=4s↑  Ri↓=4s↓  2s↑+2s↓+|Bi|     Ri
    /// P1         4        4        2+2+8 = 12       12  (reversal term)
    /// P2         8        6        4+3+2 = 9         9  (reversal term)
    /// P3         4        8        2+4+1 = 7         8  (Ri↓)
    ///
    /// B  = max(8, 2, 1)                    = 8
    /// B̄  = (8 + 2 − 1)/3                   = 3
    /// R↑ = max(4, 8, 4) = 8     R↓ = max(4, 6, 8) = 8     R = max(12, 9, 8) = 12
    ///      (R > max(R↑, R↓): taking R = max(R↑, R↓) would give 8)
    /// E↑ = 6 − (−1) = 7         E↓ = 4 − (−6) = 10
    /// E  = max(2, 6, −1, −6, 4, 0) − min(…) = 6 − (−6) = 12
    /// M  = max(−2, 5, −0.5) − min(…)  = 5 − (−2) = 7
    /// x̄↑ + 2s↑ = 4, 10, 1    x̄↑ − 2s↑ = 0, 2, −3    A↑ = 10 − (−3) = 13
    /// x̄↓ + 2s↓ = −4, 7, 4    x̄↓ − 2s↓ = −8, 1, −4   A↓ = 7 − (−8)  = 15
    /// A  = max(10, 7) − min(−3, −8) = 10 + 8 = 18
    /// ```
    #[test]
    fn hand_worked_three_targets() {
        // Deliberately out of order; P3's down runs carry a 5e-10 rad target offset,
        // within SAME_TARGET_RAD.
        let mut m = measurements(&[
            (240.0, Up, &[-2.0, -1.0, 0.0]),
            (0.0, Down, &[-7.0, -6.0, -5.0]),
            (120.0, Up, &[4.0, 6.0, 8.0]),
            (0.0, Up, &[1.0, 2.0, 3.0]),
            (240.0, Down, &[-2.0, 0.0, 2.0]),
            (120.0, Down, &[2.5, 4.0, 5.5]),
        ]);
        for x in m.iter_mut().filter(|x| x.direction == Down) {
            if x.target > 4.0 {
                x.target += 5e-10;
            }
        }
        let report = evaluate(&m).unwrap();
        assert_eq!(report.targets.len(), 3);
        // (P°, x̄↑, x̄↓, s↑, s↓, Bi, x̄i, Ri↑, Ri↓, Ri)
        let want = [
            (0.0, 2.0, -6.0, 1.0, 1.0, 8.0, -2.0, 4.0, 4.0, 12.0),
            (120.0, 6.0, 4.0, 2.0, 1.5, 2.0, 5.0, 8.0, 6.0, 9.0),
            (240.0, -1.0, 0.0, 1.0, 2.0, -1.0, -0.5, 4.0, 8.0, 8.0),
        ];
        for (t, w) in report.targets.iter().zip(want) {
            let name = format!("P = {}°", w.0);
            assert!((t.target.to_degrees() - w.0).abs() < 1e-6, "{name}");
            assert_eq!((t.n_up, t.n_down), (3, 3), "{name}");
            let t = t.in_arcsec();
            close(t.mean_up, w.1, &format!("{name} x̄↑"));
            close(t.mean_down, w.2, &format!("{name} x̄↓"));
            close(t.s_up, w.3, &format!("{name} s↑"));
            close(t.s_down, w.4, &format!("{name} s↓"));
            close(t.reversal, w.5, &format!("{name} B"));
            close(t.mean_bidirectional, w.6, &format!("{name} x̄"));
            close(t.repeat_up, w.7, &format!("{name} R↑"));
            close(t.repeat_down, w.8, &format!("{name} R↓"));
            close(t.repeat, w.9, &format!("{name} R"));
        }
        let a = report.axis.in_arcsec();
        for (got, want, what) in [
            (a.b, 8.0, "B"),
            (a.b_mean, 3.0, "B̄"),
            (a.r_up, 8.0, "R↑"),
            (a.r_down, 8.0, "R↓"),
            (a.r, 12.0, "R"),
            (a.e_up, 7.0, "E↑"),
            (a.e_down, 10.0, "E↓"),
            (a.e, 12.0, "E"),
            (a.m, 7.0, "M"),
            (a.a_up, 13.0, "A↑"),
            (a.a_down, 15.0, "A↓"),
            (a.a, 18.0, "A"),
        ] {
            close(got, want, what);
        }
    }

    #[test]
    fn json_keys_are_the_iso_symbols() {
        let m = measurements(&[(0.0, Up, &[1.0, 2.0]), (0.0, Down, &[0.0, 1.0])]);
        let json = serde_json::to_value(evaluate(&m).unwrap().axis).unwrap();
        let mut keys: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(|k| k.as_str())
            .collect();
        keys.sort_unstable();
        let mut want = [
            "B", "B_mean", "R_up", "R_down", "R", "E_up", "E_down", "E", "M", "A_up", "A_down", "A",
        ];
        want.sort_unstable();
        assert_eq!(keys, want);
    }

    /// A tiny 64-bit linear congruential generator (Knuth's MMIX constants).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() * n as f64) as usize
        }
    }

    #[test]
    fn axis_values_bound_what_the_definitions_say_they_bound() {
        let mut rng = Lcg(20080666108);
        for case in 0..2000 {
            let n_targets = 1 + rng.below(12);
            let scale = 10f64.powf(-7.0 + 3.0 * rng.next());
            let mut m = Vec::new();
            for i in 0..n_targets {
                let target = (30.0 * i as f64).to_radians();
                for direction in [Up, Down] {
                    let offset = scale * (rng.next() - 0.5) * 20.0;
                    for run in 1..=2 + rng.below(5) as u32 {
                        let deviation = offset + scale * (rng.next() - 0.5);
                        m.push(Measurement {
                            target,
                            direction,
                            run,
                            deviation,
                        });
                    }
                }
            }
            let r = evaluate(&m).unwrap();
            assert_eq!(r.targets.len(), n_targets);
            let a = r.axis;
            let tol = 1e-12 * scale;
            let ge = |x: f64, y: f64, what: &str| {
                assert!(x >= y - tol, "case {case}: {what}: {x} < {y}\n{a:?}");
            };
            for t in &r.targets {
                ge(a.r, t.repeat, "R ≥ Ri");
                ge(t.repeat, t.reversal.abs(), "Ri ≥ |Bi|");
            }
            ge(a.r, a.r_up, "R ≥ R↑");
            ge(a.r, a.r_down, "R ≥ R↓");
            ge(a.r, a.b, "R ≥ B");
            ge(a.e, a.e_up, "E ≥ E↑");
            ge(a.e, a.e_down, "E ≥ E↓");
            ge(a.a, a.a_up, "A ≥ A↑");
            ge(a.a, a.a_down, "A ≥ A↓");
            ge(a.a, a.e, "A ≥ E");
            ge(a.e, a.m, "E ≥ M");
            ge(a.b, a.b_mean.abs(), "B ≥ |B̄|");
        }
    }

    /// Pure reversal, no scatter: every ↑ deviation +b/2, every ↓ −b/2, at the
    /// paper's 12 targets with 5 runs each.
    #[test]
    fn pure_reversal_gives_b_everywhere_and_zero_scatter() {
        let b = 32.8 / ARCSEC_PER_RAD;
        let m: Vec<_> = (0..12)
            .flat_map(|i| {
                [(Up, 0.5 * b), (Down, -0.5 * b)].into_iter().flat_map(
                    move |(direction, deviation)| {
                        (1..=5).map(move |run| Measurement {
                            target: (30.0 * i as f64).to_radians(),
                            direction,
                            run,
                            deviation,
                        })
                    },
                )
            })
            .collect();
        let r = evaluate(&m).unwrap();
        assert_eq!(r.targets.len(), 12);
        for t in &r.targets {
            assert_eq!((t.s_up, t.s_down), (0.0, 0.0));
            assert_eq!((t.reversal, t.repeat, t.mean_bidirectional), (b, b, 0.0));
        }
        let a = r.axis;
        assert_eq!((a.b, a.r, a.e, a.a), (b, b, b, b));
        close(a.b_mean, b, "B̄");
        assert_eq!(
            (a.r_up, a.r_down, a.e_up, a.e_down, a.m),
            (0.0, 0.0, 0.0, 0.0, 0.0)
        );
        assert_eq!((a.a_up, a.a_down), (0.0, 0.0));
    }

    #[test]
    fn empty_input_is_an_error() {
        assert_eq!(evaluate(&[]), Err(Iso230Error::Empty));
    }

    #[test]
    fn a_single_run_in_one_direction_is_named() {
        let m = measurements(&[
            (0.0, Up, &[1.0, 2.0]),
            (0.0, Down, &[1.0, 2.0]),
            (90.0, Up, &[1.0, 2.0]),
            (90.0, Down, &[1.0]),
        ]);
        let e = evaluate(&m).unwrap_err();
        assert!(matches!(
            e,
            Iso230Error::TooFewRuns { target_deg, direction: Down, runs: 1 }
                if (target_deg - 90.0).abs() < 1e-9
        ));
        let text = e.to_string();
        assert!(text.contains("90°") && text.contains("down"), "{text}");
    }

    #[test]
    fn a_target_measured_only_up_is_named() {
        let m = measurements(&[
            (0.0, Up, &[1.0, 2.0]),
            (0.0, Down, &[1.0, 2.0]),
            (180.0, Up, &[1.0, 2.0, 3.0]),
        ]);
        let e = evaluate(&m).unwrap_err();
        assert!(matches!(
            e,
            Iso230Error::OneDirection { target_deg, measured: Up }
                if (target_deg - 180.0).abs() < 1e-9
        ));
        let text = e.to_string();
        assert!(
            text.contains("180°") && text.contains("only in the up"),
            "{text}"
        );
    }

    #[test]
    fn non_finite_values_and_repeated_runs_are_errors() {
        let mut m = measurements(&[(0.0, Up, &[1.0, 2.0]), (0.0, Down, &[1.0, 2.0])]);
        m[2].deviation = f64::NAN;
        assert!(matches!(
            evaluate(&m),
            Err(Iso230Error::NotFinite {
                index: 2,
                field: "deviation",
                ..
            })
        ));
        m[2].deviation = 0.0;
        m[1].target = f64::INFINITY;
        assert!(matches!(
            evaluate(&m),
            Err(Iso230Error::NotFinite {
                index: 1,
                field: "target",
                ..
            })
        ));
        m[1].target = 0.0;
        m[3].run = m[2].run;
        assert!(matches!(
            evaluate(&m),
            Err(Iso230Error::DuplicateRun {
                direction: Down,
                run: 1,
                ..
            })
        ));
    }
}
