//! The positioning test as an ensemble (docs/experiments.md (positioning), issue 58):
//! the same ISO 230-2 cycle on the same machine, run under perturbations that do not
//! change the machine, because where an axis with stick friction comes to rest is
//! decided by differences far below its encoder's count. On the worm gear a change of
//! the compensation's backlash by 1e-12° moves A after compensation by up to 1″: one
//! run is one draw of a distribution, and an ensemble gives its mean and spread.
//!
//! Member k ([`Ensemble::perturbation`]):
//!
//! - member 0 is the test as given (bit for bit [`super::run`]'s readings);
//! - member k ≥ 1 adds a sub-count offset δk to the compensation's backlash value
//!   (the offset the controller adds to the command while it moves downwards; a
//!   compensation that is off gets a backlash of δk alone): |δk| log-spaced from
//!   1e-8 to 1e-2 of the table encoder's count (1e-12° to 1e-6° on the presets'
//!   0.0001° encoder; a count of 1″ or 1 µm where the encoder is exact), alternating
//!   in sign. Every reversal then starts the axis on a slightly different path, and
//!   the stops fall where they may;
//! - member k's measurement noise (if the test adds any) is drawn from the seed
//!   `seed + k`.
//!
//! The members run four at a time in the kernel's lanes (one parameter set, a
//! compensation and a seed per lane), their lane batches in parallel on the cores.

use rayon::prelude::*;
use serde::Serialize;

use super::iso230::{self, AxisStats, Iso230Error, Measurement, ReportUnits};
use super::{run_lanes, test_params, Lane, PositioningTest};
use crate::controller::Compensation;
use crate::model::Params;
use crate::sim::{SimError, LANES};

/// Members of an ensemble unless told otherwise.
pub const DEFAULT_MEMBERS: usize = 8;
/// The most members an ensemble may have.
pub const MAX_MEMBERS: usize = 256;
/// The smallest and largest offset, as fractions of the table encoder's count.
pub const SMALLEST_OFFSET: f64 = 1e-8;
pub const LARGEST_OFFSET: f64 = 1e-2;

/// How many members, and so how the members differ (the module's doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Ensemble {
    /// Members, the unperturbed run among them (1 to [`MAX_MEMBERS`]).
    pub members: usize,
}

impl Default for Ensemble {
    fn default() -> Self {
        Ensemble {
            members: DEFAULT_MEMBERS,
        }
    }
}

/// What member k of an ensemble changes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perturbation {
    /// Added to the compensation's backlash value, rad or m (0 for member 0).
    pub offset: f64,
    /// Added to the test's noise seed.
    pub seed: u64,
}

/// Why an ensemble gave no values.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EnsembleError {
    #[error("an ensemble has 1 to {MAX_MEMBERS} members: got {0}")]
    Members(usize),
    #[error("ensemble member {member}: {source}")]
    Sim {
        member: usize,
        #[source]
        source: SimError,
    },
    #[error("ensemble member {member}: {source}")]
    Iso230 {
        member: usize,
        #[source]
        source: Iso230Error,
    },
}

impl Ensemble {
    /// An ensemble of `members` members (1 to [`MAX_MEMBERS`]).
    pub fn new(members: usize) -> Result<Ensemble, EnsembleError> {
        if (1..=MAX_MEMBERS).contains(&members) {
            Ok(Ensemble { members })
        } else {
            Err(EnsembleError::Members(members))
        }
    }

    /// Member `k`'s perturbation on `p`'s axis.
    pub fn perturbation(&self, k: usize, p: &Params) -> Perturbation {
        Perturbation {
            offset: self.fraction(k) * count(p),
            seed: k as u64,
        }
    }

    /// Member `k`'s offset as a fraction of a count: 0 for member 0, then log-spaced
    /// from [`SMALLEST_OFFSET`] to [`LARGEST_OFFSET`], alternating in sign.
    fn fraction(&self, k: usize) -> f64 {
        if k == 0 {
            return 0.0;
        }
        let perturbed = self.members - 1;
        let (lo, hi) = (SMALLEST_OFFSET.log10(), LARGEST_OFFSET.log10());
        let j = k - 1;
        let exponent = if perturbed < 2 {
            hi
        } else {
            lo + (hi - lo) * j as f64 / (perturbed - 1) as f64
        };
        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
        sign * 10f64.powf(exponent)
    }

    /// Member `k`'s compensation on `p`'s axis: `base` with the member's offset
    /// added to its backlash value (`base` itself for member 0).
    pub fn compensation(&self, k: usize, p: &Params, base: &Compensation) -> Compensation {
        let offset = self.perturbation(k, p).offset;
        let mut c = base.clone();
        if offset != 0.0 {
            c.backlash = Some(c.backlash.unwrap_or(0.0) + offset);
        }
        c
    }

    /// Member `k`'s lane: the test's compensation perturbed, the noise seed moved on.
    fn lane(&self, k: usize, p: &Params, test: &PositioningTest) -> Lane {
        Lane {
            compensation: self.compensation(k, p, &test.compensation),
            seed: test.seed.wrapping_add(self.perturbation(k, p).seed),
        }
    }
}

/// The table encoder's count on `p`'s axis, rad or m: its resolution, or one report
/// unit (1″, 1 µm) where it is exact.
fn count(p: &Params) -> f64 {
    let r = p.controller.table_encoder_resolution;
    if r > 0.0 {
        r
    } else {
        1.0 / ReportUnits::of(p.axis).deviation_per_si
    }
}

/// Statistics of one figure over an ensemble's members.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Spread {
    pub mean: f64,
    /// The members' sample standard deviation (n − 1; 0 for one member).
    pub sd: f64,
    pub min: f64,
    pub max: f64,
}

impl Spread {
    /// The statistics of `values` (at least one).
    pub fn of(values: &[f64]) -> Spread {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let ss: f64 = values.iter().map(|v| (v - mean).powi(2)).sum();
        Spread {
            mean,
            sd: if values.len() > 1 {
                (ss / (n - 1.0)).sqrt()
            } else {
                0.0
            },
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }
}

/// The ISO 230-2 values of an ensemble's members and their statistics, in the axis's
/// report units (″ or µm).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PositioningEnsemble {
    /// Members (the first the unperturbed run).
    pub size: usize,
    /// Each member's backlash offset, report units.
    pub offsets: Vec<f64>,
    /// Each member's values.
    pub members: Vec<AxisStats>,
    /// The members' mean, sample standard deviation, least and largest, field by
    /// field.
    pub mean: AxisStats,
    pub sd: AxisStats,
    pub min: AxisStats,
    pub max: AxisStats,
    /// `″` or `µm`.
    pub unit: &'static str,
}

impl PositioningEnsemble {
    /// The statistics of one value (`|s| s.a`) over the members.
    pub fn spread(&self, value: impl Fn(&AxisStats) -> f64) -> Spread {
        Spread::of(&self.members.iter().map(value).collect::<Vec<_>>())
    }
}

/// The ensemble of `test` on `params`: each member's ISO 230-2 values and their
/// statistics. One call per parameter set; the members run in the kernel's lanes.
pub fn run(
    params: &Params,
    test: &PositioningTest,
    ensemble: &Ensemble,
) -> Result<PositioningEnsemble, EnsembleError> {
    let readings = readings(params, test, ensemble)?;
    evaluate(params, ensemble, &readings)
}

/// [`run`] on each of `params`, in order.
pub fn run_batch(
    params: &[Params],
    test: &PositioningTest,
    ensemble: &Ensemble,
) -> Vec<Result<PositioningEnsemble, EnsembleError>> {
    let jobs: Vec<(Params, PositioningTest)> =
        params.iter().map(|p| (p.clone(), test.clone())).collect();
    readings_batch(&jobs, ensemble)
        .into_iter()
        .zip(params)
        .map(|(r, p)| evaluate(p, ensemble, &r?))
        .collect()
}

/// Each member's readings of `test` on `params`, member 0 first.
pub fn readings(
    params: &Params,
    test: &PositioningTest,
    ensemble: &Ensemble,
) -> Result<Vec<Vec<Measurement>>, EnsembleError> {
    let job = [(params.clone(), test.clone())];
    readings_batch(&job, ensemble)
        .pop()
        .expect("one job, one result")
}

/// Each job's members' readings (a test on a parameter set, its compensation the
/// base of the members'), the jobs and their lane batches in parallel; a job whose
/// member fails (a simulation that diverges) gives that member's error.
pub fn readings_batch(
    jobs: &[(Params, PositioningTest)],
    ensemble: &Ensemble,
) -> Vec<Result<Vec<Vec<Measurement>>, EnsembleError>> {
    jobs.par_iter()
        .map(|(p, test)| {
            Ensemble::new(ensemble.members)?;
            let cycle = Cycle {
                p: &test_params(p, test),
                test,
                ensemble,
            };
            in_member_lanes(&cycle, ensemble.members)
                .into_iter()
                .enumerate()
                .map(|(member, r)| r.map_err(|source| EnsembleError::Sim { member, source }))
                .collect()
        })
        .collect()
}

/// A test whose ensemble members (of one parameter set) run side by side in the
/// kernel's lanes, member `k` as it runs alone.
pub trait MemberRun: Sync {
    type Out: Send;
    /// Members `members` at once: one result per member, or an error that stops them
    /// all.
    fn lanes<const L: usize>(
        &self,
        members: [usize; L],
    ) -> Result<[Result<Self::Out, SimError>; L], SimError>;
}

/// Members `0..members` of `run`, in order, [`LANES`] at a time (three run as four
/// with the last repeated), the lane batches in parallel.
pub fn in_member_lanes<R: MemberRun>(run: &R, members: usize) -> Vec<Result<R::Out, SimError>> {
    let starts: Vec<usize> = (0..members).step_by(LANES).collect();
    starts
        .par_iter()
        .map(|&first| {
            let ks: Vec<usize> = (first..(first + LANES).min(members)).collect();
            let k = |i: usize| ks[i.min(ks.len() - 1)];
            let out: Result<Vec<_>, SimError> = match ks.len() {
                1 => run.lanes::<1>([k(0)]).map(Vec::from),
                2 => run.lanes::<2>([k(0), k(1)]).map(Vec::from),
                _ => run.lanes::<LANES>(std::array::from_fn(k)).map(Vec::from),
            };
            match out {
                Ok(mut v) => {
                    v.truncate(ks.len());
                    v
                }
                Err(e) => ks.iter().map(|_| Err(e.clone())).collect(),
            }
        })
        .flatten_iter()
        .collect()
}

/// The cycle's members on one parameter set (already in the test's loop).
struct Cycle<'a> {
    p: &'a Params,
    test: &'a PositioningTest,
    ensemble: &'a Ensemble,
}

impl MemberRun for Cycle<'_> {
    type Out = Vec<Measurement>;

    fn lanes<const L: usize>(
        &self,
        members: [usize; L],
    ) -> Result<[Result<Vec<Measurement>, SimError>; L], SimError> {
        let lanes = members.map(|k| self.ensemble.lane(k, self.p, self.test));
        let params: [Params; L] = std::array::from_fn(|_| self.p.clone());
        run_lanes(&params, self.test, lanes, |_, _| {})
    }
}

/// The ensemble's values from its members' readings (member 0 first) on `params`'s
/// axis.
pub fn evaluate(
    params: &Params,
    ensemble: &Ensemble,
    readings: &[Vec<Measurement>],
) -> Result<PositioningEnsemble, EnsembleError> {
    let units = ReportUnits::of(params.axis);
    let k = units.deviation_per_si;
    let members = readings
        .iter()
        .enumerate()
        .map(|(member, r)| {
            iso230::evaluate(r)
                .map(|e| e.axis.scaled(k))
                .map_err(|source| EnsembleError::Iso230 { member, source })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let stat = |f: fn(&[f64]) -> f64| AxisStats::fieldwise(&members, f);
    Ok(PositioningEnsemble {
        size: members.len(),
        offsets: (0..members.len())
            .map(|m| ensemble.perturbation(m, params).offset * k)
            .collect(),
        mean: stat(|v| Spread::of(v).mean),
        sd: stat(|v| Spread::of(v).sd),
        min: stat(|v| Spread::of(v).min),
        max: stat(|v| Spread::of(v).max),
        members,
        unit: units.deviation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_offsets_span_the_sub_count_decades_alternating_in_sign() {
        let p = presets::load("worm-gear").unwrap();
        let e = Ensemble::default();
        let deg: Vec<f64> = (0..8)
            .map(|k| e.perturbation(k, &p).offset.to_degrees())
            .collect();
        assert_eq!(deg[0], 0.0);
        for (k, d) in deg.iter().enumerate().skip(1) {
            let want = 10f64.powi(-13 + k as i32) * if k % 2 == 1 { 1.0 } else { -1.0 };
            assert!(
                (d / want - 1.0).abs() < 1e-9,
                "member {k}: {d}° against {want}°"
            );
        }
        assert!(Ensemble::new(0).is_err() && Ensemble::new(MAX_MEMBERS + 1).is_err());
    }

    #[test]
    fn member_zero_is_the_test_and_the_others_run_as_they_would_alone() {
        let p = presets::load("worm-gear").unwrap();
        let test = PositioningTest {
            targets: vec![0.0, 0.2],
            runs: 2,
            dwell: 0.3,
            noise: 1e-6,
            ..PositioningTest::default()
        };
        let e = Ensemble::new(6).unwrap();
        let got = readings(&p, &test, &e).unwrap();
        assert_eq!(got.len(), 6);
        assert_eq!(got[0], super::super::run(&p, &test, |_, _| {}).unwrap());
        for (k, r) in got.iter().enumerate().skip(1) {
            let d = e.perturbation(k, &p);
            let alone = PositioningTest {
                compensation: crate::controller::Compensation {
                    backlash: Some(d.offset),
                    ..Default::default()
                },
                seed: test.seed + d.seed,
                ..test.clone()
            };
            assert_eq!(
                r,
                &super::super::run(&p, &alone, |_, _| {}).unwrap(),
                "member {k}"
            );
        }
        let stats = evaluate(&p, &e, &got).unwrap();
        let a = stats.spread(|s| s.a);
        assert_eq!(stats.mean.a, a.mean);
        assert!(a.min <= a.mean && a.mean <= a.max && a.sd >= 0.0);
        assert_eq!(stats.unit, "″");
    }
}
