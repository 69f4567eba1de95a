//! The rows of a `friction_map` experiment: one constant-speed run each, its mean
//! speed and mean effort at the motor, and how they were obtained (the run statistics
//! of `io::import::runs`).

use super::{Axis, Columns};

/// A friction map: one row per constant-speed run, in SI units — speeds in rad/s and
/// efforts in N·m on a rotary axis, m/s and N on a linear one. Every series has one
/// value per run; the optional ones are either given for every run or absent.
///
/// Rows are read and written in order of increasing speed ([`FrictionMap::sorted`]);
/// speeds are non-zero (a run at rest is not on the map) and distinct (one row per
/// run).
#[derive(Clone, Debug, PartialEq)]
pub struct FrictionMap {
    /// Rotary (rad/s, N·m) or linear (m/s, N).
    pub axis: Axis,
    /// Each run's mean speed, rad/s or m/s (negative: the negative direction).
    pub speed: Vec<f64>,
    /// Each run's mean effort: torque, N·m, or force, N.
    pub effort: Vec<f64>,
    /// The sample standard deviation (n − 1 denominator) of the speed over each run.
    pub speed_std: Option<Vec<f64>>,
    /// The sample standard deviation of the effort over each run.
    pub effort_std: Option<Vec<f64>>,
    /// Samples averaged per run (whole numbers).
    pub samples: Option<Vec<f64>>,
    /// Glitch samples dropped per run (whole numbers).
    pub dropped: Option<Vec<f64>>,
    /// Samples left out at each run's start before the speed settled (whole numbers).
    pub transient: Option<Vec<f64>>,
    /// Columns not interpreted, values as written.
    pub extra: Columns,
}

impl FrictionMap {
    /// A map of mean speeds and efforts alone.
    pub fn new(axis: Axis, speed: Vec<f64>, effort: Vec<f64>) -> FrictionMap {
        FrictionMap {
            axis,
            speed,
            effort,
            speed_std: None,
            effort_std: None,
            samples: None,
            dropped: None,
            transient: None,
            extra: Columns::new(),
        }
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        self.speed.len()
    }

    /// True when there is no run.
    pub fn is_empty(&self) -> bool {
        self.speed.is_empty()
    }

    /// The row indices in order of increasing speed (a stable order: equal speeds, which
    /// a map refuses, keep theirs).
    pub fn speed_order(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.speed.len()).collect();
        order.sort_by(|&a, &b| self.speed[a].total_cmp(&self.speed[b]));
        order
    }

    /// The same runs with every series, the extra columns included, in order of
    /// increasing speed.
    pub fn sorted(&self) -> FrictionMap {
        let order = self.speed_order();
        let pick = |v: &[f64]| order.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        let pick_some = |v: &Option<Vec<f64>>| v.as_deref().map(pick);
        FrictionMap {
            axis: self.axis,
            speed: pick(&self.speed),
            effort: pick(&self.effort),
            speed_std: pick_some(&self.speed_std),
            effort_std: pick_some(&self.effort_std),
            samples: pick_some(&self.samples),
            dropped: pick_some(&self.dropped),
            transient: pick_some(&self.transient),
            extra: self
                .extra
                .iter()
                .map(|(name, v)| (name.clone(), pick(v)))
                .collect(),
        }
    }

    /// What a map file may not hold, as a message: series of other lengths than the
    /// speeds, a speed of 0, two runs at the same speed, counts that are not whole
    /// numbers ≥ 0. (Non-finite values are the writer's general check.)
    pub(super) fn check(&self) -> Result<(), String> {
        let n = self.speed.len();
        let series = [
            ("effort", Some(&self.effort)),
            ("speed_std", self.speed_std.as_ref()),
            ("effort_std", self.effort_std.as_ref()),
            ("samples", self.samples.as_ref()),
            ("dropped", self.dropped.as_ref()),
            ("transient", self.transient.as_ref()),
        ];
        for (name, v) in series {
            if let Some(v) = v.filter(|v| v.len() != n) {
                return Err(format!(
                    "`{name}` has {} values but `speed` has {n}",
                    v.len()
                ));
            }
        }
        if let Some(row) = self.speed.iter().position(|&v| v == 0.0) {
            return Err(format!(
                "run {}: a speed of 0 (a run at rest is not on a friction map)",
                row + 1
            ));
        }
        let order = self.speed_order();
        if let Some(w) = order
            .windows(2)
            .find(|w| self.speed[w[0]] == self.speed[w[1]])
        {
            return Err(format!(
                "runs {} and {} have the same speed {}: one row per run",
                w[0].min(w[1]) + 1,
                w[0].max(w[1]) + 1,
                self.speed[w[0]]
            ));
        }
        for (name, v) in series.iter().skip(3) {
            if let Some((row, x)) = v
                .iter()
                .flat_map(|v| v.iter().enumerate())
                .find(|(_, x)| count(**x).is_err())
            {
                return Err(format!(
                    "`{name}`, run {}: {x} is not a whole number ≥ 0",
                    row + 1
                ));
            }
        }
        Ok(())
    }
}

/// A count of samples: a whole number ≥ 0 (`12` or `12.0`).
pub(super) fn count(x: f64) -> Result<f64, String> {
    if x.is_finite() && x >= 0.0 && x.fract() == 0.0 {
        Ok(x)
    } else {
        Err(format!("{x} is not a count (a whole number ≥ 0)"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorting_takes_every_series_and_the_extras_along() {
        let mut m = FrictionMap::new(Axis::Rotary, vec![2.0, -1.0, 1.0], vec![0.2, -0.1, 0.1]);
        m.samples = Some(vec![20.0, 10.0, 30.0]);
        m.extra.insert("x".into(), vec![2.5, -1.5, 1.5]);
        let s = m.sorted();
        assert_eq!(s.speed, [-1.0, 1.0, 2.0]);
        assert_eq!(s.effort, [-0.1, 0.1, 0.2]);
        assert_eq!(s.samples.as_deref(), Some(&[10.0, 30.0, 20.0][..]));
        assert_eq!(s.extra["x"], [-1.5, 1.5, 2.5]);
        assert_eq!(s.speed_std, None);
    }

    #[test]
    fn zero_and_repeated_speeds_and_broken_counts_are_refused() {
        let m = FrictionMap::new(Axis::Linear, vec![0.1, 0.0], vec![1.0, 0.0]);
        assert!(m.check().unwrap_err().contains("run 2: a speed of 0"));
        let m = FrictionMap::new(Axis::Linear, vec![0.1, -0.2, 0.1], vec![1.0, -1.0, 1.0]);
        let e = m.check().unwrap_err();
        assert!(e.contains("runs 1 and 3 have the same speed"), "{e}");
        let mut m = FrictionMap::new(Axis::Rotary, vec![1.0, 2.0], vec![1.0, 2.0]);
        m.check().unwrap();
        m.dropped = Some(vec![0.0, 1.5]);
        assert!(m.check().unwrap_err().contains("`dropped`, run 2"));
        m.dropped = Some(vec![0.0]);
        assert!(m.check().unwrap_err().contains("has 1 values"));
    }
}
