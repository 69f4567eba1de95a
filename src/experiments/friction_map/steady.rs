//! The model's friction map: the motor torque (force) that holds the drive at a
//! constant motor speed, from the equations of docs/model.md §2 with every
//! acceleration zero:
//!
//! ```text
//! T(ω) = Cm·ω + fm(ω) + Rg·(Cw·ωw + fw(ωw)) + Rg·Rw·(Ct·ωt + ft(ωt) − Tload)
//! ωw = Rg·ω,  ωt = Rg·Rw·ω
//! ```
//!
//! with each body's friction its Coulomb level or Stribeck curve (model/friction/) against
//! the motion. The gear fluctuation's lever and the unbalance average out over whole
//! revolutions, which is what the virtual experiment averages over for the fluctuation
//! (run.rs); the table's unbalance does not average out over a partial revolution.

use crate::model::{Drive, ParamError, Params};

/// The motor torque (force) that holds the drive `d` at the motor speed `speed`
/// (rad/s or m/s, not 0), N·m (N).
pub fn model_effort(d: &Drive, speed: f64) -> f64 {
    let [cm, cw, ct] = [d.cm, d.cw, d.ct];
    let (rg, rw) = (d.rg, d.rw);
    let (shaft, table) = (rg * speed, rg * rw * speed);
    let resist = |body: usize, w: f64| d.sliding_friction(body, w).copysign(w);
    cm * speed
        + resist(0, speed)
        + rg * (cw * shaft + resist(1, shaft))
        + rg * rw * (ct * table + resist(2, table) - d.tload())
}

/// The model's map at `speeds`: the parameters checked and compiled once.
pub fn model_map(p: &Params, speeds: &[f64]) -> Result<Vec<f64>, ParamError> {
    let d = Drive::new(p)?;
    Ok(speeds.iter().map(|&v| model_effort(&d, v)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_worm_map_is_its_frictions_and_dampings_through_the_ratios() {
        let p = presets::load("worm-gear").unwrap();
        let (rg, rw) = (p.rg.unwrap(), p.rw);
        let w = 10.0;
        let expected =
            p.cm * w + p.fm + rg * (p.cw * rg * w + p.fw) + rg * rw * (p.ct * rg * rw * w + p.ft);
        let got = model_map(&p, &[w, -w]).unwrap();
        assert!((got[0] - expected).abs() < 1e-12 * expected, "{got:?}");
        assert!((got[1] + expected).abs() < 1e-12 * expected, "{got:?}");
    }

    #[test]
    fn a_load_offsets_both_directions_and_a_rise_lifts_the_slow_runs() {
        let mut p = presets::load("direct-drive").unwrap();
        p.tload = 0.2;
        let m = model_map(&p, &[1.0, -1.0]).unwrap();
        assert!((m[0] + m[1] + 0.4).abs() < 1e-12, "{m:?}");
        (p.fst, p.vst) = (0.5, 0.1);
        let slow = model_map(&p, &[0.1]).unwrap()[0];
        let expected = p.ct * 0.1 + p.ft + 0.5 * (-1.0f64).exp() - 0.2;
        assert!((slow - expected).abs() < 1e-12, "{slow} vs {expected}");
    }
}
