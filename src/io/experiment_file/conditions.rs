//! The `conditions` of a manifest — how an experiment was run — with docs/experiment-files.md's
//! defaults and the checks a frequency-response record and a servo trace need.

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::response::{Delay, Reference, Response};
use super::{sample_period, Kind};
use crate::model::params::{ControllerParams, LoopMode};
use crate::model::setpoint_filter::SetpointFilter;

/// How a frequency-response record was excited.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Excitation {
    /// A sine held for `dwell_s` at each of `frequencies_hz` in turn.
    SteppedSine,
    /// Random noise, a chirp or a multisine: every frequency at once.
    Broadband,
    /// A periodic multisine: the same excitation repeated every `period_s`, exciting
    /// only whole multiples of 1/`period_s` (Pintelon & Schoukens, *System
    /// Identification: A Frequency Domain Approach*, 2nd ed., 2012, §2.2 and §3.4), so
    /// whole periods can be transformed without leakage and averaged.
    Multisine,
}

impl Excitation {
    /// The name written to manifests.
    pub fn name(self) -> &'static str {
        match self {
            Excitation::SteppedSine => "stepped_sine",
            Excitation::Broadband => "broadband",
            Excitation::Multisine => "multisine",
        }
    }
}

/// A servo trace's (or a speed-loop response's) controller settings as the drive had
/// them, each replacing the model's where given (docs/experiment-files.md, servo trace).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveFunctions {
    /// The speed controller's proportional gain, as the model's `Kvp`.
    #[serde(rename = "Kvp", default, skip_serializing_if = "Option::is_none")]
    pub kvp: Option<f64>,
    /// The speed controller's integral gain, as the model's `Kvi`.
    #[serde(rename = "Kvi", default, skip_serializing_if = "Option::is_none")]
    pub kvi: Option<f64>,
    /// Velocity feed-forward, the fraction of the reference's speed.
    #[serde(rename = "Kvff", default, skip_serializing_if = "Option::is_none")]
    pub kvff: Option<f64>,
    /// Torque feed-forward, output per motor rad/s² (m/s²).
    #[serde(rename = "Kaff", default, skip_serializing_if = "Option::is_none")]
    pub kaff: Option<f64>,
    /// The symmetrising lag's time constant, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub symmetrising_s: Option<f64>,
    /// The torque-setpoint filters, in series.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filters: Option<Vec<SetpointFilter>>,
}

impl DriveFunctions {
    /// `controller` with these functions in place of its own.
    pub fn apply(&self, controller: &mut ControllerParams) {
        if let Some(v) = self.kvp {
            controller.kvp = v;
        }
        if let Some(v) = self.kvi {
            controller.kvi = v;
        }
        if let Some(v) = self.kvff {
            controller.kvff = v;
        }
        if let Some(v) = self.kaff {
            controller.kaff = v;
        }
        if let Some(v) = self.symmetrising_s {
            controller.symmetrising_s = v;
        }
        if let Some(f) = &self.filters {
            controller.filters = f.clone();
        }
    }
}

/// The `conditions` of a manifest: how the experiment was run. Every field is optional,
/// in the unit its name carries; [`Conditions::with_defaults`] fills in docs/experiment-files.md's
/// defaults. Unknown keys are kept in `extra`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Conditions {
    /// Frequency response: amplitude of the sinusoidal motor torque, N·m (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_amplitude_nm: Option<f64>,
    /// Frequency response: brake torque on the table, balanced by a motor DC torque, that
    /// keeps the flanks loaded (docs/experiments.md (frequency response)), N·m (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preload_nm: Option<f64>,
    /// Torque curve: amplitude of the commanded table motion, deg (default 30).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_deg: Option<f64>,
    /// Torque (force) curve on a linear axis: amplitude of the commanded motion, m (no
    /// default: `amplitude_deg`'s default is a rotary table's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_m: Option<f64>,
    /// Torque curve: period of the commanded table motion, s (default 3). Multisine
    /// frequency-response record: the period of the excitation, s (required).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// Feedback arrangement: `semi_closed` or `full_closed` (default `full_closed` for the
    /// torque curve, `semi_closed` for positioning, fluctuation and unbalance).
    #[serde(rename = "loop", default, skip_serializing_if = "Option::is_none")]
    pub loop_mode: Option<LoopMode>,
    /// Positioning: dwell at each target, s (default 1). Stepped-sine frequency
    /// response record: time spent at each frequency, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dwell_s: Option<f64>,
    /// Fluctuation and unbalance: table speed, deg/min (default 180 and 360).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_deg_per_min: Option<f64>,
    /// Fluctuation, unbalance and frequency-response records: table turns per motor
    /// turn, Rg·Rw (no default here: it comes from the mechanism).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio: Option<f64>,
    /// Unbalance: the offset mass, kg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Unbalance: the mass's distance from the table axis, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
    /// Frequency-response record: `stepped_sine`, `broadband` or `multisine` (default:
    /// stepped_sine when `frequencies_hz` is given, else broadband).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub excitation: Option<Excitation>,
    /// Stepped-sine frequency-response record: the drive frequencies in the order
    /// played, Hz, each held for `dwell_s` from the first sample on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequencies_hz: Option<Vec<f64>>,
    /// Multisine record: the lowest excited line, Hz (a whole multiple of 1/`period_s`).
    /// With `last_line_hz` and `line_step_hz` it names the excited lines first,
    /// first + step, …, up to last. Absent: not stated (every line may be excited).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_line_hz: Option<f64>,
    /// Multisine record: the highest excited line, Hz (below the Nyquist frequency).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub last_line_hz: Option<f64>,
    /// Multisine record: the spacing of the excited lines, Hz (a whole multiple of
    /// 1/`period_s`; default 1/`period_s`, every line; 2/`period_s` for an odd multisine).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_step_hz: Option<f64>,
    /// Multisine record: how many periods at the start are transient, to be dropped
    /// before averaging (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transient_periods: Option<u32>,
    /// Servo trace: the drive gain, the effort (N for a force column, N·m for a torque
    /// column) per unit of controller output (V, A, N·m or N, as its column says):
    /// docs/model.md §1's Kdrive. EMPS: 35.15 N/V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive_gain: Option<f64>,
    /// Servo trace: the sample period of the control loop, s, where it differs from the
    /// record's (a trace decimated for storage). Absent: the record's. Speed-loop
    /// response: the speed controller's sample period (absent: the model's `Tc`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_period_s: Option<f64>,
    /// Servo trace: the drive's functions as they were set when it was recorded
    /// (feed-forward, symmetrising lag, setpoint filters); a replay runs the model's
    /// controller with them. Speed-loop response: the speed controller's gains `Kvp`
    /// and `Kvi` where the measurement carries them (fitted otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<DriveFunctions>,
    /// Frequency response or resonances: the band in which resonances are sought,
    /// [lowest, highest] Hz (identification: the measured peaks, the gain curve and the
    /// model's peaks; `rtid identify --band` sets it). Absent: the whole curve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub band_hz: Option<[f64; 2]>,
    /// Frequency response: the ratio the file holds, `table_over_motor` (default) or
    /// `motor_compliance` ([`Response`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub response: Option<Response>,
    /// Frequency response: the channel the analyser divided by ([`Reference`]; default
    /// the ratio's own: the motor angle, or the motor torque for a compliance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<Reference>,
    /// Frequency response: the measurement chain's delay in the phase, s, or
    /// `"unknown"` to fit it ([`Delay`]; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay_s: Option<Delay>,
    /// Frequency response with a `coherence` column: the segments averaged per line,
    /// which with the coherence gives each line's noise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub averages: Option<u32>,
    /// Condition keys this version does not know, kept as written.
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

impl Conditions {
    /// The JSON keys of the typed fields.
    pub const KEYS: [&'static str; 25] = [
        "torque_amplitude_nm",
        "preload_nm",
        "amplitude_deg",
        "amplitude_m",
        "period_s",
        "loop",
        "dwell_s",
        "speed_deg_per_min",
        "ratio",
        "mass_kg",
        "radius_m",
        "excitation",
        "frequencies_hz",
        "first_line_hz",
        "last_line_hz",
        "line_step_hz",
        "transient_periods",
        "drive_gain",
        "loop_period_s",
        "band_hz",
        "response",
        "reference",
        "delay_s",
        "averages",
        "controller",
    ];

    /// True when no condition is given.
    pub fn is_empty(&self) -> bool {
        *self == Conditions::default()
    }

    /// A copy with docs/experiment-files.md's defaults for `kind` filled in where a value is absent
    /// (the ratio excepted: it depends on the mechanism).
    pub fn with_defaults(&self, kind: Kind) -> Conditions {
        let mut c = self.clone();
        (kind.definition().defaults)(&mut c);
        c
    }

    /// The excitation (stepped sine when frequencies are given, else broadband) and,
    /// for a multisine, one transient period and every line excited.
    pub(super) fn record_defaults(&mut self) {
        let stepped = self.frequencies_hz.is_some();
        let excitation = *self.excitation.get_or_insert(if stepped {
            Excitation::SteppedSine
        } else {
            Excitation::Broadband
        });
        if excitation == Excitation::Multisine {
            self.transient_periods.get_or_insert(1);
            if let Some(period) = self.period_s.filter(|p| *p > 0.0) {
                self.line_step_hz.get_or_insert(1.0 / period);
            }
        }
    }

    /// The numeric fields with their keys.
    pub(super) fn numbers(&self) -> [(&'static str, Option<f64>); 15] {
        [
            ("torque_amplitude_nm", self.torque_amplitude_nm),
            ("preload_nm", self.preload_nm),
            ("amplitude_deg", self.amplitude_deg),
            ("amplitude_m", self.amplitude_m),
            ("period_s", self.period_s),
            ("dwell_s", self.dwell_s),
            ("speed_deg_per_min", self.speed_deg_per_min),
            ("ratio", self.ratio),
            ("mass_kg", self.mass_kg),
            ("radius_m", self.radius_m),
            ("first_line_hz", self.first_line_hz),
            ("last_line_hz", self.last_line_hz),
            ("line_step_hz", self.line_step_hz),
            ("drive_gain", self.drive_gain),
            ("loop_period_s", self.loop_period_s),
        ]
    }
}

/// A frequency response: 5 N·m of torque, no preload.
pub(super) fn frequency_response_defaults(c: &mut Conditions) {
    c.torque_amplitude_nm.get_or_insert(5.0);
    c.preload_nm.get_or_insert(0.0);
}

/// A torque curve: ±30° over 3 s, full-closed loop.
pub(super) fn torque_curve_defaults(c: &mut Conditions) {
    c.amplitude_deg.get_or_insert(30.0);
    c.period_s.get_or_insert(3.0);
    c.loop_mode.get_or_insert(LoopMode::FullClosed);
}

/// Positioning: semi-closed loop, 1 s dwell.
pub(super) fn positioning_defaults(c: &mut Conditions) {
    c.loop_mode.get_or_insert(LoopMode::SemiClosed);
    c.dwell_s.get_or_insert(1.0);
}

/// Rotational fluctuation (180°/min) or unbalance (360°/min): `speed_deg_per_min`,
/// semi-closed loop.
pub(super) fn fluctuation_defaults(c: &mut Conditions, speed_deg_per_min: f64) {
    c.speed_deg_per_min.get_or_insert(speed_deg_per_min);
    c.loop_mode.get_or_insert(LoopMode::SemiClosed);
}

/// The conditions `kind` needs, checked on the manifest alone (JSON numbers are
/// finite, so `<= 0` is the whole check of a positive value): the band where one is
/// given, then the kind's own checks.
pub(super) fn check(kind: Kind, c: &Conditions) -> Result<(), String> {
    for name in c.extra.keys() {
        if let Some(known) = crate::names::misspelling_of(name, &Conditions::KEYS) {
            return Err(format!(
                "`conditions.{name}` is not a condition rtid reads: did you mean `{known}`? \
                 (a note of your own goes under a name unlike rtid's, or in `notes`)"
            ));
        }
    }
    check_magnitudes(c)?;
    if let Some([lo, hi]) = c.band_hz {
        if !(lo >= 0.0 && lo < hi) {
            return Err(format!(
                "`conditions.band_hz` is [{lo}, {hi}]: it must be [lowest, highest] Hz with 0 ≤ lowest < highest"
            ));
        }
    }
    (kind.definition().check)(c)
}

/// Every number of the conditions within ±1e15 (as a record's values,
/// [`super::table::MAX_MAGNITUDE`]): a ratio of 1e308 is a slip, whose arithmetic
/// would then fail far from the field that caused it.
fn check_magnitudes(c: &Conditions) -> Result<(), String> {
    let Ok(Value::Object(fields)) = serde_json::to_value(c) else {
        return Ok(());
    };
    for (key, value) in &fields {
        let numbers = match value {
            Value::Array(items) => items.iter().filter_map(Value::as_f64).collect(),
            v => v.as_f64().into_iter().collect::<Vec<_>>(),
        };
        if let Some(x) = numbers
            .into_iter()
            .find(|x| x.abs() > super::table::MAX_MAGNITUDE)
        {
            return Err(format!(
                "`conditions.{key}` is {}: beyond ±1e15, not a test's condition (a unit slip?)",
                crate::names::Num(x)
            ));
        }
    }
    Ok(())
}

/// A frequency-response record: a positive ratio where one is given; for a stepped
/// sine the frequencies (positive) and the dwell (positive); for a multisine its
/// period and lines.
pub(super) fn check_record(c: &Conditions) -> Result<(), String> {
    let c = c.with_defaults(Kind::FrequencyResponseTime);
    if let Some(r) = c.ratio.filter(|r| *r <= 0.0) {
        return Err(format!(
            "`conditions.ratio` is {r}: it must be positive (Rg·Rw)"
        ));
    }
    match c.excitation {
        Some(Excitation::SteppedSine) => check_stepped_sine(&c),
        Some(Excitation::Multisine) => check_multisine(&c),
        _ => Ok(()),
    }
}

fn check_stepped_sine(c: &Conditions) -> Result<(), String> {
    let frequencies = c.frequencies_hz.as_deref().unwrap_or_default();
    if frequencies.is_empty() {
        return Err(
            "a stepped-sine record needs `conditions.frequencies_hz`: the drive \
                    frequencies in the order played, Hz"
                .into(),
        );
    }
    if let Some(f) = frequencies.iter().find(|f| **f <= 0.0) {
        return Err(format!(
            "`conditions.frequencies_hz` holds {f}: drive frequencies must be positive"
        ));
    }
    match c.dwell_s {
        None => Err(
            "a stepped-sine record needs `conditions.dwell_s`: the time spent at \
                     each frequency, s"
                .into(),
        ),
        Some(d) if d <= 0.0 => Err(format!(
            "`conditions.dwell_s` is {d}: the dwell at each frequency must be positive"
        )),
        Some(_) => Ok(()),
    }
}

/// Lines closer than this to a whole multiple of 1/period, in lines, count as on it.
const LINE_TOLERANCE: f64 = 1e-6;

/// A multisine: a positive period; lines, where given, positive whole multiples of
/// 1/period (first and last both or neither, first ≤ last).
fn check_multisine(c: &Conditions) -> Result<(), String> {
    let period = match c.period_s {
        None => {
            return Err(
                "a multisine record needs `conditions.period_s`: the period of \
                        the excitation, s"
                    .into(),
            )
        }
        Some(p) if p <= 0.0 => {
            return Err(format!(
                "`conditions.period_s` is {p}: the multisine's period must be positive"
            ))
        }
        Some(p) => p,
    };
    let on_grid = |key: &str, f: f64| {
        let lines = f * period;
        if f <= 0.0 || (lines - lines.round()).abs() > LINE_TOLERANCE * lines.max(1.0) {
            Err(format!(
                "`conditions.{key}` is {f}: it must be a positive whole multiple of \
                 1/period_s = {} Hz",
                1.0 / period
            ))
        } else {
            Ok(())
        }
    };
    for (key, value) in [
        ("first_line_hz", c.first_line_hz),
        ("last_line_hz", c.last_line_hz),
        ("line_step_hz", c.line_step_hz),
    ] {
        value.map(|f| on_grid(key, f)).transpose()?;
    }
    match (c.first_line_hz, c.last_line_hz) {
        (Some(first), Some(last)) if last < first => Err(format!(
            "`conditions.last_line_hz` is {last}, below `first_line_hz` {first}"
        )),
        (Some(_), None) | (None, Some(_)) => Err(
            "`conditions.first_line_hz` and `last_line_hz` go together: give both or neither"
                .into(),
        ),
        _ => Ok(()),
    }
}

/// A servo trace: a nonzero drive gain and a positive loop period where given.
pub(super) fn check_servo(c: &Conditions) -> Result<(), String> {
    if c.drive_gain == Some(0.0) {
        return Err("`conditions.drive_gain` is 0: the drive gain must be nonzero".into());
    }
    match c.loop_period_s {
        Some(p) if p <= 0.0 => Err(format!(
            "`conditions.loop_period_s` is {p}: the loop's sample period must be positive"
        )),
        _ => Ok(()),
    }
}

/// Largest distance of period_s/sample period from a whole number of samples.
const PERIOD_SAMPLES_TOLERANCE: f64 = 0.01;

/// The checks of a multisine record that need its sampling (`c` with defaults): the
/// period a whole number of samples, the last line below the Nyquist frequency. The
/// record's length is not checked here (as a stepped sine's is not): whether it holds
/// enough steady periods is the estimator's question, and a file's head still reads.
pub(super) fn check_multisine_record(c: &Conditions, time_s: &[f64]) -> Result<(), String> {
    let (Some(period), Some(step)) = (c.period_s, sample_period(time_s)) else {
        return Ok(());
    };
    let per_period = period / step;
    if (per_period - per_period.round()).abs() > PERIOD_SAMPLES_TOLERANCE {
        return Err(format!(
            "`conditions.period_s` is {period} s, {per_period:.4} samples of the record's \
             {step:.6e} s: a multisine's period must be a whole number of samples"
        ));
    }
    let nyquist = 0.5 / step;
    match c.last_line_hz {
        Some(last) if last >= nyquist => Err(format!(
            "`conditions.last_line_hz` is {last}: at or above the Nyquist frequency \
             {nyquist} Hz of the record"
        )),
        _ => Ok(()),
    }
}
