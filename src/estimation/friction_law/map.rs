//! The checks of a map before any fit: runs both ways, at least two speeds each way,
//! none at rest, efforts that change sign with the direction.

use std::fmt;

use serde::{Deserialize, Serialize};

/// A direction of motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// v > 0.
    Positive,
    /// v < 0.
    Negative,
}

impl Direction {
    /// The direction of a speed ≠ 0.
    pub fn of(v: f64) -> Direction {
        if v > 0.0 {
            Direction::Positive
        } else {
            Direction::Negative
        }
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Direction::Positive => "positive",
            Direction::Negative => "negative",
        })
    }
}

/// Why a map cannot be fitted. The messages name no file: the caller prefixes it.
/// Runs are counted from 1, in the order given.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MapProblem {
    #[error("{speeds} speeds but {efforts} efforts: one of each per run")]
    LengthMismatch { speeds: usize, efforts: usize },
    #[error("the map has no runs")]
    Empty,
    #[error("run {run}: its {series} is {value}: every value must be a finite number")]
    NotFinite {
        series: &'static str,
        run: usize,
        value: f64,
    },
    #[error("run {run}: a speed of exactly 0 is refused — a run at rest is not on the map")]
    ZeroSpeed { run: usize },
    #[error("one direction only: every speed is {direction}; friction laws need runs both ways")]
    OneDirection { direction: Direction },
    #[error(
        "a single speed in the {direction} direction ({speed}): the map needs at least 2 \
         distinct speeds per direction"
    )]
    SingleSpeed { direction: Direction, speed: f64 },
    #[error(
        "every effort is {sign} or zero although the speeds have both signs: friction \
         opposes the motion, so the effort changes sign with the direction unless a load \
         larger than the friction offsets it — check the effort's sign \
         (--map effort=…*-1)"
    )]
    EffortOfOneSign { sign: &'static str },
}

/// The §2 checks of a map given as each run's mean `speed` (rad/s or m/s) and mean
/// `effort` (N·m or N), in that order: finite values of equal counts, no speed of 0,
/// both directions with at least 2 distinct speeds each ([`distinct_speeds`]), and
/// efforts of both signs.
pub fn check_map(speed: &[f64], effort: &[f64]) -> Result<(), MapProblem> {
    if speed.len() != effort.len() {
        return Err(MapProblem::LengthMismatch {
            speeds: speed.len(),
            efforts: effort.len(),
        });
    }
    if speed.is_empty() {
        return Err(MapProblem::Empty);
    }
    for (series, values) in [("speed", speed), ("effort", effort)] {
        if let Some((i, &value)) = values.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(MapProblem::NotFinite {
                series,
                run: i + 1,
                value,
            });
        }
    }
    if let Some(i) = speed.iter().position(|&v| v == 0.0) {
        return Err(MapProblem::ZeroSpeed { run: i + 1 });
    }
    for direction in [Direction::Positive, Direction::Negative] {
        let other = match direction {
            Direction::Positive => Direction::Negative,
            Direction::Negative => Direction::Positive,
        };
        let distinct = distinct_speeds(speed, other);
        if distinct.is_empty() {
            return Err(MapProblem::OneDirection { direction });
        }
    }
    for direction in [Direction::Positive, Direction::Negative] {
        if let [u] = distinct_speeds(speed, direction)[..] {
            let speed = if direction == Direction::Positive {
                u
            } else {
                -u
            };
            return Err(MapProblem::SingleSpeed { direction, speed });
        }
    }
    if effort.iter().all(|&e| e >= 0.0) {
        return Err(MapProblem::EffortOfOneSign { sign: "positive" });
    }
    if effort.iter().all(|&e| e <= 0.0) {
        return Err(MapProblem::EffortOfOneSign { sign: "negative" });
    }
    Ok(())
}

/// The distinct |speeds| of the runs in `direction`, ascending; speeds that agree to
/// nine significant digits count once (one speed written twice, or converted twice).
pub fn distinct_speeds(speed: &[f64], direction: Direction) -> Vec<f64> {
    let mut u: Vec<f64> = speed
        .iter()
        .filter(|&&v| v != 0.0 && Direction::of(v) == direction)
        .map(|v| v.abs())
        .collect();
    u.sort_by(f64::total_cmp);
    u.dedup_by(|later, kept| (*later - *kept).abs() <= 1e-9 * later.abs());
    u
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distinct_speeds_merge_what_agrees_to_nine_digits() {
        let v = [1.0, -2.0, 1.0 + 1e-12, 3.0, -2.0, 0.5];
        assert_eq!(
            distinct_speeds(&v, Direction::Positive),
            vec![0.5, 1.0, 3.0]
        );
        assert_eq!(distinct_speeds(&v, Direction::Negative), vec![2.0]);
    }

    #[test]
    fn finite_values_of_equal_counts_are_required() {
        assert_eq!(
            check_map(&[1.0, -1.0], &[1.0]),
            Err(MapProblem::LengthMismatch {
                speeds: 2,
                efforts: 1
            })
        );
        assert_eq!(check_map(&[], &[]), Err(MapProblem::Empty));
        let e = check_map(&[1.0, 2.0, -1.0, -2.0], &[1.0, f64::NAN, -1.0, -1.0]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "run 2: its effort is NaN: every value must be a finite number"
        );
    }
}
