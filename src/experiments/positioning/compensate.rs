//! The backlash and angle (pitch) error compensation computed from an ISO 230-2
//! positioning record, and a record as the compensated axis would show it
//! (docs/compensation.md).
//!
//! From the measurements of the build runs (all, or a range such as runs 1–3), per
//! target Pi the mean deviations x̄i↑ and x̄i↓ of [`iso230::evaluate`]; then, in the
//! convention of [`crate::controller::Compensation`] (each value added to the
//! commanded position, the backlash while the commanded direction is down):
//!
//! ```text
//! table(Pi) = −x̄i↑                      at the targets, linear between them
//! backlash  = B̄ = (1/m)·Σi (x̄i↑ − x̄i↓)  the mean reversal value, signed
//! ```
//!
//! so that a deviation measured at Pi, corrected by the offset of its direction,
//! becomes `x + offset(Pi, dir)`: on the way up x − x̄i↑ (mean zero at every target),
//! on the way down x − x̄i↓ − (Bi − B̄) (mean zero up to the target-to-target scatter
//! of the reversal). A rotary axis whose targets lie within one turn gets a table
//! modulo 2π ([`table_of`] says how its ends are joined).
//!
//! The corrected record is a static prediction: each reading shifted by the offset
//! the controller would add at that target and direction. It does not simulate the
//! compensated axis (whose dynamics could differ slightly, e.g. the wind-up after a
//! larger reversal move).

use std::f64::consts::TAU;
use std::fmt;
use std::ops::RangeInclusive;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::iso230::{self, AxisStats, Direction, Iso230Error, Measurement, SAME_TARGET_RAD};
use crate::controller::{Compensation, ErrorTable};
use crate::model::Axis;

/// A range of run numbers, `4-5` or `3` in text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Runs(pub RangeInclusive<u32>);

/// A range of runs that cannot be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("runs `{text}`: {problem} (write a range like 1-3, or one run like 4)")]
pub struct RunsError {
    pub text: String,
    pub problem: &'static str,
}

impl FromStr for Runs {
    type Err = RunsError;

    fn from_str(text: &str) -> Result<Runs, RunsError> {
        let bad = |problem| RunsError {
            text: text.to_string(),
            problem,
        };
        let number = |s: &str| s.trim().parse::<u32>().map_err(|_| bad("not a run number"));
        let (first, last) = match text.split_once('-') {
            Some((a, b)) => (number(a)?, number(b)?),
            None => (number(text)?, number(text)?),
        };
        if first > last {
            return Err(bad("the first run is after the last"));
        }
        Ok(Runs(first..=last))
    }
}

impl fmt::Display for Runs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (a, b) = (self.0.start(), self.0.end());
        if a == b {
            write!(f, "{a}")
        } else {
            write!(f, "{a}-{b}")
        }
    }
}

impl Runs {
    /// Whether run `run` is in the range.
    pub fn contains(&self, run: u32) -> bool {
        self.0.contains(&run)
    }
}

/// Why a compensation cannot be computed or applied.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CompensateError {
    #[error("no measurement of runs {runs} in the record (its runs: {present})")]
    NoRuns { runs: Runs, present: String },
    #[error("runs {runs}: {source}")]
    Iso230 {
        runs: String,
        #[source]
        source: Iso230Error,
    },
}

/// Something the user must know before trusting a compensation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "code", rename_all = "snake_case")]
#[non_exhaustive]
pub enum CompensateWarning {
    /// The compensation built from the build runs does not lower the systematic
    /// positional deviation E of the other runs (rad): the axis drifts between runs
    /// (warm-up, load), and neither table nor backlash would help.
    NoImprovement { e_before: f64, e_after: f64 },
    /// On the other runs the table lowers E no further than the backlash alone does
    /// (rad): the position-dependent error drifts between runs, or scatters more
    /// than it varies; the table would not help (the backlash may).
    TableDoesNotHelp { e_backlash_only: f64, e_after: f64 },
    /// Every run was used to build the compensation (or fewer than two are left): the
    /// values after compensation are those of the runs it was fitted to, not a check.
    Unchecked { check_runs: usize },
    /// The compensation makes the bidirectional accuracy A of the other runs larger
    /// (rad or m): it moves their mean deviations towards the targets where they
    /// scatter most, or their error does not repeat that of the build runs.
    AccuracyWorse { a_before: f64, a_after: f64 },
    /// The compensation makes the bidirectional repeatability R of the other runs
    /// larger (rad or m): their reversal differs from the build runs' mean B̄ at some
    /// target, so the backlash leaves it larger there than it was.
    RepeatabilityWorse { r_before: f64, r_after: f64 },
}

impl CompensateWarning {
    /// The warning in words, deviations in `unit` (`″`, `µm`) at `per_si` per rad or m.
    pub fn message(&self, per_si: f64, unit: &str) -> String {
        let v = |x: &f64| format!("{:.2}{unit}", x * per_si);
        match self {
            CompensateWarning::NoImprovement { e_before, e_after } => format!(
                "the compensation does not lower the error on the runs it was not built from: \
                 E {} without it, {} with it; the axis drifts between runs (warm-up?): \
                 do not load it",
                v(e_before),
                v(e_after)
            ),
            CompensateWarning::TableDoesNotHelp {
                e_backlash_only,
                e_after,
            } => format!(
                "the error table does not help on the runs it was not built from: E {} with \
                 the backlash alone, {} with the table too; the position-dependent error of \
                 the build runs does not repeat (drift between runs, warm-up, or scatter \
                 larger than the table): load the backlash alone",
                v(e_backlash_only),
                v(e_after)
            ),
            CompensateWarning::AccuracyWorse { a_before, a_after } => format!(
                "the compensation makes the accuracy A of the runs it was not built from \
                 worse by {}: {} without it, {} with it; their error does not repeat that of \
                 the build runs, or scatters most where the table moves it: check it on more \
                 runs before loading it",
                v(&(a_after - a_before)),
                v(a_before),
                v(a_after)
            ),
            CompensateWarning::RepeatabilityWorse { r_before, r_after } => format!(
                "the compensation makes the repeatability R of the runs it was not built \
                 from worse by {}: {} without it, {} with it; their reversal differs from the \
                 build runs' mean B̄ at some target, where the backlash leaves it larger",
                v(&(r_after - r_before)),
                v(r_before),
                v(r_after)
            ),
            CompensateWarning::Unchecked { check_runs } => format!(
                "built from {}: the values after compensation are those of the runs it was \
                 fitted to; keep runs aside (--runs 1-3 of 5) to check it",
                match check_runs {
                    0 => "every run".to_string(),
                    n => format!("all runs but {n}"),
                }
            ),
        }
    }
}

/// One target of the build runs (rad or m).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TargetRow {
    pub target: f64,
    /// x̄i↑.
    pub mean_up: f64,
    /// x̄i↓.
    pub mean_down: f64,
    /// Bi = x̄i↑ − x̄i↓.
    pub reversal: f64,
    /// The table's value at the target (−x̄i↑, or the wrapped mean at 0 and 2π).
    pub table: f64,
}

/// The ISO 230-2 axis values of some runs without and with the compensation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BeforeAfter {
    pub before: AxisStats,
    /// With the backlash alone (no table).
    pub backlash_only: AxisStats,
    pub after: AxisStats,
}

/// A compensation computed from a positioning record, with what it does.
#[derive(Clone, Debug, PartialEq)]
pub struct Computed {
    pub axis: Axis,
    /// Backlash B̄ and table; no friction compensation.
    pub compensation: Compensation,
    /// The runs it was built from, ascending.
    pub build_runs: Vec<u32>,
    /// The other runs of the record, ascending.
    pub check_runs: Vec<u32>,
    pub targets: Vec<TargetRow>,
    /// On the build runs.
    pub build: BeforeAfter,
    /// On the other runs, when there are at least two.
    pub check: Option<BeforeAfter>,
    pub warnings: Vec<CompensateWarning>,
}

/// The measurements of runs `runs` (all of them for `None`).
pub fn select(measurements: &[Measurement], runs: Option<&Runs>) -> Vec<Measurement> {
    measurements
        .iter()
        .filter(|m| runs.map_or(true, |r| r.contains(m.run)))
        .copied()
        .collect()
}

/// The run numbers present in `measurements`, ascending, once each.
pub fn run_numbers(measurements: &[Measurement]) -> Vec<u32> {
    let mut runs: Vec<u32> = measurements.iter().map(|m| m.run).collect();
    runs.sort_unstable();
    runs.dedup();
    runs
}

/// Each deviation as the compensated axis would show it: `deviation +
/// position_offset(target, direction == down)` (the axis goes that much further).
pub fn apply(measurements: &[Measurement], compensation: &Compensation) -> Vec<Measurement> {
    measurements
        .iter()
        .map(|m| Measurement {
            deviation: m.deviation
                + compensation.position_offset(m.target, m.direction == Direction::Down),
            ..*m
        })
        .collect()
}

/// The ISO 230-2 axis values of `measurements` without `compensation`, with its
/// backlash alone, and with all of it.
pub fn before_after(
    measurements: &[Measurement],
    compensation: &Compensation,
) -> Result<BeforeAfter, Iso230Error> {
    let backlash = Compensation {
        table: None,
        ..compensation.clone()
    };
    Ok(BeforeAfter {
        before: iso230::evaluate(measurements)?.axis,
        backlash_only: iso230::evaluate(&apply(measurements, &backlash))?.axis,
        after: iso230::evaluate(&apply(measurements, compensation))?.axis,
    })
}

/// The compensation of `axis` built from runs `runs` of `measurements` (all for
/// `None`), its effect on those runs and on the others, and the warnings.
pub fn compute(
    measurements: &[Measurement],
    axis: Axis,
    runs: Option<&Runs>,
) -> Result<Computed, CompensateError> {
    let all_runs = run_numbers(measurements);
    let build_set = select(measurements, runs);
    let build_runs = run_numbers(&build_set);
    if let (Some(r), true) = (runs, build_runs.is_empty()) {
        return Err(CompensateError::NoRuns {
            runs: r.clone(),
            present: list(&all_runs),
        });
    }
    let iso = |runs: &[u32]| {
        let runs = list(runs);
        move |source| CompensateError::Iso230 { runs, source }
    };
    let report = iso230::evaluate(&build_set).map_err(iso(&build_runs))?;
    let table = table_of(&report.targets, axis);
    let compensation = Compensation {
        backlash: Some(report.axis.b_mean),
        table: Some(table),
        friction: None,
    };
    let targets = rows(&report.targets, &compensation);
    let build = before_after(&build_set, &compensation).map_err(iso(&build_runs))?;
    let check_runs: Vec<u32> = all_runs
        .into_iter()
        .filter(|r| !build_runs.contains(r))
        .collect();
    let check = if check_runs.len() >= 2 {
        let check_set: Vec<Measurement> = measurements
            .iter()
            .filter(|m| check_runs.contains(&m.run))
            .copied()
            .collect();
        Some(before_after(&check_set, &compensation).map_err(iso(&check_runs))?)
    } else {
        None
    };
    let warnings = warnings(check.as_ref(), check_runs.len());
    Ok(Computed {
        axis,
        compensation,
        build_runs,
        check_runs,
        targets,
        build,
        check,
        warnings,
    })
}

/// The warnings of a compensation checked (or not) on the other runs: on E first,
/// then on A and R.
fn warnings(check: Option<&BeforeAfter>, check_runs: usize) -> Vec<CompensateWarning> {
    let Some(c) = check else {
        return vec![CompensateWarning::Unchecked { check_runs }];
    };
    e_warning(c).into_iter().chain(worse(c)).collect()
}

/// The warning on the systematic deviation E of the check runs, if any.
fn e_warning(c: &BeforeAfter) -> Option<CompensateWarning> {
    if c.after.e >= c.before.e {
        Some(CompensateWarning::NoImprovement {
            e_before: c.before.e,
            e_after: c.after.e,
        })
    } else if c.after.e >= c.backlash_only.e {
        Some(CompensateWarning::TableDoesNotHelp {
            e_backlash_only: c.backlash_only.e,
            e_after: c.after.e,
        })
    } else {
        None
    }
}

/// The warnings on A and R of the check runs: each where the compensation makes it
/// larger than without, beyond the rounding of the two computations.
fn worse(c: &BeforeAfter) -> Vec<CompensateWarning> {
    let larger = |before: f64, after: f64| after - before > WORSE_TOLERANCE * before.abs();
    let mut w = Vec::new();
    if larger(c.before.a, c.after.a) {
        w.push(CompensateWarning::AccuracyWorse {
            a_before: c.before.a,
            a_after: c.after.a,
        });
    }
    if larger(c.before.r, c.after.r) {
        w.push(CompensateWarning::RepeatabilityWorse {
            r_before: c.before.r,
            r_after: c.after.r,
        });
    }
    w
}

/// The relative growth of A or R below which it is rounding, not a worse axis: the
/// scatter terms are computed anew from shifted readings.
const WORSE_TOLERANCE: f64 = 1e-9;

/// The build runs' targets with the table's value at each.
fn rows(targets: &[iso230::TargetStats], compensation: &Compensation) -> Vec<TargetRow> {
    targets
        .iter()
        .map(|t| TargetRow {
            target: t.target,
            mean_up: t.mean_up,
            mean_down: t.mean_down,
            reversal: t.reversal,
            table: compensation.position_offset(t.target, false),
        })
        .collect()
}

/// Run numbers as text: `1, 2, 3`.
fn list(runs: &[u32]) -> String {
    let text: Vec<String> = runs.iter().map(u32::to_string).collect();
    text.join(", ")
}

/// The error table of −x̄i↑ at the targets (ascending, at least one).
///
/// On a rotary axis whose targets lie within one turn the table is modulo 2π: the
/// targets are taken modulo 2π, targets that coincide there (0° and 360°) share one
/// point whose value is the mean of theirs, and the table gets points at 0 and at 2π
/// with one value, interpolated across the gap between the last target and the first
/// one turn on (so that the controller's table, which holds its end values outside
/// its points, interpolates across 360° → 0°). Otherwise (a linear axis, or targets
/// over more than one turn) the table's points are the targets.
pub fn table_of(targets: &[iso230::TargetStats], axis: Axis) -> ErrorTable {
    let points: Vec<(f64, f64)> = targets.iter().map(|t| (t.target, -t.mean_up)).collect();
    let first = points[0].0;
    let last = points[points.len() - 1].0;
    if axis == Axis::Rotary && last - first <= TAU + SAME_TARGET_RAD {
        return modulo_table(&points);
    }
    ErrorTable {
        positions: points.iter().map(|p| p.0).collect(),
        values: points.iter().map(|p| p.1).collect(),
        modulo: None,
    }
}

/// A table modulo 2π through `points` (position, value) within one turn.
fn modulo_table(points: &[(f64, f64)]) -> ErrorTable {
    let mut wrapped: Vec<(f64, f64)> = points
        .iter()
        .map(|&(p, v)| {
            let w = p.rem_euclid(TAU);
            (if TAU - w <= SAME_TARGET_RAD { 0.0 } else { w }, v)
        })
        .collect();
    wrapped.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Merge the points that coincide modulo 2π.
    let mut merged: Vec<(f64, f64, usize)> = Vec::new();
    for (p, v) in wrapped {
        match merged.last_mut() {
            Some(m) if p - m.0 <= SAME_TARGET_RAD => {
                m.1 += v;
                m.2 += 1;
            }
            _ => merged.push((p, v, 1)),
        }
    }
    let mut pts: Vec<(f64, f64)> = merged.iter().map(|m| (m.0, m.1 / m.2 as f64)).collect();
    let (p0, v0) = pts[0];
    let (pn, vn) = pts[pts.len() - 1];
    // The value at 0 ≡ 2π, linear from the last point to the first one turn on.
    let gap = p0 + TAU - pn;
    let at_zero = if p0 <= SAME_TARGET_RAD {
        v0
    } else {
        vn + (v0 - vn) * (TAU - pn) / gap
    };
    if p0 > SAME_TARGET_RAD {
        pts.insert(0, (0.0, at_zero));
    }
    pts.push((TAU, at_zero));
    ErrorTable {
        positions: pts.iter().map(|p| p.0).collect(),
        values: pts.iter().map(|p| p.1).collect(),
        modulo: Some(TAU),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::positioning::iso230::ARCSEC_PER_RAD;
    use Direction::{Down, Up};

    /// Readings at `targets_deg`: up `f(P) − b/2`, down `f(P) + b/2 + g(P)`, plus
    /// `noise(run)`, runs 1…n, in arc-seconds.
    fn record(
        targets_deg: &[f64],
        runs: u32,
        value: impl Fn(f64, Direction, u32) -> f64,
    ) -> Vec<Measurement> {
        let mut m = Vec::new();
        for run in 1..=runs {
            for &t in targets_deg {
                for direction in [Up, Down] {
                    m.push(Measurement {
                        target: t.to_radians(),
                        direction,
                        run,
                        deviation: value(t, direction, run) / ARCSEC_PER_RAD,
                    });
                }
            }
        }
        m
    }

    fn profile(t: f64) -> f64 {
        4.0 * (t.to_radians() * 2.0).sin() + 0.01 * t
    }

    #[test]
    fn runs_read_and_print_as_ranges() {
        assert_eq!("1-3".parse::<Runs>().unwrap(), Runs(1..=3));
        assert_eq!("4".parse::<Runs>().unwrap(), Runs(4..=4));
        assert_eq!(Runs(4..=5).to_string(), "4-5");
        assert_eq!(Runs(2..=2).to_string(), "2");
        for bad in ["3-1", "a-3", "", "1-", "-2"] {
            let e = bad.parse::<Runs>().unwrap_err().to_string();
            assert!(e.contains(&format!("`{bad}`")), "{e}");
        }
    }

    /// Without scatter, a table and backlash from the record cancel it exactly up
    /// to the reversal's scatter Bi − B̄, which here is the (known) g(P).
    #[test]
    fn table_and_backlash_cancel_the_mean_deviations() {
        let g = |t: f64| 0.5 * (t / 90.0 - 1.0);
        let m = record(&[0.0, 45.0, 90.0, 135.0, 180.0], 4, |t, d, run| {
            let noise = 0.1 * (run as f64 - 2.5);
            match d {
                Up => profile(t) - 15.0 + noise,
                Down => profile(t) + 15.0 + g(t) + noise,
            }
        });
        let c = compute(&m, Axis::Rotary, None).unwrap();
        // B̄ = −30 − mean(g) = −30 (g is zero mean over the symmetric targets).
        let b = c.compensation.backlash.unwrap() * ARCSEC_PER_RAD;
        assert!((b + 30.0).abs() < 1e-9, "{b}");
        let corrected = iso230::evaluate(&apply(&m, &c.compensation)).unwrap();
        for t in &corrected.targets {
            let t_deg = t.target.to_degrees();
            let up = t.mean_up * ARCSEC_PER_RAD;
            let down = t.mean_down * ARCSEC_PER_RAD;
            assert!(up.abs() < 1e-9, "{t_deg}° up {up}");
            assert!((down - g(t_deg)).abs() < 1e-9, "{t_deg}° down {down}");
        }
        assert_eq!(
            c.warnings,
            vec![CompensateWarning::Unchecked { check_runs: 0 }]
        );
        assert!(c.check.is_none());
    }

    #[test]
    fn a_rotary_table_over_one_turn_wraps_and_joins_its_ends() {
        // 0° and 360° both measured: one value, their mean, at 0 and 2π.
        let m = record(&[0.0, 120.0, 240.0, 360.0], 2, |t, _, _| match t as i32 {
            0 => 2.0,
            360 => 4.0,
            _ => profile(t),
        });
        let c = compute(&m, Axis::Rotary, None).unwrap();
        let table = c.compensation.table.unwrap();
        assert_eq!(table.modulo, Some(TAU));
        assert_eq!(table.positions.len(), 4);
        assert_eq!(table.positions[3], TAU);
        assert!((table.values[0] * ARCSEC_PER_RAD + 3.0).abs() < 1e-9);
        assert_eq!(table.values[0], table.values[3]);
        table.check().unwrap();
        // Targets 15°…345°: the ends joined across 0° linearly.
        let m = record(
            &[15.0, 345.0],
            2,
            |t, _, _| if t < 90.0 { 3.0 } else { 1.0 },
        );
        let table = table_of(&iso230::evaluate(&m).unwrap().targets, Axis::Rotary);
        let v: Vec<f64> = table.values.iter().map(|v| v * ARCSEC_PER_RAD).collect();
        assert_eq!(table.positions.len(), 4);
        assert!(
            (v[0] + 2.0).abs() < 1e-9 && (v[3] + 2.0).abs() < 1e-9,
            "{v:?}"
        );
        let at_355 = table.at(355f64.to_radians()) * ARCSEC_PER_RAD;
        assert!(
            (at_355 + (1.0 + 2.0 * 10.0 / 30.0)).abs() < 1e-9,
            "{at_355}"
        );
    }

    #[test]
    fn a_linear_axis_and_targets_over_a_turn_do_not_wrap() {
        let m = record(&[0.0, 200.0, 400.0], 2, |t, _, _| profile(t));
        for axis in [Axis::Linear, Axis::Rotary] {
            let c = compute(&m, axis, None).unwrap();
            let table = c.compensation.table.unwrap();
            assert_eq!(table.modulo, None, "{axis:?}");
            assert_eq!(table.positions.len(), 3);
        }
    }

    /// Runs 4–5 with the profile turned the other way: the table of runs 1–3
    /// makes them worse than the backlash alone, and says so; with the reversal
    /// turned too, the whole compensation makes them worse.
    #[test]
    fn a_drifting_axis_is_warned_about() {
        let targets = [0.0, 60.0, 120.0, 180.0, 240.0, 300.0];
        let half = |d: Direction| if d == Up { -10.0 } else { 10.0 };
        let steady = record(&targets, 5, |t, d, run| {
            profile(t) + half(d) + 0.05 * run as f64
        });
        let c = compute(&steady, Axis::Rotary, Some(&Runs(1..=3))).unwrap();
        assert_eq!(
            (c.build_runs.clone(), c.check_runs.clone()),
            (vec![1, 2, 3], vec![4, 5])
        );
        assert!(c.warnings.is_empty(), "{:?}", c.warnings);
        let check = c.check.unwrap();
        assert!(check.after.e < 0.1 * check.before.e, "{check:?}");
        let drifting = record(&targets, 5, |t, d, run| {
            (3.0 - run as f64) * profile(t) + half(d)
        });
        let c = compute(&drifting, Axis::Rotary, Some(&Runs(1..=3))).unwrap();
        assert!(
            matches!(c.warnings[..], [CompensateWarning::TableDoesNotHelp { e_backlash_only, e_after }] if e_after >= e_backlash_only),
            "{:?}",
            c.warnings
        );
        let text = c.warnings[0].message(ARCSEC_PER_RAD, "″");
        assert!(text.contains("drift") && text.contains("table"), "{text}");
        let reversed = record(&targets, 5, |t, d, run| {
            (3.0 - run as f64) * (profile(t) + half(d))
        });
        let c = compute(&reversed, Axis::Rotary, Some(&Runs(1..=3))).unwrap();
        // Everything worse on runs 4–5: E, and A and R with it.
        assert!(
            matches!(c.warnings[..], [
                CompensateWarning::NoImprovement { e_before, e_after },
                CompensateWarning::AccuracyWorse { .. },
                CompensateWarning::RepeatabilityWorse { .. },
            ] if e_after >= e_before),
            "{:?}",
            c.warnings
        );
    }

    /// Runs 4–5 scatter by s = 2″ at 0°, where their mean lies inside the others'
    /// range; the table of runs 1–3 lowers their E from 10″ to 8″ but moves 0° to
    /// the edge: A grows from 10″ to 12″, and the warning says so.
    #[test]
    fn an_accuracy_made_worse_is_warned_about() {
        let spread = std::f64::consts::SQRT_2;
        let m = record(&[0.0, 90.0, 180.0], 5, |t, _, run| match (t as i32, run) {
            (0, 1..=3) => 13.0,
            (0, 4) => 5.0 + spread,
            (0, _) => 5.0 - spread,
            (90, _) => 10.0,
            _ => 0.0,
        });
        let c = compute(&m, Axis::Rotary, Some(&Runs(1..=3))).unwrap();
        let check = c.check.unwrap();
        let arcsec = |x: f64| x * ARCSEC_PER_RAD;
        assert!(
            arcsec(check.after.e) < arcsec(check.before.e) - 1.9,
            "{check:?}"
        );
        let [CompensateWarning::AccuracyWorse { a_before, a_after }] = c.warnings[..] else {
            panic!("{:?}", c.warnings);
        };
        assert!((arcsec(a_before) - 10.0).abs() < 1e-6, "{a_before}");
        assert!((arcsec(a_after) - 12.0).abs() < 1e-6, "{a_after}");
        let text = c.warnings[0].message(ARCSEC_PER_RAD, "″");
        for part in [
            "accuracy A",
            "worse by 2.00″",
            "10.00″ without it",
            "12.00″ with it",
        ] {
            assert!(text.contains(part), "{part}: {text}");
        }
    }

    /// Runs 4–5 have no reversal at 0° (and scatter there) where runs 1–3 had −30″:
    /// the backlash corrects the other targets and leaves 30″ of reversal at 0°, so R
    /// grows from 30″ to 38″ while E falls from 50″ to 30″.
    #[test]
    fn a_repeatability_made_worse_is_warned_about() {
        let spread = std::f64::consts::SQRT_2;
        let profile = |t: f64| if t > 100.0 { 20.0 } else { 0.0 };
        let m = record(&[0.0, 90.0, 180.0], 5, |t, d, run| {
            let half = if d == Up { -15.0 } else { 15.0 };
            match (t as i32, run) {
                (0, 4) => spread,
                (0, 5) => -spread,
                _ => profile(t) + half,
            }
        });
        let c = compute(&m, Axis::Rotary, Some(&Runs(1..=3))).unwrap();
        let check = c.check.unwrap();
        let arcsec = |x: f64| x * ARCSEC_PER_RAD;
        assert!((arcsec(check.before.e) - 50.0).abs() < 1e-6, "{check:?}");
        assert!((arcsec(check.after.e) - 30.0).abs() < 1e-6, "{check:?}");
        let [CompensateWarning::RepeatabilityWorse { r_before, r_after }] = c.warnings[..] else {
            panic!("{:?}", c.warnings);
        };
        assert!((arcsec(r_before) - 30.0).abs() < 1e-6, "{r_before}");
        assert!((arcsec(r_after) - 38.0).abs() < 1e-6, "{r_after}");
        let text = c.warnings[0].message(ARCSEC_PER_RAD, "″");
        assert!(
            text.contains("repeatability R") && text.contains("worse by 8.00″"),
            "{text}"
        );
        // In µm on a linear axis: the unit is the caller's.
        let w = CompensateWarning::RepeatabilityWorse {
            r_before: 3e-6,
            r_after: 4.5e-6,
        };
        assert!(w.message(1e6, "µm").contains("worse by 1.50µm"));
    }

    #[test]
    fn runs_absent_from_the_record_are_named() {
        let m = record(&[0.0, 90.0], 3, |t, _, _| profile(t));
        let e = compute(&m, Axis::Rotary, Some(&Runs(7..=9))).unwrap_err();
        assert_eq!(
            e.to_string(),
            "no measurement of runs 7-9 in the record (its runs: 1, 2, 3)"
        );
        let e = compute(&m, Axis::Rotary, Some(&Runs(3..=3))).unwrap_err();
        assert!(e.to_string().starts_with("runs 3: "), "{e}");
    }
}
