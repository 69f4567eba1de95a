//! One constant-speed run reduced to a row of a friction map: its mean speed and mean
//! effort over the samples where the speed had settled, with what was left out and
//! why.
//!
//! The rule (the friction map's shared definition, issue 25), on a run's speed `v` and
//! effort `e` in SI units:
//!
//! 1. Glitches — the samples [`glitches`] flags on the speed or on the effort — are
//!    dropped from both.
//! 2. The reference speed `m` is the median of the speeds left.
//! 3. The speed's quantum `q` is [`quantum`] of the whole run's speeds, glitches
//!    included.
//! 4. The settle band is `b = max(0.05·|m|, 2·q)`.
//! 5. The transient — the leading samples (after the glitches are dropped) before the
//!    first one within `b` of `m` — is left out.
//! 6. Over the samples left: the mean speed and effort, their sample standard
//!    deviations (n − 1 denominator), n.
//! 7. The run has not settled — an error — when fewer than [`MIN_SAMPLES`] samples are
//!    left, or when the mean speeds of their first and second halves differ by more
//!    than `b`. Samples outside the band after the transient are counted, not refused:
//!    at a creep speed a recorder's speed reading scatters far around its mean (the
//!    shared lead-screw drive at −2 rpm reads 0 … 15 rpm, a fifth of its samples
//!    outside the band) while the run itself holds its speed, and its mean is what the
//!    map needs.
//! 8. The run does not hold its speed, or its effort is not steady — an error — when,
//!    over the samples averaged (each at its index in the run, so a dropped glitch
//!    leaves a gap), the least-squares line's change from the first to the last
//!    sample is, for the speed, more than [`HELD_SPEED`] (½) of the speed's scatter
//!    about that line (sample standard deviation, n − 2) and more than
//!    [`NEGLIGIBLE_CHANGE`] (1 %) of its mean; for the effort, more than
//!    [`STEADY_EFFORT`] (3) times the effort's scatter about its line — each limit at
//!    least what noise alone gives a line through n samples once in a thousand (the
//!    99.9 % quantile of Student's t, n − 2 degrees of freedom, times the change's
//!    standard error, about √(12/n) scatters: 5.0 at n = 10, 1.2 at 100, 0.51 at 500),
//!    so that a short run is not refused for its noise. A speed that
//!    changes within the run is an acceleration, whose inertial torque is in the
//!    effort's mean; an effort that climbs or falls through a run has no one mean.
//!    Measured: the 108 steady-state runs of the shared EPOS drives (two lead screws,
//!    one worm) change their speed by at most 0.31 of its scatter and their effort by
//!    at most 2.0 times its scatter; the stretches of a robot axis's servo trace
//!    (`fixtures/formats/matlab/kuka/`, row 1) where its speed stays within 5 % for 10 to 30
//!    samples mid-acceleration change their speed by 26 to 82 times its scatter (and
//!    its two speed peaks by 1.9 and 1.2, over 127 and 155 samples). Its creeping
//!    approach to the end position (0.06 deg/s, 0.1 to 0.3 % of its top speed, 11 to
//!    49 samples) passes these rules: locally it holds its speed.

use std::ops::Range;

use super::glitches::{glitches, median, quantum, Glitch};

/// The fewest samples a run averages.
pub const MIN_SAMPLES: usize = 10;

/// The settle band's width as a fraction of the reference speed.
pub const BAND_FRACTION: f64 = 0.05;

/// The settle band's width in quanta of the speed, at least.
pub const BAND_QUANTA: f64 = 2.0;

/// A held speed changes over its run by at most this fraction of its scatter…
pub const HELD_SPEED: f64 = 0.5;

/// …or by at most this fraction of its mean.
pub const NEGLIGIBLE_CHANGE: f64 = 0.01;

/// A steady effort changes over its run by at most this many times its scatter.
pub const STEADY_EFFORT: f64 = 3.0;

/// The settle band around `reference` for a speed of quantum `quantum`:
/// `max(0.05·|reference|, 2·quantum)`.
pub fn settle_band(reference: f64, quantum: f64) -> f64 {
    (BAND_FRACTION * reference.abs()).max(BAND_QUANTA * quantum)
}

/// A run's statistics. Indices are of the samples given to [`statistics`].
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// Mean speed over the averaged samples, rad/s or m/s.
    pub speed: f64,
    /// Mean effort over them, N·m or N.
    pub effort: f64,
    /// Sample standard deviation of the speed (n − 1 denominator).
    pub speed_std: f64,
    /// Sample standard deviation of the effort.
    pub effort_std: f64,
    /// How many samples were averaged (n).
    pub samples: usize,
    /// The reference speed: the median of the speeds once the glitches are dropped.
    pub reference: f64,
    /// The speed's quantum over the whole run.
    pub quantum: f64,
    /// The settle band's half-width around the reference.
    pub band: f64,
    /// The glitches found on the speed.
    pub speed_glitches: Vec<Glitch>,
    /// The glitches found on the effort.
    pub effort_glitches: Vec<Glitch>,
    /// Every index dropped as a glitch (of either channel), in order.
    pub dropped: Vec<usize>,
    /// The indices left out as the transient, in order.
    pub transient: Vec<usize>,
    /// From the first averaged sample to the end: every index in it but the dropped
    /// ones was averaged.
    pub averaged: Range<usize>,
    /// How many averaged samples lie outside the settle band (counted, not refused).
    pub outside: usize,
}

/// Why a run gives no row.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The two channels differ in length.
    #[error("the speed has {speed} samples but the effort {effort}")]
    Lengths { speed: usize, effort: usize },
    /// Fewer than [`MIN_SAMPLES`] samples left to average.
    #[error(
        "not settled: {left} samples left to average ({dropped} glitches dropped, {transient} \
         samples of transient left out), fewer than {MIN_SAMPLES}"
    )]
    TooFew {
        left: usize,
        dropped: usize,
        transient: usize,
    },
    /// The mean speed drifts across the run.
    #[error(
        "not settled: the mean speed of the first half is {} and of the second {}, \
         further apart than the settle band {}",
        short(*first),
        short(*second),
        short(*band)
    )]
    Drifting { first: f64, second: f64, band: f64 },
    /// The speed changes along the run ([`HELD_SPEED`], [`NEGLIGIBLE_CHANGE`]).
    #[error(
        "not a held speed: the speed changes by {} % of its mean {} within the run, {} times \
         its scatter about that change (a held speed changes by at most {HELD_SPEED} of its \
         scatter or {} % of its mean)",
        short(100.0 * change / mean.abs()),
        short(*mean),
        short(change / scatter),
        100.0 * NEGLIGIBLE_CHANGE
    )]
    SpeedChanges {
        change: f64,
        mean: f64,
        scatter: f64,
    },
    /// The effort drifts along the run ([`STEADY_EFFORT`]).
    #[error(
        "not a steady effort: the effort changes by {} within the run, {} times its scatter \
         about that change (at most {STEADY_EFFORT})",
        short(*change),
        short(change / scatter)
    )]
    EffortDrifts { change: f64, scatter: f64 },
}

/// The statistics of one constant-speed run, `speed` and `effort` in SI units, by the
/// rule in the module's docs.
pub fn statistics(speed: &[f64], effort: &[f64]) -> Result<Run, RunError> {
    if speed.len() != effort.len() {
        return Err(RunError::Lengths {
            speed: speed.len(),
            effort: effort.len(),
        });
    }
    let (speed_glitches, effort_glitches) = (glitches(speed), glitches(effort));
    let mut dropped: Vec<usize> = speed_glitches
        .iter()
        .chain(&effort_glitches)
        .map(|g| g.index)
        .collect();
    dropped.sort_unstable();
    dropped.dedup();
    let kept: Vec<usize> = (0..speed.len())
        .filter(|i| dropped.binary_search(i).is_err())
        .collect();
    let reference = median(&mut kept.iter().map(|&i| speed[i]).collect::<Vec<f64>>());
    let quantum = quantum(speed);
    let band = settle_band(reference, quantum);
    let within = |i: usize| (speed[i] - reference).abs() <= band;
    let settled = kept.iter().position(|&i| within(i)).unwrap_or(kept.len());
    let (transient, used) = kept.split_at(settled);
    if used.len() < MIN_SAMPLES {
        return Err(RunError::TooFew {
            left: used.len(),
            dropped: dropped.len(),
            transient: transient.len(),
        });
    }
    let outside = used.iter().filter(|&&i| !within(i)).count();
    let half = used.len() / 2;
    let (first, second) = (
        mean(used[..half].iter().map(|&i| speed[i])),
        mean(used[half..].iter().map(|&i| speed[i])),
    );
    if (first - second).abs() > band {
        return Err(RunError::Drifting {
            first,
            second,
            band,
        });
    }
    let (speed_mean, speed_std) = mean_std(used.iter().map(|&i| speed[i]));
    let (effort_mean, effort_std) = mean_std(used.iter().map(|&i| effort[i]));
    steadiness(used, speed, speed_mean, effort)?;
    Ok(Run {
        speed: speed_mean,
        effort: effort_mean,
        speed_std,
        effort_std,
        samples: used.len(),
        reference,
        quantum,
        band,
        speed_glitches,
        effort_glitches,
        dropped,
        transient: transient.to_vec(),
        averaged: used[0]..speed.len(),
        outside,
    })
}

/// Rule 8 of the module's docs over the samples `used` (indices into `speed` and
/// `effort`), the speed's mean `speed_mean`.
fn steadiness(
    used: &[usize],
    speed: &[f64],
    speed_mean: f64,
    effort: &[f64],
) -> Result<(), RunError> {
    let noise = noise_limit(used);
    let (change, scatter) = trend(used, speed);
    let change = change.abs();
    let held = HELD_SPEED.max(noise) * scatter;
    if change > held && change > NEGLIGIBLE_CHANGE * speed_mean.abs() {
        return Err(RunError::SpeedChanges {
            change,
            mean: speed_mean,
            scatter,
        });
    }
    let (change, scatter) = trend(used, effort);
    let change = change.abs();
    let largest = used.iter().map(|&i| effort[i].abs()).fold(0.0, f64::max);
    if change > STEADY_EFFORT.max(noise) * scatter + 1e3 * f64::EPSILON * largest {
        return Err(RunError::EffortDrifts { change, scatter });
    }
    Ok(())
}

/// The largest change, in scatters, that noise alone gives a line through the samples
/// at indices `at` (at least 3) once in a thousand: the 99.9 % two-sided quantile of
/// Student's t with n − 2 degrees of freedom times the change's standard error in
/// scatters, span/√Sxx (about √(12/n) for consecutive samples).
fn noise_limit(at: &[usize]) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let n = at.len() as f64;
    let x_mean = at.iter().map(|&i| i as f64).sum::<f64>() / n;
    let sxx: f64 = at.iter().map(|&i| (i as f64 - x_mean).powi(2)).sum();
    let span = (at[at.len() - 1] - at[0]) as f64;
    let t = StudentsT::new(0.0, 1.0, n - 2.0).map_or(f64::INFINITY, |d| d.inverse_cdf(0.9995));
    t * span / sxx.sqrt()
}

/// The least-squares line through `values[i]` at abscissa i, for i in `at` (at least
/// 3, increasing): its change from the first to the last index, and the values'
/// scatter about it (sample standard deviation, n − 2 denominator).
fn trend(at: &[usize], values: &[f64]) -> (f64, f64) {
    let n = at.len() as f64;
    let x_mean = at.iter().map(|&i| i as f64).sum::<f64>() / n;
    let y_mean = at.iter().map(|&i| values[i]).sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for &i in at {
        let dx = i as f64 - x_mean;
        sxy += dx * (values[i] - y_mean);
        sxx += dx * dx;
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let ss: f64 = at
        .iter()
        .map(|&i| (values[i] - y_mean - slope * (i as f64 - x_mean)).powi(2))
        .sum();
    let span = (at[at.len() - 1] - at[0]) as f64;
    (slope * span, (ss / (n - 2.0)).sqrt())
}

fn mean(values: impl ExactSizeIterator<Item = f64>) -> f64 {
    let n = values.len() as f64;
    values.sum::<f64>() / n
}

/// Mean and sample standard deviation (n − 1 denominator; 0 for one value).
fn mean_std(values: impl ExactSizeIterator<Item = f64> + Clone) -> (f64, f64) {
    let n = values.len();
    let m = mean(values.clone());
    let ss: f64 = values.map(|x| (x - m).powi(2)).sum();
    (
        m,
        if n > 1 {
            (ss / (n - 1) as f64).sqrt()
        } else {
            0.0
        },
    )
}

/// A number in a message, rounded to four significant digits.
pub(crate) fn short(x: f64) -> String {
    let rounded: f64 = format!("{x:.3e}").parse().unwrap_or(x);
    crate::names::Num(rounded).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, SeedableRng};
    use rand_distr::{Distribution, Normal};

    /// A run at `speed` with Gaussian noise on both channels, the effort
    /// 0.3 + 0.01·speed.
    fn noisy_run(n: usize, speed: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let mut rng = StdRng::seed_from_u64(seed);
        let noise = Normal::new(0.0, 0.01).unwrap();
        let v: Vec<f64> = (0..n)
            .map(|_| speed + speed.abs() * noise.sample(&mut rng))
            .collect();
        let e = v
            .iter()
            .map(|v| 0.3 + 0.01 * v + noise.sample(&mut rng))
            .collect();
        (v, e)
    }

    #[test]
    fn a_steady_run_gives_its_mean_and_sample_deviation() {
        let v: Vec<f64> = (0..20).map(|i| 10.0 + [0.1, -0.1][i % 2]).collect();
        let e: Vec<f64> = (0..20).map(|i| 2.0 + [0.5, -0.5][i % 2]).collect();
        let r = statistics(&v, &e).unwrap();
        assert!((r.speed - 10.0).abs() < 1e-12 && (r.effort - 2.0).abs() < 1e-12);
        // Sample deviation: sqrt(20·0.25/19).
        assert!((r.effort_std - (5.0f64 / 19.0).sqrt()).abs() < 1e-12);
        assert_eq!((r.samples, r.averaged.clone(), r.outside), (20, 0..20, 0));
        assert!(r.dropped.is_empty() && r.transient.is_empty());
        // The quantum is 0.2, so the band is max(0.5, 0.4).
        assert!((r.quantum - 0.2).abs() < 1e-12 && (r.band - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_glitch_on_either_channel_is_dropped_from_both() {
        let (mut v, mut e) = noisy_run(200, -5.0, 1);
        e[50] = 40.0;
        v[120] = 80.0;
        let r = statistics(&v, &e).unwrap();
        assert_eq!(r.dropped, [50, 120]);
        assert_eq!(r.effort_glitches.len(), 1);
        assert_eq!(r.speed_glitches[0].index, 120);
        assert_eq!(r.samples, 198);
        let kept = |x: &[f64]| -> f64 {
            let k = (0..200).filter(|i| ![50, 120].contains(i));
            k.map(|i| x[i]).sum::<f64>() / 198.0
        };
        assert!((r.effort - kept(&e)).abs() < 1e-12, "{}", r.effort);
        assert!((r.speed - kept(&v)).abs() < 1e-12, "{}", r.speed);
        assert!((r.speed + 5.0).abs() < 0.02 && (r.effort - 0.25).abs() < 0.01);
    }

    #[test]
    fn the_start_before_the_speed_settles_is_left_out() {
        // Accelerating from rest to 20 in 8 samples, then steady.
        let (mut v, e) = noisy_run(100, 20.0, 2);
        for (i, x) in v.iter_mut().take(8).enumerate() {
            *x = 20.0 * i as f64 / 8.0;
        }
        let r = statistics(&v, &e).unwrap();
        assert_eq!(r.transient, (0..8).collect::<Vec<_>>());
        assert_eq!((r.averaged.clone(), r.samples), (8..100, 92));
        assert!((r.speed - 20.0).abs() < 0.1, "{}", r.speed);
        // Left in, the start would have pulled the mean down by about 0.5.
        let all: f64 = v.iter().sum::<f64>() / 100.0;
        assert!(r.speed - all > 0.5);
    }

    #[test]
    fn a_ramp_has_not_settled() {
        // 10 to 20 over the run: the median's band takes in the middle only.
        let v: Vec<f64> = (0..100).map(|i| 10.0 + 0.1 * i as f64).collect();
        let e = vec![1.0; 100];
        let err = statistics(&v, &e).unwrap_err();
        assert!(matches!(err, RunError::Drifting { .. }), "{err}");
        assert!(err.to_string().starts_with("not settled"), "{err}");
        // A speed that changes halfway by less than the band on either side of the
        // median, but by more than the band between the halves.
        // (A ripple of 0.02 sets the quantum, and so the band, by the 5 %.)
        let ripple = |i: usize| 0.01 * [1.0, -1.0][i % 2];
        let v: Vec<f64> = (0..100)
            .map(|i| if i < 50 { 20.0 } else { 21.5 } + ripple(i))
            .collect();
        let err = statistics(&v, &e).unwrap_err();
        assert!(matches!(err, RunError::Drifting { .. }), "{err}");
    }

    #[test]
    fn too_few_samples_are_refused() {
        let (v, e) = noisy_run(9, 3.0, 3);
        assert_eq!(
            statistics(&v, &e).unwrap_err(),
            RunError::TooFew {
                left: 9,
                dropped: 0,
                transient: 0
            }
        );
        let (v, e) = noisy_run(10, 3.0, 3);
        assert_eq!(statistics(&v, &e).unwrap().samples, 10);
        assert!(matches!(
            statistics(&[], &[]).unwrap_err(),
            RunError::TooFew { left: 0, .. }
        ));
        assert!(matches!(
            statistics(&v, &e[1..]).unwrap_err(),
            RunError::Lengths {
                speed: 10,
                effort: 9
            }
        ));
    }

    #[test]
    fn the_band_is_two_quanta_on_a_coarse_speed() {
        // A speed read in whole counts at 3 counts: 5 % is 0.15, two quanta 2.
        let v: Vec<f64> = (0..50).map(|i| [3.0, 4.0, 3.0, 2.0][i % 4]).collect();
        let r = statistics(&v, &vec![0.5; 50]).unwrap();
        assert_eq!((r.quantum, r.band, r.outside), (1.0, 2.0, 0));
    }

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(short(1.0471975511965976), "1.047");
        assert_eq!(short(-0.0031234), "-0.003123");
        assert_eq!(short(1234.5678), "1235");
        assert_eq!(short(0.0), "0");
        assert_eq!(short(1.5e-9), "1.5e-9");
        assert_eq!(short(9.999999999999993), "10");
    }
}
