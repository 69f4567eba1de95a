//! Each experiment's data against the model at the start and the result, as the
//! result file holds them ([`crate::identify::pipeline::comparison`] computes them).

use serde::{Deserialize, Serialize};

/// What a curve shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    Measured,
    /// The model at the start values.
    Start,
    /// The model at the identified values.
    Fitted,
}

/// One curve of a comparison.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Curve {
    pub label: String,
    pub role: Role,
    pub points: Vec<(f64, f64)>,
}

/// The data of one experiment and the model, in the experiment's axes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// The experiment file.
    pub source: String,
    pub x_label: String,
    pub y_label: String,
    pub curves: Vec<Curve>,
}

impl Comparison {
    /// The same curves with at most `max` points each.
    pub fn thinned(mut self, max: usize) -> Comparison {
        for c in &mut self.curves {
            c.thin(max);
        }
        self
    }
}

impl Curve {
    /// Keeps at most `max` points (every k-th).
    pub(crate) fn thin(&mut self, max: usize) {
        let every = self.points.len().div_ceil(max.max(1)).max(1);
        self.points = std::mem::take(&mut self.points)
            .into_iter()
            .step_by(every)
            .collect();
    }
}
