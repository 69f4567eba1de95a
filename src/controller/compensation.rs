//! The compensations every CNC applies to the commanded position — backlash and an
//! angle (pitch) error table — and the friction compensation it adds to the torque
//! setpoint, as plain settings (docs/compensation.md states the convention; the
//! controller applies them, `Controller::set_compensation`).
//!
//! **Convention.** Each value is *added to the commanded position* of the axis
//! (rad or m, SI inside), at the commanded position and in the commanded direction:
//!
//! ```text
//! offset(p, ↑) = table(p)
//! offset(p, ↓) = table(p) + backlash
//! ```
//!
//! so that a table of −(mean deviation approaching upwards) and a backlash of the
//! mean reversal value B̄ = mean(x̄↑ − x̄↓) of ISO 230-2 cancel the deviations of a
//! record in both directions, up to the target-to-target scatter of the reversal.
//! The direction is that of the last commanded motion (upwards before the first).

use serde::{Deserialize, Serialize};

use crate::model::friction::SteadyFriction;

/// An angle (pitch) error table: values at increasing positions, interpolated
/// linearly between them, the first and last values held outside; on a rotary axis
/// with a `modulo` (2π), positions are taken modulo it first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ErrorTable {
    /// Strictly increasing, rad or m.
    pub positions: Vec<f64>,
    /// Added to the commanded position at each of `positions`, rad or m.
    pub values: Vec<f64>,
    /// The period of a rotary axis's positions, rad (`None`: no wrap).
    pub modulo: Option<f64>,
}

/// Why a table cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TableError {
    #[error("the table has {positions} positions and {values} values: one value per position")]
    Lengths { positions: usize, values: usize },
    #[error("the table is empty")]
    Empty,
    #[error(
        "table position {index} ({value}) is not finite or does not increase on the one before"
    )]
    NotIncreasing { index: usize, value: f64 },
    #[error("table value {index} is not finite")]
    NotFinite { index: usize },
    #[error("the table's modulo {0} is not a positive finite period")]
    Modulo(f64),
}

impl ErrorTable {
    /// Checks the table: as many values as positions, at least one, positions strictly
    /// increasing, everything finite, a positive modulo.
    pub fn check(&self) -> Result<(), TableError> {
        let (n, m) = (self.positions.len(), self.values.len());
        if n != m {
            return Err(TableError::Lengths {
                positions: n,
                values: m,
            });
        }
        if n == 0 {
            return Err(TableError::Empty);
        }
        for (i, &p) in self.positions.iter().enumerate() {
            if !p.is_finite() || (i > 0 && p <= self.positions[i - 1]) {
                return Err(TableError::NotIncreasing { index: i, value: p });
            }
        }
        if let Some(i) = self.values.iter().position(|v| !v.is_finite()) {
            return Err(TableError::NotFinite { index: i });
        }
        match self.modulo {
            Some(m) if !(m.is_finite() && m > 0.0) => Err(TableError::Modulo(m)),
            _ => Ok(()),
        }
    }

    /// The value at `position`: linear between the points, held outside them.
    pub fn at(&self, position: f64) -> f64 {
        let p = match self.modulo {
            Some(m) => position.rem_euclid(m),
            None => position,
        };
        let x = &self.positions;
        let last = x.len() - 1;
        if p <= x[0] {
            return self.values[0];
        }
        if p >= x[last] {
            return self.values[last];
        }
        let i = x.partition_point(|&xi| xi <= p) - 1;
        let w = (p - x[i]) / (x[i + 1] - x[i]);
        self.values[i] + w * (self.values[i + 1] - self.values[i])
    }
}

/// A pulse added to the torque setpoint at each reversal of the commanded direction:
/// amplitude·exp(−t/decay) in the new direction, t from the reversal.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReversalPulse {
    /// N·m (N) at the motor, ≥ 0.
    pub amplitude: f64,
    /// s, > 0.
    pub decay_s: f64,
}

/// Friction compensation: the identified law at the motor fed forward on the
/// commanded motor velocity (nothing at a commanded standstill), plus an optional
/// pulse at each reversal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionCompensation {
    /// The law at the motor (N·m or N against rad/s or m/s).
    pub law: SteadyFriction,
    /// Added to the law's effort at every commanded speed ≠ 0, N·m (N): the map's
    /// offset, if compensated.
    pub offset: f64,
    pub pulse: Option<ReversalPulse>,
}

/// The compensations of an axis, each off when `None`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Compensation {
    /// Added to the commanded position while the commanded direction is negative,
    /// rad or m.
    pub backlash: Option<f64>,
    pub table: Option<ErrorTable>,
    pub friction: Option<FrictionCompensation>,
}

impl Compensation {
    /// Whether nothing is compensated.
    pub fn is_off(&self) -> bool {
        self.backlash.is_none() && self.table.is_none() && self.friction.is_none()
    }

    /// The value added to the commanded position `position` (rad or m) when the
    /// commanded direction is negative (`downwards`) or not.
    pub fn position_offset(&self, position: f64, downwards: bool) -> f64 {
        let table = self.table.as_ref().map_or(0.0, |t| t.at(position));
        let backlash = if downwards {
            self.backlash.unwrap_or(0.0)
        } else {
            0.0
        };
        table + backlash
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn table(modulo: Option<f64>) -> ErrorTable {
        ErrorTable {
            positions: vec![0.0, 1.0, 3.0],
            values: vec![1.0, 3.0, -1.0],
            modulo,
        }
    }

    #[test]
    fn the_table_interpolates_and_holds_its_ends() {
        let t = table(None);
        t.check().unwrap();
        assert_eq!(t.at(-5.0), 1.0);
        assert_eq!(t.at(0.5), 2.0);
        assert_eq!(t.at(2.0), 1.0);
        assert_eq!(t.at(1.0), 3.0);
        assert_eq!(t.at(9.0), -1.0);
        let wrapped = table(Some(2.0 * PI));
        assert!((wrapped.at(0.5 + 2.0 * PI) - 2.0).abs() < 1e-12);
        assert!((wrapped.at(0.5 - 4.0 * PI) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn bad_tables_are_refused() {
        let mut t = table(None);
        t.positions[2] = 1.0;
        assert_eq!(
            t.check(),
            Err(TableError::NotIncreasing {
                index: 2,
                value: 1.0
            })
        );
        let mut t = table(Some(0.0));
        assert_eq!(t.check(), Err(TableError::Modulo(0.0)));
        t.values.pop();
        assert!(matches!(t.check(), Err(TableError::Lengths { .. })));
    }

    #[test]
    fn backlash_acts_downwards_only() {
        let c = Compensation {
            backlash: Some(0.25),
            table: Some(table(None)),
            friction: None,
        };
        assert_eq!(c.position_offset(0.5, false), 2.0);
        assert_eq!(c.position_offset(0.5, true), 2.25);
        assert!(Compensation::default().is_off());
    }
}
