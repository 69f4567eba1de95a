//! The error table as a SINUMERIK encoder/leadscrew error compensation program (EEC,
//! "interpolatory compensation", function manual *Extended Functions*, K3) —
//! docs/compensation.md gives the sources.
//!
//! SINUMERIK takes equidistant points from `$AA_ENC_COMP_MIN` every
//! `$AA_ENC_COMP_STEP` to `$AA_ENC_COMP_MAX`, so the table is resampled linearly
//! onto such a grid from its first to its last position ([`Grid::of`]; the targets'
//! own points when they are already equidistant). A modulo table (a rotary axis, 0°
//! to 360°) is written with `$AA_ENC_COMP_IS_MODULO = 1`, its values at 0° and 360°
//! equal.
//!
//! **Reference point.** SINUMERIK asks for a table whose value at the axis's
//! reference point is zero, so that the axis does not jump when the compensation
//! comes on after referencing (808D Function Manual 01/2017, p. 106; 840D sl
//! *Extended Functions* 03/2013, p. 238). [`Grid::zeroed_at`] takes the table's value
//! there off every point: the compensated axis then keeps the reference point's own
//! deviation as a constant offset everywhere (E, A, R and B unchanged), which is where
//! its zero is set, not what the table is for.
//!
//! **Sign.** SINUMERIK adds its compensation value to the axis's actual position: a
//! positive value makes the axis move in the negative direction. Its value is thus
//! the axis's error, the opposite of rtid's table (added to the commanded position):
//! `$AA_ENC_COMP = −table`, which for a table built from a record is x̄↑.

use std::fmt::Write as _;
use std::path::Path;

use crate::controller::ErrorTable;
use crate::model::Axis;

/// The most points written (SINUMERIK's MD38000 `$MA_MM_ENC_COMP_MAX_POINTS` is
/// configured per axis; tables of this size are far beyond a positioning record).
pub const MAX_POINTS: usize = 5000;

/// A table that cannot be written for SINUMERIK.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SinumerikError {
    #[error("the table has one position: SINUMERIK needs at least two, a distance apart")]
    OnePoint,
    #[error("resampling the table every {step} (its closest positions) would take {points} points, over {max}")]
    TooManyPoints {
        step: f64,
        points: usize,
        max: usize,
    },
    #[error("the reference position {position} is outside the table, {start} to {end}")]
    ReferenceOutside { position: f64, start: f64, end: f64 },
    #[error("{path}: {source}")]
    Io {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
}

/// An equidistant grid of table values (SI, rtid's sign).
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub start: f64,
    pub step: f64,
    /// At `start + i·step`, i = 0…n.
    pub values: Vec<f64>,
    pub modulo: bool,
}

impl Grid {
    /// `table` resampled linearly from its first to its last position, the step the
    /// closest two positions' distance, shortened so that whole steps span the
    /// table.
    pub fn of(table: &ErrorTable) -> Result<Grid, SinumerikError> {
        let x = &table.positions;
        if x.len() < 2 {
            return Err(SinumerikError::OnePoint);
        }
        let (start, end) = (x[0], x[x.len() - 1]);
        let gap = x.windows(2).map(|w| w[1] - w[0]).fold(f64::MAX, f64::min);
        let steps = ((end - start) / gap - 1e-9).ceil().max(1.0);
        if steps >= MAX_POINTS as f64 {
            return Err(SinumerikError::TooManyPoints {
                step: gap,
                points: steps as usize + 1,
                max: MAX_POINTS,
            });
        }
        let n = steps as usize;
        let step = (end - start) / steps;
        // The last point is `end` itself (on a modulo table, `at` would wrap it to 0).
        let values = (0..=n)
            .map(|i| {
                let p = if i == n { end } else { start + step * i as f64 };
                at_unwrapped(table, p)
            })
            .collect();
        Ok(Grid {
            start,
            step,
            values,
            modulo: table.modulo.is_some(),
        })
    }
}

/// Where a program's table is zero, and what was taken off to make it so (SI, rtid's
/// sign).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// The reference point's position, rad or m.
    pub position: f64,
    /// The grid's value there before the shift, taken off every point.
    pub shift: f64,
}

impl Grid {
    /// The last point's position.
    pub fn end(&self) -> f64 {
        self.start + self.step * (self.values.len() - 1) as f64
    }

    /// The grid's value at `p`, linear between its points (as SINUMERIK
    /// interpolates); `None` outside them.
    pub fn at(&self, p: f64) -> Option<f64> {
        let (start, end) = (self.start, self.end());
        // Positions a rounding beyond the ends (360° as 2π) are the ends.
        let slack = 1e-12 * (end - start);
        if !(p >= start - slack && p <= end + slack) {
            return None;
        }
        let last = self.values.len() - 1;
        let x = ((p - start) / self.step).clamp(0.0, last as f64);
        let i = (x.floor() as usize).min(last - 1);
        let f = x - i as f64;
        Some(self.values[i] + f * (self.values[i + 1] - self.values[i]))
    }

    /// The grid less its value at `position` (rad or m), so that it is zero at the
    /// axis's reference point; refused outside the grid.
    pub fn zeroed_at(mut self, position: f64) -> Result<(Grid, Reference), SinumerikError> {
        let Some(shift) = self.at(position) else {
            return Err(SinumerikError::ReferenceOutside {
                position,
                start: self.start,
                end: self.end(),
            });
        };
        for v in &mut self.values {
            *v -= shift;
        }
        Ok((self, Reference { position, shift }))
    }
}

/// The table's value at `p` within its positions, without wrapping.
fn at_unwrapped(table: &ErrorTable, p: f64) -> f64 {
    let x = &table.positions;
    let last = x.len() - 1;
    if p >= x[last] {
        return table.values[last];
    }
    let plain = ErrorTable {
        modulo: None,
        ..table.clone()
    };
    plain.at(p)
}

/// The program for machine axis `AX{axis_number}`: the grid's values with
/// SINUMERIK's sign, in degrees or millimetres, zero at `reference` (the shift a
/// comment); `backlash` (rad or m) as a comment for MD32450; `note` (one line) says
/// where it came from.
pub fn program(
    grid: &Grid,
    reference: &Reference,
    axis: Axis,
    axis_number: u32,
    backlash: Option<f64>,
    note: &str,
) -> String {
    let (unit, k) = super::unit_of(axis);
    let ax = format!("AX{axis_number}");
    let decimals = if axis == Axis::Rotary { 9 } else { 6 };
    let n = grid.values.len();
    let end = grid.end();
    let mut s = String::new();
    // Invariant: writing to a String does not fail.
    let mut line = |text: String| {
        let _ = writeln!(s, "{text}");
    };
    line("%_N_AX_EEC_INI".into());
    line(format!("; {}", note.replace('\n', " ")));
    line(format!("; encoder/leadscrew error compensation of {ax}, {unit}; each value is the axis's error (SINUMERIK adds it to the actual position: the opposite of rtid's table)"));
    line(format!("; {n} equidistant points, resampled linearly from rtid's table; MD38000 $MA_MM_ENC_COMP_MAX_POINTS[0,{ax}] >= {n}"));
    line(format!("; zero at the reference point {:.6} {unit} (no jump when the compensation comes on): each value is -(table - {:.decimals$}), rtid's table less its value there; the axis keeps the reference point's own deviation as a constant offset", reference.position * k, reference.shift * k));
    line(format!("; load this program with MD32700 $MA_ENC_COMP_ENABLE[0,{ax}] = 0 (the table is not loaded while the compensation is on), then set MD32700 $MA_ENC_COMP_ENABLE[0,{ax}] = 1 to activate it (effective with the axis referenced)"));
    if let Some(b) = backlash {
        line(format!("; backlash (machine data, not set by this program): MD32450 $MA_BACKLASH[0,{ax}] = {:.decimals$} ({unit}: -B_mean; positive when the encoder leads the machine part, the table stopping short of its targets)", -b * k));
    }
    line("CHANDATA(1)".into());
    for (i, v) in grid.values.iter().enumerate() {
        // `+ 0.0`: the reference point's zero printed without a sign.
        line(format!(
            "$AA_ENC_COMP[0,{i},{ax}]={:.decimals$}",
            -v * k + 0.0
        ));
    }
    line(format!("$AA_ENC_COMP_STEP[0,{ax}]={:.6}", grid.step * k));
    line(format!("$AA_ENC_COMP_MIN[0,{ax}]={:.6}", grid.start * k));
    line(format!("$AA_ENC_COMP_MAX[0,{ax}]={:.6}", end * k));
    line(format!(
        "$AA_ENC_COMP_IS_MODULO[0,{ax}]={}",
        u8::from(grid.modulo)
    ));
    line("M17".into());
    s
}

/// Writes `text` (a program) at `path` atomically.
pub fn write(path: &Path, text: &str) -> Result<(), SinumerikError> {
    super::super::atomic::write(path, text.as_bytes()).map_err(|source| SinumerikError::Io {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_uneven_table_is_resampled_onto_whole_steps_and_keeps_its_points() {
        let table = ErrorTable {
            positions: vec![0.0, 0.1, 0.25, 0.3],
            values: vec![1.0, 2.0, -1.0, 0.0],
            modulo: None,
        };
        let g = Grid::of(&table).unwrap();
        // Closest positions 0.05 apart: 6 steps of 0.05 over 0.3.
        assert_eq!(g.values.len(), 7);
        assert!((g.step - 0.05).abs() < 1e-15);
        let want = [1.0, 1.5, 2.0, 1.0, 0.0, -1.0, 0.0];
        for (i, (v, w)) in g.values.iter().zip(want).enumerate() {
            assert!((v - w).abs() < 1e-12, "point {i}: {v} vs {w}");
        }
        let one = ErrorTable {
            positions: vec![0.0],
            values: vec![1.0],
            modulo: None,
        };
        assert!(matches!(Grid::of(&one), Err(SinumerikError::OnePoint)));
        let dense = ErrorTable {
            positions: vec![0.0, 1e-6, 1.0],
            values: vec![0.0; 3],
            modulo: None,
        };
        assert!(matches!(
            Grid::of(&dense),
            Err(SinumerikError::TooManyPoints { .. })
        ));
    }

    /// Zeroed at a point between two grid points, the grid interpolates to zero
    /// there; every value moves by the same shift; outside the grid it is refused.
    #[test]
    fn a_grid_zeroed_at_its_reference_is_zero_there() {
        let table = ErrorTable {
            positions: vec![0.0, 0.1, 0.2],
            values: vec![1.0, 3.0, 2.0],
            modulo: None,
        };
        let grid = Grid::of(&table).unwrap();
        let (zeroed, r) = grid.clone().zeroed_at(0.05).unwrap();
        assert_eq!(
            r,
            Reference {
                position: 0.05,
                shift: 2.0
            }
        );
        assert!(zeroed.at(0.05).unwrap().abs() < 1e-12);
        for (a, b) in grid.values.iter().zip(&zeroed.values) {
            assert!((a - b - 2.0).abs() < 1e-12);
        }
        let (first, r) = grid.clone().zeroed_at(0.0).unwrap();
        assert_eq!((first.values[0], r.shift), (0.0, 1.0));
        assert_eq!(grid.clone().zeroed_at(0.2).unwrap().1.shift, 2.0);
        for outside in [-0.01, 0.21, f64::NAN] {
            assert!(matches!(
                grid.clone().zeroed_at(outside),
                Err(SinumerikError::ReferenceOutside { .. })
            ));
        }
    }
}
