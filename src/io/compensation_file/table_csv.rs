//! The error table as a neutral CSV: `position_deg,value_arcsec` on a rotary axis,
//! `position_mm,value_um` on a linear one (units in the column names), one row per
//! table point, each value added to the commanded position as in rtid's convention
//! (docs/compensation.md); `#` lines before the header state the convention and the
//! backlash.

use std::fmt::Write as _;
use std::path::Path;

use crate::controller::ErrorTable;
use crate::model::Axis;

/// The columns' units on an axis: per SI unit and the column-name suffix, of a
/// position and of a value.
struct Units {
    target_per_si: f64,
    target_key: &'static str,
    deviation_per_si: f64,
    deviation_key: &'static str,
}

fn units(axis: Axis) -> Units {
    let degrees = 180.0 / std::f64::consts::PI;
    match axis {
        Axis::Rotary => Units {
            target_per_si: degrees,
            target_key: "deg",
            deviation_per_si: degrees * 3600.0,
            deviation_key: "arcsec",
        },
        Axis::Linear => Units {
            target_per_si: 1e3,
            target_key: "mm",
            deviation_per_si: 1e6,
            deviation_key: "um",
        },
    }
}

/// The CSV text of `table` on `axis`, with `backlash` (rad or m) in a comment.
pub fn text(table: &ErrorTable, axis: Axis, backlash: Option<f64>) -> String {
    let u = units(axis);
    let mut s = String::new();
    // Invariant: writing to a String does not fail.
    let _ = writeln!(
        s,
        "# rtid error table: each value is added to the commanded position (docs/compensation.md)"
    );
    if let Some(b) = backlash {
        let _ = writeln!(
            s,
            "# backlash, added while the commanded direction is down: {:.4} {}",
            b * u.deviation_per_si,
            u.deviation_key
        );
    }
    if let Some(m) = table.modulo {
        let _ = writeln!(s, "# modulo {:.6} {}", m * u.target_per_si, u.target_key);
    }
    let _ = writeln!(s, "position_{},value_{}", u.target_key, u.deviation_key);
    for (p, v) in table.positions.iter().zip(&table.values) {
        let _ = writeln!(
            s,
            "{:.6},{:.4}",
            p * u.target_per_si,
            v * u.deviation_per_si
        );
    }
    s
}

/// Writes `text` at `path` atomically.
pub fn write(path: &Path, text: &str) -> std::io::Result<()> {
    super::super::atomic::write(path, text.as_bytes())
}
