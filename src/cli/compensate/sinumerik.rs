//! `rtid compensate --sinumerik FILE --axis-number N [--reference-deg|--reference-mm]`:
//! the error table as a SINUMERIK EEC program, zero at the axis's reference point
//! (docs/compensation.md), and the shift that took stated in the output.

use anyhow::{bail, Context};

use super::{table_of, Args, Origin};
use rtid::experiments::positioning::compensate::Computed;
use rtid::experiments::positioning::iso230::ReportUnits;
use rtid::io::compensation_file::sinumerik::{self, Grid, Reference, SinumerikError};
use rtid::model::Axis;

/// The program's table: resampled onto SINUMERIK's grid, zero at the reference point.
pub struct Zeroed {
    pub grid: Grid,
    pub reference: Reference,
}

/// The program's table when `--sinumerik` is asked for, checked before anything is
/// written: the reference is `--reference-deg`/`--reference-mm`, else the table's
/// first point.
pub fn table(a: &Args, c: &Computed) -> anyhow::Result<Option<Zeroed>> {
    if a.sinumerik.is_none() {
        return Ok(None);
    }
    let grid = Grid::of(table_of(c)?)?;
    let (start, end) = (grid.start, grid.end());
    let Some((option, given, position)) = reference(a, c.axis)? else {
        let (grid, reference) = grid.zeroed_at(start)?;
        return Ok(Some(Zeroed { grid, reference }));
    };
    match grid.zeroed_at(position) {
        Ok((grid, reference)) => Ok(Some(Zeroed { grid, reference })),
        Err(SinumerikError::ReferenceOutside { .. }) => {
            let u = ReportUnits::of(c.axis);
            let k = u.target_per_si;
            bail!(
                "{option} {given}: outside the SINUMERIK table, which runs from {:.3} to {:.3} {}",
                start * k,
                end * k,
                u.target_key
            )
        }
        Err(e) => Err(e.into()),
    }
}

/// The reference option given: its name, its value as given, and the position (rad
/// or m); refused on the other kind of axis.
fn reference(a: &Args, axis: Axis) -> anyhow::Result<Option<(&'static str, f64, f64)>> {
    match (axis, a.reference_deg, a.reference_mm) {
        (_, None, None) => Ok(None),
        (Axis::Rotary, Some(deg), None) => Ok(Some(("--reference-deg", deg, deg.to_radians()))),
        (Axis::Linear, None, Some(mm)) => Ok(Some(("--reference-mm", mm, mm * 1e-3))),
        (Axis::Rotary, _, Some(_)) => {
            bail!("--reference-mm is for a linear axis; this axis is rotary (--reference-deg)")
        }
        (Axis::Linear, Some(_), _) => {
            bail!("--reference-deg is for a rotary axis; this axis is linear (--reference-mm)")
        }
    }
}

/// The program's text for `--axis-number`.
pub fn program(a: &Args, o: &Origin, c: &Computed, z: &Zeroed) -> anyhow::Result<String> {
    let n = a
        .axis_number
        .context("--sinumerik needs --axis-number N (the machine axis AX<N>)")?;
    let note = format!(
        "rtid {} compensate {}{}",
        rtid::VERSION,
        o.name,
        a.runs
            .as_ref()
            .map_or(String::new(), |r| format!(" --runs {r}"))
    );
    Ok(sinumerik::program(
        &z.grid,
        &z.reference,
        c.axis,
        n,
        c.compensation.backlash,
        &note,
    ))
}

/// The shift in words, in the report's units.
pub fn summary(z: &Zeroed, axis: Axis) -> String {
    let u = ReportUnits::of(axis);
    format!(
        "SINUMERIK program: zero at the reference point {:.2}{}, rtid's table less its value \
         there, {:.2}{}, at every point (E, A, R unchanged; the axis keeps the reference \
         point's own deviation as a constant offset)",
        z.reference.position * u.target_per_si,
        u.target,
        z.reference.shift * u.deviation_per_si,
        u.deviation
    )
}

/// The shift in the command's JSON: the reference in degrees or mm, the shift in the
/// report's deviation unit.
pub fn json(z: &Zeroed, axis: Axis) -> anyhow::Result<serde_json::Value> {
    let u = ReportUnits::of(axis);
    let num = |x: f64| rtid::io::json::value(&x);
    Ok(serde_json::json!({
        format!("reference_{}", u.target_key): num(z.reference.position * u.target_per_si)?,
        "shift": num(z.reference.shift * u.deviation_per_si)?,
    }))
}
