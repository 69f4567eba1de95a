//! `rtid.run_experiment("servo_trace", …)`: a servo trace of the model along
//! point-to-point moves, as `rtid experiment servo-trace` records it.

use pyo3::prelude::*;

use super::{limit, Settings, Work};
use crate::errors::{bad_argument, rtid_error};
use rtid::experiments::servo_trace::{self, MoveTo, TrapezoidalMoves};
use rtid::limits;
use rtid::model::Params;

/// The moves the settings describe, checked before anything runs, and the run.
pub fn prepare(s: &Settings, p: &Params) -> PyResult<Work> {
    let mut m = TrapezoidalMoves {
        acceleration: s.get("acceleration")?,
        dwell_s: s.get("dwell_s")?,
        ..Default::default()
    };
    if let Some(moves) = s.get::<Option<Vec<(f64, f64)>>>("moves")? {
        m.moves = moves
            .into_iter()
            .map(|(target, speed)| MoveTo { target, speed })
            .collect();
    }
    m.check()
        .map_err(|e| bad_argument("moves, acceleration, dwell_s", e))?;
    limit(
        m.duration(),
        limits::MAX_SIMULATED_S,
        "simulated seconds",
        "moves, acceleration, dwell_s",
    )?;
    let p = p.clone();
    Ok(Box::new(move || {
        let trace = servo_trace::virtual_trace(&p, &m, None).map_err(|e| rtid_error(&e))?;
        Ok(servo_trace::to_file(&p, &m, &trace))
    }))
}
