//! The friction-torque test as a virtual experiment (paper §4.2, Fig. 9;
//! docs/experiments.md, friction torque curve): the servo, in full-closed loop by default, moves the table harmonically,
//! θref(t) = A·sin(2πt/T) with A = 30°, T = 3 s, and the motor torque command over
//! time is the measured curve. Coulomb friction and viscous damping are fitted to it
//! (docs/identification.md); [`simulate_torque`] is the model side of that fit.
//!
//! The run starts at rest at zero angle, where the command already moves at full
//! speed: the first `run_in_periods` (default 1) absorb that start-up transient and
//! are not recorded. Then `periods` periods are recorded every `sample` seconds
//! (default 1 ms), with the time restarted at 0.
//!
//! Evaluation ([`evaluate`]): RMS and peak torque, and the Coulomb friction seen at
//! the motor from the torque jump at each reversal of the table velocity. Near a
//! reversal the motor torque is inertia (J_eff·θ̈, at its extremum there, so
//! symmetric in time), viscous damping (∝ velocity, antisymmetric and zero at the
//! reversal) and Coulomb friction, which flips from +F to −F. A straight line is fitted
//! to the torque on each side, outside a guard interval that excludes the servo's
//! transition through the stick; both lines are extrapolated to the reversal time and
//! F = −sign(velocity before)·(after − before)/2. The symmetric inertia term cancels
//! in the difference; the linear viscous one extrapolates to zero. On the model
//! F = fm + fw·Rg + ft·Rg·Rw (friction of every body referred to the motor).

use serde::Serialize;

use crate::experiments::inverse_dynamics::{of_torque_curve, IdimFit, IdimSettings};
use crate::input::{Harmonic, Trajectory};
use crate::io::experiment_file::{sample_period, Conditions, Data, Kind, Manifest};
use crate::model::idx::THETA_T;
use crate::model::params::{Axis, LoopMode, Params};
use crate::model::NSTATE;
use crate::recorder::{NullRecorder, Recorder};
use crate::sim::{SimError, Simulation};

/// Conditions of the test (defaults: docs/experiments.md (friction torque curve) and docs/experiment-files.md).
#[derive(Clone, Debug, PartialEq)]
pub struct TorqueTest {
    /// Amplitude of the commanded table motion, rad (default 30°).
    pub amplitude: f64,
    /// Period of the commanded table motion, s (default 3).
    pub period: f64,
    /// Recorded periods (default 2).
    pub periods: f64,
    /// Periods simulated before recording, the servo's start-up transient (default 1).
    pub run_in_periods: f64,
    /// Interval between recorded samples, s (default 1 ms; rounded to whole steps).
    pub sample: f64,
    /// Feedback arrangement (default full-closed, as in the paper).
    pub loop_mode: LoopMode,
}

impl Default for TorqueTest {
    fn default() -> Self {
        TorqueTest {
            amplitude: 30f64.to_radians(),
            period: 3.0,
            periods: 2.0,
            run_in_periods: 1.0,
            sample: 1e-3,
            loop_mode: LoopMode::FullClosed,
        }
    }
}

impl TorqueTest {
    /// The test described by an experiment file's conditions (absent ones: defaults).
    pub fn from_conditions(conditions: &Conditions) -> TorqueTest {
        let c = conditions.with_defaults(Kind::TorqueCurve);
        let d = TorqueTest::default();
        TorqueTest {
            // A linear axis's amplitude in m, else the rotary one (default 30°).
            amplitude: c
                .amplitude_m
                .or(c.amplitude_deg.map(f64::to_radians))
                .unwrap_or(d.amplitude),
            period: c.period_s.unwrap_or(d.period),
            loop_mode: c.loop_mode.unwrap_or(d.loop_mode),
            ..d
        }
    }

    /// The commanded table motion.
    pub fn trajectory(&self) -> Harmonic {
        Harmonic {
            amplitude: self.amplitude,
            period: self.period,
        }
    }

    /// The recorded duration, s.
    pub fn duration(&self) -> f64 {
        self.periods * self.period
    }
}

/// The recorded part of a run: times from 0, motor torque command, table angle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TorqueCurve {
    /// s, from the end of the run-in.
    pub time: Vec<f64>,
    /// Motor torque command, N·m.
    pub motor_torque: Vec<f64>,
    /// Table angle, rad.
    pub table_angle: Vec<f64>,
}

/// Keeps every `every`-th step into pre-reserved vectors; the sample's time is its
/// index times the sample interval (exact, restarted at 0).
struct EveryNth {
    every: u64,
    count: u64,
    interval: f64,
    curve: TorqueCurve,
}

impl EveryNth {
    fn new(every: u64, interval: f64, capacity: usize) -> Self {
        EveryNth {
            every,
            count: 0,
            interval,
            curve: TorqueCurve {
                time: Vec::with_capacity(capacity),
                motor_torque: Vec::with_capacity(capacity),
                table_angle: Vec::with_capacity(capacity),
            },
        }
    }
}

impl Recorder for EveryNth {
    #[inline]
    fn record(&mut self, _t: f64, y: &[f64; NSTATE], motor_torque: f64) {
        if self.count % self.every == 0 {
            let c = &mut self.curve;
            c.time
                .push((self.count / self.every) as f64 * self.interval);
            c.motor_torque.push(motor_torque);
            c.table_angle.push(y[THETA_T]);
        }
        self.count += 1;
    }
}

/// Runs the test on the model: run-in, then `duration` seconds recorded.
/// `progress(done, total)` counts periods (run-in included).
fn simulate(
    params: &Params,
    test: &TorqueTest,
    duration: f64,
    mut progress: impl FnMut(usize, usize),
) -> Result<TorqueCurve, SimError> {
    let mut p = params.clone();
    p.controller.loop_mode = test.loop_mode;
    let mut sim = Simulation::with_default_step(&p)?;
    let mut controller = sim.controller(&p)?;
    let reference = test.trajectory();
    let dt = sim.dt();
    let every = (test.sample / dt).round().max(1.0) as u64;
    let interval = every as f64 * dt;
    let samples = (duration / interval + 1e-9).floor() as usize + 1;
    let per_period = ((test.period / dt).round() as u64).max(1);
    let mut left_steps = (samples as u64 - 1) * every;
    let total =
        test.run_in_periods.max(0.0).ceil() as usize + left_steps.div_ceil(per_period) as usize;
    let mut done = 0;
    // Run-in, a period at a time.
    let mut left = test.run_in_periods * test.period;
    while left > 0.5 * dt {
        let span = left.min(test.period);
        sim.run_closed_loop(&mut controller, &reference, span, &mut NullRecorder)?;
        left -= span;
        done += 1;
        progress(done.min(total), total);
    }
    let mut rec = EveryNth::new(every, interval, samples);
    // The sample at the end of the run-in: the torque held over its last step.
    rec.record(sim.time(), &sim.state(), controller.torque());
    while left_steps > 0 {
        let n = left_steps.min(per_period);
        sim.run_closed_loop(&mut controller, &reference, n as f64 * dt, &mut rec)?;
        left_steps -= n;
        done += 1;
        progress(done.min(total), total);
    }
    Ok(rec.curve)
}

/// Runs the test on the model. `progress(done, total)` is called after each period.
pub fn run(
    params: &Params,
    test: &TorqueTest,
    progress: impl FnMut(usize, usize),
) -> Result<TorqueCurve, SimError> {
    simulate(params, test, test.duration(), progress)
}

/// The motor torque of the test on the model at `times` (s after the run-in, as in a
/// recorded file), linearly interpolated between the recorded samples; times before 0
/// give the first sample. `test.periods` is ignored: the run lasts to the last time.
/// At the recorded times it reproduces [`run`]'s torque exactly.
pub fn simulate_torque(
    params: &Params,
    conditions: &TorqueTest,
    times: &[f64],
) -> Result<Vec<f64>, SimError> {
    let end = times
        .iter()
        .copied()
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    // One sample beyond the last time, so it always lies inside the record.
    let curve = simulate(params, conditions, end + conditions.sample, |_, _| {})?;
    Ok(times
        .iter()
        .map(|&t| interpolate(&curve.time, &curve.motor_torque, t))
        .collect())
}

impl TorqueCurve {
    /// The motor torque at `t`, linearly interpolated (held beyond the ends).
    pub fn torque_at(&self, t: f64) -> f64 {
        interpolate(&self.time, &self.motor_torque, t)
    }
}

/// Linear interpolation of (x, y) at `t`, x increasing; clamped at the ends.
fn interpolate(x: &[f64], y: &[f64], t: f64) -> f64 {
    if t.is_nan() {
        return f64::NAN;
    }
    let i = x.partition_point(|&v| v <= t);
    if i == 0 {
        return y[0];
    }
    if i == x.len() {
        return y[x.len() - 1];
    }
    let (x0, x1) = (x[i - 1], x[i]);
    if t == x0 {
        return y[i - 1];
    }
    y[i - 1] + (y[i] - y[i - 1]) * (t - x0) / (x1 - x0)
}

/// The experiment-file form of a recorded curve on `axis` (torque and angle, or
/// force and position).
pub fn to_data(curve: &TorqueCurve, axis: Axis) -> Data {
    let (time_s, effort, position) = (
        curve.time.clone(),
        curve.motor_torque.clone(),
        Some(curve.table_angle.clone()),
    );
    match axis {
        Axis::Rotary => Data::TorqueCurve {
            time_s,
            motor_torque_nm: effort,
            table_angle_rad: position,
            extra: Default::default(),
        },
        Axis::Linear => Data::ForceCurve {
            time_s,
            force_n: effort,
            table_position_m: position,
            extra: Default::default(),
        },
    }
}

/// The curve of a torque-curve experiment file (`None` for another kind); on a
/// linear axis the force in `motor_torque` and the carriage position in
/// `table_angle`. The table angle is empty when the file has none.
pub fn from_data(data: &Data) -> Option<TorqueCurve> {
    let (time, effort, position) = match data {
        Data::TorqueCurve {
            time_s,
            motor_torque_nm,
            table_angle_rad,
            ..
        } => (time_s, motor_torque_nm, table_angle_rad),
        Data::ForceCurve {
            time_s,
            force_n,
            table_position_m,
            ..
        } => (time_s, force_n, table_position_m),
        _ => return None,
    };
    Some(TorqueCurve {
        time: time.clone(),
        motor_torque: effort.clone(),
        table_angle: position.clone().unwrap_or_default(),
    })
}

/// The manifest of a virtual torque-curve test.
pub fn manifest(params: &Params, test: &TorqueTest) -> Manifest {
    let mut m = Manifest::new(Kind::TorqueCurve);
    m.mechanism = Some(params.name.clone());
    match params.axis {
        Axis::Rotary => m.conditions.amplitude_deg = Some(test.amplitude.to_degrees()),
        Axis::Linear => m.conditions.amplitude_m = Some(test.amplitude),
    }
    m.conditions.period_s = Some(test.period);
    m.conditions.loop_mode = Some(test.loop_mode);
    m.notes = Some(format!(
        "virtual friction-torque test by rtid: {} period(s) recorded after a run-in of {}, \
         motor torque command sampled every {} ms, time restarted at 0 after the run-in",
        test.periods,
        test.run_in_periods,
        test.sample * 1e3
    ));
    m
}

/// One reversal of the table velocity and the torque jump across it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Reversal {
    /// When the table velocity reverses, s.
    pub time_s: f64,
    /// +1 if the table moved in the positive sense before the reversal, −1 otherwise.
    pub direction_before: f64,
    /// Torque just after minus just before (extrapolated lines), N·m.
    pub jump_nm: f64,
    /// −direction_before·jump/2: the Coulomb friction torque at the motor, N·m.
    pub friction_nm: f64,
}

/// What the evaluation of a torque curve finds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TorqueReport {
    pub samples: usize,
    pub duration_s: f64,
    /// Root mean square of the motor torque, N·m.
    pub rms_nm: f64,
    /// Largest |motor torque|, N·m.
    pub peak_nm: f64,
    /// The Coulomb friction at the motor, N·m: the friction law's
    /// (`inverse_dynamics`) when the curve has the table angle, else the mean of the
    /// reversals' estimates (none if no reversal is usable).
    pub friction_nm: Option<f64>,
    /// Where `friction_nm` comes from: `inverse_dynamics` (the law
    /// F = M·a + Fv·v + Fc·sign(v) + OF fitted over the whole curve: any trajectory)
    /// or `reversal_windows` (the torque jumps at the reversals of the test's sine).
    pub friction_from: &'static str,
    /// The friction law fitted to the whole curve (IDIM-LS on the table angle) when
    /// the curve has it: M and Fv referred to the table, Fc at the motor.
    pub inverse_dynamics: Option<IdimFit>,
    /// Where the reversals come from: `table_angle` or `command` (no angle column). On
    /// another trajectory than the test's sine the windows' estimate is biased (on the
    /// EMPS record +39 %): `friction_nm` is then the law's.
    pub reversals_from: &'static str,
    pub reversals: Vec<Reversal>,
}

/// Why a torque curve cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TorqueEvalError {
    #[error("the torque curve has {0} samples; at least 3 are needed")]
    TooShort(usize),
}

/// Evaluates a torque curve recorded under `test` (its period locates the reversals
/// when the curve has no table angle, and sets the fit windows).
pub fn evaluate(curve: &TorqueCurve, test: &TorqueTest) -> Result<TorqueReport, TorqueEvalError> {
    let n = curve.time.len();
    if n < 3 {
        return Err(TorqueEvalError::TooShort(n));
    }
    let rms = (curve.motor_torque.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    let peak = curve
        .motor_torque
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let (t0, t1) = (curve.time[0], curve.time[n - 1]);
    let (times, from) = if curve.table_angle.len() == n {
        (
            angle_extrema(&curve.time, &curve.table_angle),
            "table_angle",
        )
    } else {
        // The command A·sin(2πt/T) reverses at T/4 + k·T/2 (time restarted at a whole
        // number of periods); direction before: + at T/4, − at 3T/4. The table follows
        // with the servo's lag (≈ 40 ms for the presets), so this estimate is poorer:
        // ~15 % low on the worm preset. Record the table angle when you can.
        let half = 0.5 * test.period;
        let first = ((t0 - 0.25 * test.period) / half).ceil() as i64;
        let times = (first..)
            .map(|k| (0.25 * test.period + k as f64 * half, k))
            .take_while(|&(t, _)| t <= t1)
            .map(|(t, k)| (t, if k % 2 == 0 { 1.0 } else { -1.0 }))
            .collect();
        (times, "command")
    };
    let (guard, width) = (0.01 * test.period, 0.06 * test.period);
    let reversals: Vec<Reversal> = times
        .into_iter()
        .filter(|&(t, _)| t - guard - width >= t0 && t + guard + width <= t1)
        .filter_map(|(t, dir)| {
            let before = line_at(curve, t - guard - width, t - guard, t)?;
            let after = line_at(curve, t + guard, t + guard + width, t)?;
            let jump = after - before;
            Some(Reversal {
                time_s: t,
                direction_before: dir,
                jump_nm: jump,
                friction_nm: -dir * jump / 2.0,
            })
        })
        .collect();
    let windows = (!reversals.is_empty())
        .then(|| reversals.iter().map(|r| r.friction_nm).sum::<f64>() / reversals.len() as f64);
    let law = friction_law(curve);
    Ok(TorqueReport {
        samples: n,
        duration_s: t1 - t0,
        rms_nm: rms,
        peak_nm: peak,
        friction_nm: law.as_ref().map(|f| f.coulomb.value).or(windows),
        friction_from: if law.is_some() {
            "inverse_dynamics"
        } else {
            "reversal_windows"
        },
        inverse_dynamics: law,
        reversals_from: from,
        reversals,
    })
}

/// The friction law fitted over the whole curve when it has the table angle (the
/// filters carried to its sampling rate); none without the angle or when the curve
/// cannot carry the fit (too short, too little motion).
fn friction_law(curve: &TorqueCurve) -> Option<IdimFit> {
    if curve.table_angle.len() != curve.time.len() {
        return None;
    }
    let period = sample_period(&curve.time)?;
    of_torque_curve(curve, &IdimSettings::for_sample_period(period)).ok()
}

/// How a recorded motion differs from the test's command A·sin(2πt/T).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionDifference {
    /// RMS of the recorded position minus the command, over the command's RMS.
    pub relative_rms: f64,
    /// Half the recorded position's peak-to-peak, rad or m.
    pub recorded_amplitude: f64,
    /// The recorded motion's period from its crossings of its mean, s (none with
    /// fewer than two crossings).
    pub recorded_period: Option<f64>,
}

/// The recorded motion against the test's command, when the curve has the position.
pub fn motion_difference(curve: &TorqueCurve, test: &TorqueTest) -> Option<MotionDifference> {
    let n = curve.time.len();
    if curve.table_angle.len() != n || n == 0 {
        return None;
    }
    let command = test.trajectory();
    let (mut diff, mut norm) = (0.0, 0.0);
    for (&t, &q) in curve.time.iter().zip(&curve.table_angle) {
        let c = command.angle(t);
        diff += (q - c) * (q - c);
        norm += c * c;
    }
    let (lo, hi) = curve
        .table_angle
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let mean = 0.5 * (lo + hi);
    let crossings: Vec<f64> = curve
        .table_angle
        .windows(2)
        .zip(&curve.time)
        .filter(|(w, _)| (w[0] - mean) * (w[1] - mean) < 0.0)
        .map(|(_, &t)| t)
        .collect();
    let recorded_period = (crossings.len() >= 2).then(|| {
        2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
    });
    Some(MotionDifference {
        relative_rms: (diff / norm.max(f64::MIN_POSITIVE)).sqrt(),
        recorded_amplitude: 0.5 * (hi - lo),
        recorded_period,
    })
}

/// Times of the extrema of `angle` (with the sign of the motion before each): an
/// extremum counts once the angle has come back from it by 1 % of its range, so
/// encoder counts and noise do not make false reversals. A flat extremum (the table
/// stuck) is timed at its middle.
fn angle_extrema(time: &[f64], angle: &[f64]) -> Vec<(f64, f64)> {
    let (lo, hi) = angle
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let h = 0.01 * (hi - lo);
    if h.is_nan() || h <= 0.0 {
        return Vec::new();
    }
    let mut out = Vec::new();
    // Index range of the current extremum candidate, and the sense of motion.
    let (mut first, mut last) = (0, 0);
    let mut dir = 0.0;
    for i in 1..angle.len() {
        let (v, ext) = (angle[i], angle[first]);
        if dir == 0.0 {
            if (v - angle[0]).abs() > h {
                dir = (v - angle[0]).signum();
                (first, last) = (i, i);
            }
            continue;
        }
        if dir * (v - ext) > 0.0 {
            (first, last) = (i, i);
        } else if v == ext {
            last = i;
        } else if dir * (ext - v) > h {
            out.push((0.5 * (time[first] + time[last]), dir));
            dir = -dir;
            (first, last) = (i, i);
        }
    }
    out
}

/// The least-squares line through the curve's torque for times in [a, b], at `t`.
fn line_at(curve: &TorqueCurve, a: f64, b: f64, t: f64) -> Option<f64> {
    let lo = curve.time.partition_point(|&x| x < a);
    let hi = curve.time.partition_point(|&x| x <= b);
    // A time column that is not ascending gives no window.
    if hi <= lo {
        return None;
    }
    let (x, y) = (&curve.time[lo..hi], &curve.motor_torque[lo..hi]);
    if x.len() < 2 {
        return None;
    }
    let m = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / m, y.iter().sum::<f64>() / m);
    let sxx: f64 = x.iter().map(|v| (v - mx) * (v - mx)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(u, v)| (u - mx) * (v - my)).sum();
    if sxx <= 0.0 {
        return None;
    }
    Some(my + sxy / sxx * (t - mx))
}
