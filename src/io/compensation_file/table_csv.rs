//! The error table as a neutral CSV: `position_deg,value_arcsec` on a rotary axis,
//! `position_mm,value_um` on a linear one (units in the column names), one row per
//! table point, each value added to the commanded position as in rtid's convention
//! (docs/compensation.md); `#` lines before the header state the convention and the
//! backlash.

use std::fmt::Write as _;
use std::path::Path;

use crate::controller::ErrorTable;
use crate::experiments::positioning::iso230::ReportUnits;
use crate::model::Axis;

/// The CSV text of `table` on `axis`, with `backlash` (rad or m) in a comment.
pub fn text(table: &ErrorTable, axis: Axis, backlash: Option<f64>) -> String {
    let u = ReportUnits::of(axis);
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
