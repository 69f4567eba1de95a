//! What a sweep measures at each parameter point, computed by the virtual experiments.
//!
//! | output | columns | how |
//! |---|---|---|
//! | `resonances` | `resonance_1_hz` … | peaks of the **exact linear** frequency response (fast) |
//! | `peak_gain` | `peak_gain_db` | the highest of those peaks (fast, linear) |
//! | `modes` | `mode_1_hz` … | undamped natural frequencies, motor held (fast, linear) |
//! | `reversal` | `reversal_arcsec` | ISO 230-2 mean reversal value B̄ of the positioning test |
//! | `repeatability` | `repeatability_arcsec` | ISO 230-2 bidirectional repeatability R |
//! | `accuracy` | `accuracy_arcsec` | ISO 230-2 bidirectional accuracy A |
//! | `fluctuation_pp` | `fluctuation_pp_arcsec` | peak-to-peak of θt − θm·Rg·Rw at constant speed |
//! | `torque_rms` | `torque_rms_nm` | RMS motor torque of the friction-torque test |
//!
//! The last five are nonlinear time simulations (servo, backlash, stick friction);
//! the three ISO 230-2 values share one positioning run. [`TestLength::Short`] (the
//! default of `rtid sweep`) shortens them to what a sweep can afford; the physics is
//! the same (module docs of [`TestLength`]).
//!
//! **Resonances.** The peaks of the exact linear gain (table over motor amplitude ×
//! Rg·Rw, docs/model.md) from half the lowest to twice the highest motor-held natural
//! frequency, found by [`crate::estimation::peaks::of_linear_response`] — the same function the
//! identification's resonance objective uses, so both report the same resonance for
//! the same parameters. The number of columns is
//! the number of motor-held modes of the base topology (worm 3, roller 2); column i is
//! the i-th peak in ascending frequency, empty when the gain has fewer peaks (a mode
//! that the motor torque hardly excites, or two that merged).

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::estimation::peaks::{self, Peak};
use crate::experiments::fluctuation::{self, FluctuationError, FluctuationTest};
use crate::experiments::positioning::iso230::{self, Iso230Error};
use crate::experiments::positioning::{self, PositioningTest};
use crate::experiments::torque_curve::{self, TorqueEvalError, TorqueTest};
use crate::model::modes;
use crate::model::{ParamError, Params, Topology};
use crate::names::UnknownName;
use crate::sim::SimError;

/// One requested output.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Output {
    Resonances,
    PeakGain,
    Modes,
    Reversal,
    Repeatability,
    Accuracy,
    FluctuationPp,
    TorqueRms,
}

/// Every output, in the order of the module docs.
pub const ALL: [Output; 8] = [
    Output::Resonances,
    Output::PeakGain,
    Output::Modes,
    Output::Reversal,
    Output::Repeatability,
    Output::Accuracy,
    Output::FluctuationPp,
    Output::TorqueRms,
];

impl Output {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Output::Resonances => "resonances",
            Output::PeakGain => "peak_gain",
            Output::Modes => "modes",
            Output::Reversal => "reversal",
            Output::Repeatability => "repeatability",
            Output::Accuracy => "accuracy",
            Output::FluctuationPp => "fluctuation_pp",
            Output::TorqueRms => "torque_rms",
        }
    }

    /// Its CSV columns (units in the names) for a drive of `topology`.
    pub fn columns(self, topology: Topology) -> Vec<String> {
        let held_modes = match topology {
            Topology::SpurGear => 3,
            Topology::Direct => 2,
            Topology::TwoMass => 1,
            Topology::DirectDrive => 0,
        };
        let numbered = |stem: &str| {
            (1..=held_modes)
                .map(|i| format!("{stem}_{i}_hz"))
                .collect::<Vec<_>>()
        };
        match self {
            Output::Resonances => numbered("resonance"),
            Output::Modes => numbered("mode"),
            Output::PeakGain => vec!["peak_gain_db".into()],
            Output::Reversal => vec!["reversal_arcsec".into()],
            Output::Repeatability => vec!["repeatability_arcsec".into()],
            Output::Accuracy => vec!["accuracy_arcsec".into()],
            Output::FluctuationPp => vec!["fluctuation_pp_arcsec".into()],
            Output::TorqueRms => vec!["torque_rms_nm".into()],
        }
    }
}

impl FromStr for Output {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, UnknownName> {
        ALL.into_iter()
            .find(|o| o.name() == s.trim())
            .ok_or_else(|| UnknownName {
                what: "output",
                given: s.to_string(),
                expected: ALL.map(Output::name).join(", "),
            })
    }
}

/// How long the nonlinear tests run.
///
/// - `Full`: the paper's tests as `rtid experiment` runs them (positioning: 13
///   targets × 5 runs × 2 directions, 1 s dwell, ≈ 190 s simulated; fluctuation: one
///   revolution each way at 180°/min, ≈ 250 s; torque: 3 periods of 3 s).
/// - `Short`: positioning at 5 targets every 10° (0°–40°) × 3 runs × 2 directions
///   with 0.5 s dwell (≈ 23 s; every target at the same phase of the worm's
///   fluctuation, as the 30° targets of the full test are: 30° is six worm
///   revolutions); fluctuation over 18° of table travel each way at 180°/min, the
///   peak-to-peak taken over the middle 10° (two worm revolutions), skipping 4° after
///   each start and reversal (≈ 13.5 s); torque curve over one recorded period after
///   one period of run-in (6 s).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum TestLength {
    #[default]
    Short,
    Full,
}

impl FromStr for TestLength {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, UnknownName> {
        match s {
            "short" => Ok(TestLength::Short),
            "full" => Ok(TestLength::Full),
            other => Err(UnknownName {
                what: "test length",
                given: other.to_string(),
                expected: "short or full".into(),
            }),
        }
    }
}

impl TestLength {
    /// The positioning test.
    pub fn positioning(self) -> PositioningTest {
        match self {
            TestLength::Full => PositioningTest::default(),
            TestLength::Short => PositioningTest {
                targets: (0..5).map(|i| (10.0 * i as f64).to_radians()).collect(),
                runs: 3,
                dwell: 0.5,
                ..PositioningTest::default()
            },
        }
    }

    /// The fluctuation test.
    pub fn fluctuation(self) -> FluctuationTest {
        match self {
            TestLength::Full => FluctuationTest::default(),
            TestLength::Short => FluctuationTest {
                revolutions: 0,
                run_in: 9f64.to_radians(),
                ..FluctuationTest::default()
            },
        }
    }

    /// The torque-curve test.
    pub fn torque(self) -> TorqueTest {
        match self {
            TestLength::Full => TorqueTest::default(),
            TestLength::Short => TorqueTest {
                periods: 1.0,
                ..TorqueTest::default()
            },
        }
    }
}

/// Why an output could not be computed at a point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error("simulation: {0}")]
    Sim(#[from] SimError),
    #[error("ISO 230-2: {0}")]
    Iso230(#[from] Iso230Error),
    #[error("fluctuation: {0}")]
    Fluctuation(#[from] FluctuationError),
    #[error("torque curve: {0}")]
    Torque(#[from] TorqueEvalError),
    #[error("{column} is not a finite number ({value})")]
    NotFinite { column: String, value: f64 },
}

/// The requested outputs of a sweep and the tests that compute them.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluator {
    pub outputs: Vec<Output>,
    pub tests: TestLength,
    pub topology: Topology,
}

impl Evaluator {
    /// Every column, in order.
    pub fn columns(&self) -> Vec<String> {
        self.outputs
            .iter()
            .flat_map(|o| o.columns(self.topology))
            .collect()
    }

    /// The outputs at `p`, one value per column (`None`: no such peak).
    pub fn evaluate(&self, p: &Params) -> Result<Vec<Option<f64>>, OutputError> {
        self.evaluate_with(p, Runs::default())
    }

    /// The outputs at each of `points`, in order, each what [`Evaluator::evaluate`]
    /// gives for it: the closed-loop tests of all the points (positioning,
    /// fluctuation, torque curve) run together in the kernel's lanes (their
    /// `run_batch`), the other outputs point by point.
    pub fn evaluate_batch(&self, points: &[Params]) -> Vec<Result<Vec<Option<f64>>, OutputError>> {
        let wants = |outputs: &[Output]| {
            points.len() > 1 && self.outputs.iter().any(|o| outputs.contains(o))
        };
        let mut runs: Vec<Runs> = points.iter().map(|_| Runs::default()).collect();
        if wants(&[Output::Reversal, Output::Repeatability, Output::Accuracy]) {
            let batch = positioning::run_batch(points, &self.tests.positioning());
            runs.iter_mut()
                .zip(batch)
                .for_each(|(r, m)| r.positioning = Some(m));
        }
        if wants(&[Output::FluctuationPp]) {
            let batch = fluctuation::run_batch(points, &self.tests.fluctuation());
            runs.iter_mut()
                .zip(batch)
                .for_each(|(r, m)| r.fluctuation = Some(m));
        }
        if wants(&[Output::TorqueRms]) {
            let batch = torque_curve::run_batch(points, &self.tests.torque());
            runs.iter_mut()
                .zip(batch)
                .for_each(|(r, m)| r.torque = Some(m));
        }
        points
            .iter()
            .zip(runs)
            .map(|(p, r)| self.evaluate_with(p, r))
            .collect()
    }

    /// [`Evaluator::evaluate`], with the closed-loop tests at `p` that were run
    /// already (`runs`).
    fn evaluate_with(&self, p: &Params, mut runs: Runs) -> Result<Vec<Option<f64>>, OutputError> {
        p.validate()?;
        let mut out = Vec::new();
        let mut peaks: Option<Vec<Peak>> = None;
        let mut iso: Option<iso230::AxisStats> = None;
        for &o in &self.outputs {
            let n = o.columns(self.topology).len();
            match o {
                Output::Resonances | Output::PeakGain => {
                    if peaks.is_none() {
                        peaks = Some(gain_peaks(p, n_held(self.topology))?);
                    }
                    let peaks = peaks.as_ref().expect("computed above");
                    if o == Output::Resonances {
                        out.extend((0..n).map(|i| peaks.get(i).map(|pk| pk.frequency_hz)));
                    } else {
                        out.push(peaks.iter().map(|pk| pk.gain_db).reduce(f64::max));
                    }
                }
                Output::Modes => {
                    let hz = modes::modes(p)?.clamped_hz;
                    out.extend((0..n).map(|i| hz.get(i).copied()));
                }
                Output::Reversal | Output::Repeatability | Output::Accuracy => {
                    if iso.is_none() {
                        let m = match runs.positioning.take() {
                            Some(m) => m?,
                            None => positioning::run(p, &self.tests.positioning(), |_, _| {})?,
                        };
                        iso = Some(iso230::evaluate(&m)?.axis.in_arcsec());
                    }
                    let a = iso.expect("computed above");
                    out.push(Some(match o {
                        Output::Reversal => a.b_mean,
                        Output::Repeatability => a.r,
                        _ => a.a,
                    }));
                }
                Output::FluctuationPp => {
                    let test = self.tests.fluctuation();
                    let record = match runs.fluctuation.take() {
                        Some(r) => r?,
                        None => fluctuation::run(p, &test, |_, _| {})?,
                    };
                    out.push(Some(match self.tests {
                        TestLength::Full => fluctuation::evaluate(&record, p.ratio())?.pp_arcsec,
                        TestLength::Short => short_fluctuation_pp(&record, &test, p.ratio()),
                    }));
                }
                Output::TorqueRms => {
                    let test = self.tests.torque();
                    let curve = match runs.torque.take() {
                        Some(c) => c?,
                        None => torque_curve::run(p, &test, |_, _| {})?,
                    };
                    out.push(Some(torque_curve::evaluate(&curve, &test)?.rms_nm));
                }
            }
        }
        for (column, v) in self.columns().into_iter().zip(&out) {
            if let Some(v) = *v {
                if !v.is_finite() {
                    return Err(OutputError::NotFinite { column, value: v });
                }
            }
        }
        Ok(out)
    }
}

/// The closed-loop tests of one point run already (in a batch's lanes), each taken
/// by the output that reads it.
#[derive(Default)]
struct Runs {
    positioning: Option<Result<Vec<iso230::Measurement>, SimError>>,
    fluctuation: Option<Result<fluctuation::Record, SimError>>,
    torque: Option<Result<torque_curve::TorqueCurve, SimError>>,
}

/// Travel skipped at each end of a pass of the short fluctuation test, rad: the
/// backlash take-up after the reversal and the servo's start-up.
pub const SHORT_FLUCTUATION_SKIP_DEG: f64 = 4.0;

/// Peak-to-peak of θt − θm·ratio, arc-seconds, over the steady middle of each pass
/// of the short test (its travel less [`SHORT_FLUCTUATION_SKIP_DEG`] at both ends,
/// located by the commanded schedule: dwell, ramp up, dwell, ramp down); the larger
/// of the two directions. [`fluctuation::evaluate`] analyses whole revolutions centred
/// in a pass and, with less than one revolution, the whole pass — reversal included.
fn short_fluctuation_pp(record: &fluctuation::Record, test: &FluctuationTest, ratio: f64) -> f64 {
    let travel = test.revolutions as f64 * std::f64::consts::TAU + 2.0 * test.run_in;
    let ramp = travel / test.speed;
    let skip = SHORT_FLUCTUATION_SKIP_DEG.to_radians() / test.speed;
    let up = (test.dwell + skip, test.dwell + ramp - skip);
    let down_start = 2.0 * test.dwell + ramp;
    let down = (down_start + skip, down_start + ramp - skip);
    let pp = |(a, b): (f64, f64)| {
        let (lo, hi) = record
            .time
            .iter()
            .zip(record.table_angle.iter().zip(&record.motor_angle))
            .filter(|(&t, _)| t >= a && t <= b)
            .map(|(_, (&th, &m))| (th - ratio * m) * iso230::ARCSEC_PER_RAD)
            .fold((f64::MAX, f64::MIN), |(l, h), d| (l.min(d), h.max(d)));
        if hi >= lo {
            hi - lo
        } else {
            0.0
        }
    };
    pp(up).max(pp(down))
}

/// Number of motor-held modes of a topology.
fn n_held(topology: Topology) -> usize {
    match topology {
        Topology::SpurGear => 3,
        Topology::Direct => 2,
        Topology::TwoMass => 1,
        Topology::DirectDrive => 0,
    }
}

/// The peaks of the exact linear gain curve (module docs), at most `max` of them (the
/// highest), ascending in frequency.
pub fn gain_peaks(p: &Params, max: usize) -> Result<Vec<Peak>, ParamError> {
    let hz = modes::modes(p)?.clamped_hz;
    let positive = hz.iter().copied().filter(|f| *f > 0.0 && f.is_finite());
    let (lo, hi) = positive.fold((f64::MAX, 0.0f64), |(l, h), f| (l.min(f), h.max(f)));
    if hi <= 0.0 {
        return Ok(Vec::new());
    }
    peaks::of_linear_response(p, 0.5 * lo, 2.0 * hi, max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_worm_resonances_are_near_its_motor_held_modes() {
        let p = presets::load("worm-gear").unwrap();
        let e = Evaluator {
            outputs: vec![Output::Resonances, Output::PeakGain, Output::Modes],
            tests: TestLength::Short,
            topology: p.topology,
        };
        let v = e.evaluate(&p).unwrap();
        assert_eq!(e.columns().len(), v.len());
        // docs/model.md §11: motor held 186.5, 236.9 Hz. The gain peaks of the damped drive
        // lie within 2 % of them (measured: 186.9 and 234.2 Hz; the second mode is the
        // more damped one, Ciw acting on the shaft-table twist).
        let (r1, r2) = (v[0].unwrap(), v[1].unwrap());
        let (m1, m2) = (v[4].unwrap(), v[5].unwrap());
        assert!(
            (m1 - 186.5).abs() < 0.1 && (m2 - 236.9).abs() < 0.1,
            "{v:?}"
        );
        assert!(
            (r1 - m1).abs() < 0.02 * m1 && (r2 - m2).abs() < 0.02 * m2,
            "{v:?}"
        );
        assert!(r1 != m1 && r2 != m2, "the peaks are the damped ones: {v:?}");
        assert!(v[3].unwrap() > 20.0, "a lightly damped peak is tall: {v:?}");
    }

    #[test]
    fn output_names_round_trip_and_unknown_ones_list_the_known() {
        for o in ALL {
            assert_eq!(o.name().parse::<Output>().unwrap(), o);
        }
        let err = "torque".parse::<Output>().unwrap_err();
        assert!(err.to_string().contains("torque_rms"), "{err}");
    }
}
