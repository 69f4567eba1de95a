//! Glitches and gaps, said rather than smoothed: a sample far outside its channel's
//! run — more than [`GLITCH_DEVIATIONS`] robust deviations from the median of its
//! neighbours — and a step of the time base much longer than the others.
//!
//! What the neighbours predict is the median of the [`HALF_WINDOW`] samples on each
//! side, carried to the sample along their median slope: a ramp or a sine predicts
//! itself. The robust deviation is the larger of two scatters, each 1.4826 × a median
//! absolute difference (about the standard deviation of Gaussian scatter, unmoved by
//! the glitches themselves): the channel's, of every sample from its prediction, and
//! the neighbourhood's, of the neighbours' carried values from theirs — large where
//! the record changes regime, as when a drive starts from rest, so that the start is
//! not taken for a glitch.

/// How many robust deviations from its neighbours make a sample a glitch.
pub const GLITCH_DEVIATIONS: f64 = 10.0;

/// Neighbours on each side of a sample in its local median.
pub const HALF_WINDOW: usize = 4;

/// A time step this many times the median step is a gap.
pub const GAP_STEPS: f64 = 1.5;

/// A sample far outside its channel's run.
#[derive(Clone, Debug, PartialEq)]
pub struct Glitch {
    /// Index of the sample.
    pub index: usize,
    /// Its value, as the channel holds it (the file's units, after its own scaling).
    pub value: f64,
    /// The median of its neighbours.
    pub neighbours: f64,
    /// How many robust deviations away.
    pub deviations: f64,
}

/// The glitches of `values` (none when the channel is too short to judge). Where most
/// of the record sits still, the scatter is at least the channel's [`quantum`].
pub fn glitches(values: &[f64]) -> Vec<Glitch> {
    let n = values.len();
    if n < 2 * HALF_WINDOW + 1 {
        return Vec::new();
    }
    let local: Vec<Local> = (0..n).map(|i| local(values, i)).collect();
    let mut residuals: Vec<f64> = values
        .iter()
        .zip(&local)
        .map(|(v, l)| (v - l.prediction).abs())
        .collect();
    let global = (1.4826 * median(&mut residuals)).max(quantum(values));
    values
        .iter()
        .zip(&local)
        .enumerate()
        .filter_map(|(index, (&value, l))| {
            let scale = l.scale.max(global);
            if scale.is_nan() || scale <= 0.0 {
                return None;
            }
            let deviations = (value - l.prediction).abs() / scale;
            (deviations > GLITCH_DEVIATIONS).then_some(Glitch {
                index,
                value,
                neighbours: l.prediction,
                deviations,
            })
        })
        .collect()
}

/// The channel's step where it sits still for most of the record (the global scatter
/// is then zero): the 10th percentile of its non-zero sample-to-sample changes — an
/// encoder count, a recorder's resolution — so that one count is not a glitch and a
/// jump of many is. Zero when the channel never changes. (Also the step of a run's
/// speed in [`super::runs`].)
pub(crate) fn quantum(values: &[f64]) -> f64 {
    let mut steps: Vec<f64> = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .collect();
    if steps.is_empty() {
        return 0.0;
    }
    steps.sort_by(f64::total_cmp);
    steps[steps.len() / 10]
}

/// What the neighbours of a sample say of it.
struct Local {
    /// The value they predict.
    prediction: f64,
    /// 1.4826 × the median distance of their own carried values from the prediction:
    /// the scatter here, large where the record changes regime (a drive starting from
    /// rest), so that a start is not a glitch.
    scale: f64,
}

/// What the samples around `i` (itself left out, the window shifted inwards at the
/// ends) say `values[i]` should be: the median of their values carried to `i` along
/// their median slope, so that a ramp or a sine, even at the record's ends, predicts
/// itself and a glitch among the neighbours moves nothing.
fn local(values: &[f64], i: usize) -> Local {
    const W: usize = 2 * HALF_WINDOW;
    let n = values.len();
    let lo = i.saturating_sub(HALF_WINDOW).min(n - W - 1);
    let neighbours = (lo..=lo + W).filter(|&j| j != i);
    // On the stack: this runs once per sample of every channel.
    let (mut slopes, mut k) = ([0.0; W], 0);
    for j in (lo..lo + W).filter(|&j| j != i && j + 1 != i) {
        slopes[k] = values[j + 1] - values[j];
        k += 1;
    }
    let slope = median(&mut slopes[..k]);
    let slope = if slope.is_nan() { 0.0 } else { slope };
    let mut carried = [0.0; W];
    for (c, j) in carried.iter_mut().zip(neighbours) {
        *c = values[j] + (i as f64 - j as f64) * slope;
    }
    let prediction = median(&mut carried);
    let mut spread = carried.map(|c| (c - prediction).abs());
    Local {
        prediction,
        scale: 1.4826 * median(&mut spread),
    }
}

/// The median of `v` (sorted in place; the mean of the middle two for an even count),
/// NaN when empty.
pub(crate) fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// The indices `i` where the step `time[i] − time[i−1]` is more than [`GAP_STEPS`]
/// times the median step.
pub fn gaps(time: &[f64]) -> Vec<usize> {
    if time.len() < 3 {
        return Vec::new();
    }
    let mut steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let typical = median(&mut steps.clone());
    if typical.is_nan() || typical <= 0.0 {
        return Vec::new();
    }
    steps
        .iter_mut()
        .enumerate()
        .filter(|(_, s)| **s > GAP_STEPS * typical)
        .map(|(i, _)| i + 1)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_recorder_glitch_is_found_and_nothing_else() {
        // A noisy steady torque (%) with one recorder glitch, as the EPOS runs have.
        use rand::{rngs::StdRng, SeedableRng};
        use rand_distr::{Distribution, Normal};
        let mut rng = StdRng::seed_from_u64(3);
        let noise = Normal::new(0.0, 0.4).unwrap();
        let mut torque: Vec<f64> = (0..2000).map(|_| -9.0 + noise.sample(&mut rng)).collect();
        torque[0] = -1200.0;
        torque[120] = -40.0;
        let found = glitches(&torque);
        let indices: Vec<usize> = found.iter().map(|g| g.index).collect();
        assert_eq!(indices, vec![0, 120]);
        assert_eq!(found[0].value, -1200.0);
    }

    #[test]
    fn a_smooth_motion_has_no_glitch() {
        let angle: Vec<f64> = (0..2000).map(|i| (i as f64 * 0.01).sin() * 30.0).collect();
        assert!(glitches(&angle).is_empty());
        let ramp: Vec<f64> = (0..100).map(|i| i as f64).collect();
        assert!(glitches(&ramp).is_empty());
    }

    #[test]
    fn a_start_from_rest_is_not_a_glitch() {
        // Exactly zero at rest, then a noisy run: the global scatter is tiny (most
        // samples sit at zero), the start's neighbourhood is not.
        use rand::{rngs::StdRng, SeedableRng};
        use rand_distr::{Distribution, Normal};
        let mut rng = StdRng::seed_from_u64(5);
        let noise = Normal::new(0.0, 4.0).unwrap();
        let mut torque: Vec<f64> = vec![0.0; 400];
        for x in torque.iter_mut().skip(130).take(60) {
            *x = -45.0 + noise.sample(&mut rng);
        }
        assert!(glitches(&torque).is_empty(), "{:?}", glitches(&torque));
        torque[300] = -45.0;
        assert_eq!(
            glitches(&torque)
                .iter()
                .map(|g| g.index)
                .collect::<Vec<_>>(),
            vec![300]
        );
    }

    #[test]
    fn a_still_quantised_signal_has_no_glitch() {
        let mut v = vec![5.0; 100];
        v[50] = 6.0;
        assert!(glitches(&v).is_empty());
    }

    #[test]
    fn a_gap_in_the_time_base_is_found() {
        let mut t: Vec<f64> = (0..100).map(|i| i as f64 * 1e-3).collect();
        for x in t.iter_mut().skip(60) {
            *x += 5e-3;
        }
        assert_eq!(gaps(&t), vec![60]);
        assert!(gaps(&t[..60]).is_empty());
    }
}
