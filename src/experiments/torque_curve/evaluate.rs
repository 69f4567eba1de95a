//! The evaluation of a torque curve (module docs of the parent): RMS and peak torque,
//! the Coulomb friction from the torque jump at each reversal, the friction law fitted
//! over the whole curve, and how the recorded motion differs from the command.

use serde::Serialize;

use super::{TorqueCurve, TorqueTest};
use crate::estimation::inverse_dynamics::{identify, IdimError, IdimFit, IdimSettings};
use crate::input::Trajectory;
use crate::io::experiment_file::sample_period;

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
    idim_fit(curve, &IdimSettings::for_sample_period(period)).ok()
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

/// The law fitted to a torque curve (paper §4.2) by IDIM-LS
/// ([`crate::estimation::inverse_dynamics`]): the table angle is the motion, the
/// motor torque the effort, so M and Fv are referred to the table and Fc is the
/// friction seen at the motor, fm + fw·Rg + ft·Rg·Rw — what [`evaluate`] estimates
/// from the reversal windows, here from the whole curve.
pub fn idim_fit(curve: &TorqueCurve, settings: &IdimSettings) -> Result<IdimFit, IdimError> {
    let period = sample_period(&curve.time).unwrap_or(f64::NAN);
    identify(period, &curve.table_angle, &curve.motor_torque, settings)
}
