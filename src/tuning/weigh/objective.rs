//! How settings are weighed against today's (docs/tuning.md, "The search"): each
//! criterion of [`Criteria`] as a ratio to today's value (each with a floor, so that
//! a figure near zero today does not make noise decide), weighted by the
//! [`Objective`]; a candidate beats today's setting when its weighted mean ratio is
//! below 1. A criterion worse than today's beyond its tolerance is named ([`Worse`]).

use serde::Serialize;

use super::criteria::Criteria;
use super::verify::STEP_S;

/// What the tuning is for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Objective {
    /// Point-to-point positioning: ISO 230-2 A and R after compensation first, then
    /// the step's settling at the table (the default).
    #[default]
    Positioning,
    /// Contouring: the following error and the reversal spike first.
    Following,
    /// Settling: the step's settling and overshoot at the table first.
    Settling,
}

impl std::str::FromStr for Objective {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "positioning" => Ok(Objective::Positioning),
            "following" | "contouring" => Ok(Objective::Following),
            "settling" => Ok(Objective::Settling),
            _ => Err(format!(
                "unknown objective {s:?}: positioning, following (contouring) or settling"
            )),
        }
    }
}

impl std::fmt::Display for Objective {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Objective::Positioning => "positioning",
            Objective::Following => "following",
            Objective::Settling => "settling",
        })
    }
}

/// One figure of [`Criteria`] that a setting is judged by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Criterion {
    /// ISO 230-2 accuracy A after the compensation built for the setting.
    Accuracy,
    /// ISO 230-2 bidirectional repeatability R after it.
    Repeatability,
    /// When a 1° (1 mm) step settles within 20″ (20 µm) at the table.
    TableSettling,
    /// The step's overshoot at the table.
    TableOvershoot,
    /// The following error at constant speed.
    FollowingError,
    /// The reversal spike.
    ReversalSpike,
    /// The peak torque (force) of the move.
    PeakEffort,
    /// The table's motion at rest after the step.
    MotionAtRest,
}

/// Every criterion, in the order tables show them.
pub const ALL: [Criterion; 8] = [
    Criterion::Accuracy,
    Criterion::Repeatability,
    Criterion::TableSettling,
    Criterion::TableOvershoot,
    Criterion::FollowingError,
    Criterion::ReversalSpike,
    Criterion::PeakEffort,
    Criterion::MotionAtRest,
];

impl Criterion {
    /// The criterion's name in tables and warnings.
    pub fn label(self) -> &'static str {
        match self {
            Criterion::Accuracy => "ISO 230-2 A after compensation",
            Criterion::Repeatability => "ISO 230-2 R after compensation",
            Criterion::TableSettling => "step settled at the table",
            Criterion::TableOvershoot => "step overshoot at the table",
            Criterion::FollowingError => "following error, motor × ratio",
            Criterion::ReversalSpike => "reversal spike, motor × ratio",
            Criterion::PeakEffort => "peak torque of the move",
            Criterion::MotionAtRest => "table motion at rest",
        }
    }

    /// The criterion's value on `c`; a step that never settles counts as twice the
    /// step's length.
    pub fn value(self, c: &Criteria) -> f64 {
        let s = &c.servo;
        match self {
            Criterion::Accuracy => c.positioning.a,
            Criterion::Repeatability => c.positioning.r,
            Criterion::TableSettling => s.table_settling_s.unwrap_or(2.0 * STEP_S),
            Criterion::TableOvershoot => s.table_overshoot_percent,
            Criterion::FollowingError => s.following_error,
            Criterion::ReversalSpike => s.reversal_spike,
            Criterion::PeakEffort => s.move_peak_effort,
            Criterion::MotionAtRest => s.table_motion_at_rest,
        }
    }

    /// The unit of [`Criterion::value`] (`deviation`: the axis's ″ or µm; `effort`:
    /// N·m or N).
    pub fn unit(self, deviation: &'static str, effort: &'static str) -> &'static str {
        match self {
            Criterion::TableSettling => "s",
            Criterion::TableOvershoot => "%",
            Criterion::PeakEffort => effort,
            _ => deviation,
        }
    }

    /// Below this a difference is noise: 0.5 report units of a deviation, 10 ms,
    /// 1 % of the step, 2 % of today's effort.
    pub fn floor(self, today: f64) -> f64 {
        match self {
            Criterion::TableSettling => 0.01,
            Criterion::TableOvershoot => 1.0,
            Criterion::PeakEffort => 0.02 * today.abs(),
            _ => 0.5,
        }
    }
}

/// The weight of each criterion an objective does not list: enough that a setting
/// which makes one of them several times worse pays for it.
pub const OTHERS: f64 = 0.05;

impl Objective {
    /// The criteria and their weights; every other criterion weighs [`OTHERS`].
    pub fn weights(self) -> &'static [(Criterion, f64)] {
        use Criterion::*;
        match self {
            Objective::Positioning => &[
                (Accuracy, 1.0),
                (Repeatability, 0.5),
                (TableSettling, 0.25),
                (TableOvershoot, 0.1),
                (FollowingError, 0.1),
            ],
            Objective::Following => &[
                (FollowingError, 1.0),
                (ReversalSpike, 0.5),
                (Accuracy, 0.25),
                (TableSettling, 0.1),
            ],
            Objective::Settling => &[
                (TableSettling, 1.0),
                (TableOvershoot, 0.5),
                (Accuracy, 0.25),
                (FollowingError, 0.1),
            ],
        }
    }

    /// The weighted mean ratio of `c`'s criteria to `today`'s, over every criterion:
    /// 1 for today's setting, below 1 for a better one.
    pub fn score(self, c: &Criteria, today: &Criteria) -> f64 {
        self.score_of(&values(c), &values(today))
    }

    /// [`Objective::score`] of the criteria's values (in the order of [`ALL`]):
    /// linear in `c`, so the score of an ensemble's mean values is the mean of its
    /// members' scores.
    pub fn score_of(self, c: &Values, today: &Values) -> f64 {
        let (sum, weight) = ALL
            .iter()
            .enumerate()
            .fold((0.0, 0.0), |(sum, weight), (i, &k)| {
                let w = self.weight(k);
                let floor = k.floor(today[i]);
                (sum + w * (c[i] + floor) / (today[i] + floor), weight + w)
            });
        sum / weight
    }

    /// The weight of `k`: the objective's, or [`OTHERS`].
    pub fn weight(self, k: Criterion) -> f64 {
        self.weights()
            .iter()
            .find(|(l, _)| *l == k)
            .map_or(OTHERS, |(_, w)| *w)
    }

    /// Whether the objective lists `k`.
    pub fn lists(self, k: Criterion) -> bool {
        self.weights().iter().any(|(l, _)| *l == k)
    }
}

/// Every criterion's value, in the order of [`ALL`].
pub type Values = [f64; ALL.len()];

/// The values of `c`'s criteria ([`Criterion::value`]), in the order of [`ALL`].
pub fn values(c: &Criteria) -> Values {
    ALL.map(|k| k.value(c))
}

impl Objective {
    /// Whether `c` is no worse than `today` on any criterion the objective lists
    /// (as [`worse`] judges): such a setting is preferred to a better-scoring one
    /// that trades one of them away.
    pub fn keeps(self, c: &Criteria, today: &Criteria) -> bool {
        worse(c, today).iter().all(|w| !self.lists(w.criterion))
    }
}

/// A criterion a setting makes worse than today's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Worse {
    pub criterion: Criterion,
    pub before: f64,
    pub after: f64,
}

/// The criteria `c` makes worse than `today` by more than [`Criterion::tolerance`]
/// (excursions at the table, settling, overshoot, effort; the table's motion at rest
/// included).
pub fn worse(c: &Criteria, today: &Criteria) -> Vec<Worse> {
    ALL.iter()
        .filter_map(|&k| {
            let (before, after) = (k.value(today), k.value(c));
            (after > before + k.tolerance(before)).then_some(Worse {
                criterion: k,
                before,
                after,
            })
        })
        .collect()
}

impl Criterion {
    /// A change smaller than this from `today`'s value is no change: 2 % of it and a
    /// tenth of the floor.
    pub fn tolerance(self, today: f64) -> f64 {
        0.02 * today.abs() + 0.1 * self.floor(today)
    }
}
