//! A stepped-speed record — one file in which the drive held several speeds in turn —
//! cut into its plateaus, each then a run of the friction map ([`super::runs`]).
//!
//! The speed's running median (the sample and [`HALF_WINDOW`] neighbours on each side,
//! the window shifted inwards at the record's ends: a glitch does not move it) is
//! followed from the record's start; a segment ends where the running median leaves
//! the settle band ([`settle_band`], with the whole record's [`quantum`]) around its
//! value at the segment's first sample. A segment of at least [`MIN_SAMPLES`] samples
//! is a plateau, once its tail is trimmed back to its last sample within the band of
//! its median (the running median lags half a window behind a change, so the start
//! of the next change would otherwise end the plateau). Everything else — shorter
//! segments, trimmed tails — is transition.
//!
//! A plateau's own start (a speed that overshoots, then settles) is left to the run
//! statistics, which leave it out as the run's transient. The cut presumes changes of
//! speed that are short beside the plateaus: a slow ramp of more than
//! [`MIN_SAMPLES`] samples per band's width would be cut into pieces each taken for a
//! plateau.

use std::ops::Range;

use super::glitches::{median, quantum, HALF_WINDOW};
use super::runs::{settle_band, MIN_SAMPLES};

/// A record cut at its changes of speed: ranges of sample indices, in order; together
/// they cover the record once.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Segments {
    /// Stretches of at least [`MIN_SAMPLES`] samples at one speed.
    pub plateaus: Vec<Range<usize>>,
    /// The samples between, before and after them.
    pub transitions: Vec<Range<usize>>,
}

/// The plateaus and transitions of `speed` (any unit), by the rule in the module's
/// docs.
pub fn plateaus(speed: &[f64]) -> Segments {
    let n = speed.len();
    if n == 0 {
        return Segments::default();
    }
    let running = running_median(speed);
    let q = quantum(speed);
    let mut cuts = vec![0];
    let mut level = running[0];
    for (i, &r) in running.iter().enumerate().skip(1) {
        if (r - level).abs() > settle_band(level, q) {
            cuts.push(i);
            level = r;
        }
    }
    cuts.push(n);
    let plateaus: Vec<Range<usize>> = cuts
        .windows(2)
        .filter(|w| w[1] - w[0] >= MIN_SAMPLES)
        .map(|w| trimmed(speed, w[0]..w[1], q))
        .filter(|r| r.len() >= MIN_SAMPLES)
        .collect();
    let mut transitions = Vec::new();
    let mut at = 0;
    for p in &plateaus {
        if p.start > at {
            transitions.push(at..p.start);
        }
        at = p.end;
    }
    if at < n {
        transitions.push(at..n);
    }
    Segments {
        plateaus,
        transitions,
    }
}

/// `segment` ending at its last sample within the settle band of its median.
fn trimmed(speed: &[f64], segment: Range<usize>, q: f64) -> Range<usize> {
    let m = median(&mut speed[segment.clone()].to_vec());
    let band = settle_band(m, q);
    let mut end = segment.end;
    while end > segment.start && (speed[end - 1] - m).abs() > band {
        end -= 1;
    }
    segment.start..end
}

/// The median of each sample and its [`HALF_WINDOW`] neighbours on each side, the
/// window shifted inwards at the ends (the whole record when it is shorter).
fn running_median(values: &[f64]) -> Vec<f64> {
    const WIDTH: usize = 2 * HALF_WINDOW + 1;
    let n = values.len();
    let mut window = [0.0; WIDTH];
    (0..n)
        .map(|i| {
            let lo = i.saturating_sub(HALF_WINDOW).min(n.saturating_sub(WIDTH));
            let hi = (lo + WIDTH).min(n);
            let w = &mut window[..hi - lo];
            w.copy_from_slice(&values[lo..hi]);
            median(w)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `levels` held `hold` samples each, joined by linear changes of `change`
    /// samples, with a small alternating ripple.
    fn stepped(levels: &[f64], hold: usize, change: usize) -> Vec<f64> {
        let mut v = Vec::new();
        for (k, &level) in levels.iter().enumerate() {
            if k > 0 {
                let from = levels[k - 1];
                for j in 1..=change {
                    v.push(from + (level - from) * j as f64 / (change + 1) as f64);
                }
            }
            v.extend((0..hold).map(|i| level + 0.01 * level.abs() * [1.0, -1.0][i % 2]));
        }
        v
    }

    #[test]
    fn sharp_steps_are_cut_where_they_are() {
        let v = stepped(&[10.0, 20.0, -5.0], 30, 0);
        let s = plateaus(&v);
        assert_eq!(s.plateaus, [0..30, 30..60, 60..90]);
        assert!(s.transitions.is_empty());
    }

    #[test]
    fn changes_between_plateaus_are_transitions() {
        // Plateaus of 40 samples joined by changes of 6.
        let v = stepped(&[10.0, 30.0, -10.0, -30.0], 40, 6);
        let s = plateaus(&v);
        assert_eq!(s.plateaus.len(), 4, "{s:?}");
        for (k, p) in s.plateaus.iter().enumerate() {
            let (start, end) = (k * 46, k * 46 + 40);
            // Each plateau lies within its hold, missing at most a few samples at its
            // ends; nothing of a change is in it.
            assert!(p.start >= start && p.end <= end, "{k}: {p:?}");
            assert!(p.len() >= 34, "{k}: {p:?}");
        }
        let covered: usize = s
            .plateaus
            .iter()
            .chain(&s.transitions)
            .map(|r| r.len())
            .sum();
        assert_eq!(covered, v.len());
        assert_eq!(s.transitions.len(), 3, "{s:?}");
    }

    #[test]
    fn a_steady_record_is_one_plateau_and_a_glitch_cuts_nothing() {
        let mut v = stepped(&[50.0], 200, 0);
        v[100] = 500.0;
        let s = plateaus(&v);
        assert_eq!(s.plateaus, vec![0..200]);
        assert!(plateaus(&[]).plateaus.is_empty());
    }

    #[test]
    fn the_start_of_a_change_is_trimmed_from_the_plateau_before() {
        // Up, down, then to the next level: the running median stays at the first
        // level over the two samples at 20, which end the plateau all the same.
        let mut v = stepped(&[10.0], 40, 0);
        v.extend([20.0, 20.0, 0.0, 0.0]);
        v.extend(stepped(&[30.0], 40, 0));
        let s = plateaus(&v);
        assert_eq!(s.plateaus, [0..40, 44..84]);
        assert_eq!(s.transitions, vec![40..44]);
    }

    #[test]
    fn a_hold_too_short_is_a_transition() {
        let v = stepped(&[10.0, 20.0, 30.0], 20, 0);
        let mut v2 = v[..20].to_vec();
        v2.extend(&v[20..28]); // 8 samples at 20
        v2.extend(&v[40..60]);
        let s = plateaus(&v2);
        assert_eq!(s.plateaus, [0..20, 28..48]);
        assert_eq!(s.transitions, vec![20..28]);
    }
}
