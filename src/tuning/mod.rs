//! Tuning of the drive's cascade from its model (docs/tuning.md): the velocity loop's
//! open-loop frequency response on the sampled loop ([`open_loop`]), its stability
//! margins ([`margins`]), notch filters at the resonances ([`notches`]), and the
//! velocity PI and position gain for a target phase margin with a gain-margin floor
//! ([`search`]). [`tune`] puts them together with the margins before and after;
//! [`bode`] gives a setting's open loop as a Bode plot draws it.
//!
//! Layer: above `model` and `controller` (it reads the linear response, the modes and
//! the controller's discretised filters), below `experiments` and the command line.

pub mod bode;
pub mod margins;
pub mod notches;
pub mod open_loop;
pub mod position;
pub mod search;
pub mod verify;

use serde::Serialize;

use crate::model::{ParamError, Params, SetpointFilter};
pub use margins::Margins;
pub use open_loop::{VelocityLoop, VelocityPi};

/// What the tuned velocity loop must keep.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Targets {
    /// Phase margin, deg (default 50).
    pub phase_margin_deg: f64,
    /// Gain margin floor, dB (default 6).
    pub gain_margin_db: f64,
}

impl Default for Targets {
    fn default() -> Self {
        Targets {
            phase_margin_deg: 50.0,
            gain_margin_db: 6.0,
        }
    }
}

/// Why a drive could not be tuned.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TuneError {
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error("{}", unreachable_message(*phase_margin_deg, *gain_margin_db, *best_phase_margin_deg, *best_crossover_hz, *best_gain_margin_db))]
    Unreachable {
        phase_margin_deg: f64,
        gain_margin_db: f64,
        best_phase_margin_deg: Option<f64>,
        best_crossover_hz: Option<f64>,
        best_gain_margin_db: Option<f64>,
    },
    #[error("targets must be finite with a phase margin in (0°, 180°) and a gain margin ≥ 0 dB: got {phase_margin_deg}° and {gain_margin_db} dB")]
    Targets {
        phase_margin_deg: f64,
        gain_margin_db: f64,
    },
}

fn unreachable_message(
    pm: f64,
    gm: f64,
    best: Option<f64>,
    at: Option<f64>,
    best_gm: Option<f64>,
) -> String {
    let best = match (best, at) {
        (Some(b), Some(f)) => format!(
            "the best is {b:.1}° at a crossover of {f:.2} Hz (gain margin {})",
            best_gm.map_or("unbounded".into(), |g| format!("{g:.1} dB"))
        ),
        _ => "no gain tried crosses over".into(),
    };
    format!(
        "target phase margin {pm}° with a gain margin ≥ {gm} dB not reachable with the \
         PI corner at a quarter of the crossover: {best}"
    )
}

/// One setting of the cascade and its velocity loop's margins.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Setting {
    #[serde(rename = "Kvp")]
    pub kvp: f64,
    #[serde(rename = "Kvi")]
    pub kvi: f64,
    #[serde(rename = "Kpp")]
    pub kpp: f64,
    pub filters: Vec<SetpointFilter>,
    pub velocity_loop: Margins,
    /// The closed position loop's largest gain, dB ([`position::peak_db`]).
    pub position_peak_db: f64,
}

/// The drive's settings before and after tuning, and the tuned parameter set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Tuned {
    pub targets: Targets,
    /// The resonances the notches sit at.
    pub resonances: Vec<notches::Resonance>,
    pub before: Setting,
    pub after: Setting,
    #[serde(skip)]
    pub params: Params,
}

/// Tunes `p`'s velocity and position loops for `targets` (`p` validated).
pub fn tune(p: &Params, targets: Targets) -> Result<Tuned, TuneError> {
    let (pm, gm) = (targets.phase_margin_deg, targets.gain_margin_db);
    if !(pm.is_finite() && pm > 0.0 && pm < 180.0 && gm.is_finite() && gm >= 0.0) {
        return Err(TuneError::Targets {
            phase_margin_deg: pm,
            gain_margin_db: gm,
        });
    }
    let c = &p.controller;
    let before_loop = VelocityLoop::new(p, &c.filters)?;
    let current = VelocityPi {
        kvp: c.kvp,
        kvi: c.kvi,
    };
    let before = Setting {
        kvp: c.kvp,
        kvi: c.kvi,
        kpp: c.kpp,
        filters: c.filters.clone(),
        velocity_loop: search::Grid::new(&before_loop).margins(current),
        position_peak_db: position::peak_db(&before_loop, current, c.kpp),
    };
    let nyquist = 0.5 / c.tc;
    let resonances = notches::resonances(p, notches::MAX_RELATIVE_CENTRE * nyquist)?;
    let filters = notches::notches(p)?;
    let lp = VelocityLoop::new(p, &filters)?;
    let v = search::velocity(&search::Grid::new(&lp), targets)?;
    let kpp = search::position_gain(v.margins.crossover_hz.unwrap_or(0.0));
    let mut params = p.clone();
    params.controller.kvp = v.pi.kvp;
    params.controller.kvi = v.pi.kvi;
    params.controller.kpp = kpp;
    params.controller.filters = filters.clone();
    params.validate()?;
    Ok(Tuned {
        targets,
        resonances,
        before,
        after: Setting {
            kvp: v.pi.kvp,
            kvi: v.pi.kvi,
            kpp,
            filters,
            velocity_loop: v.margins,
            position_peak_db: position::peak_db(&lp, v.pi, kpp),
        },
        params,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn an_unreachable_phase_margin_is_a_typed_error_with_the_best() {
        // The PI with its corner at a quarter of the crossover lags 14° there, the
        // plant at least its viscous lag: no crossover has 170° left.
        let p = presets::load("worm-gear").unwrap();
        let targets = Targets {
            phase_margin_deg: 170.0,
            gain_margin_db: 6.0,
        };
        let err = tune(&p, targets).unwrap_err();
        let TuneError::Unreachable {
            best_phase_margin_deg: Some(best),
            ..
        } = err
        else {
            panic!("{err}")
        };
        assert!(best < 166.0 && best > 50.0, "{best}");
        assert!(err.to_string().contains("170° "), "{err}");
    }

    #[test]
    fn the_tuned_position_loop_has_no_peak_and_a_higher_gain_would() {
        // Kpp = ω_c/4 keeps the closed position loop at or below 0 dB; 0.7·ω_c
        // (about 1.8 times the largest gain that does) peaks above it.
        for name in ["worm-gear", "two-mass"] {
            let p = presets::load(name).unwrap();
            let t = tune(&p, Targets::default()).unwrap();
            assert!(t.after.position_peak_db <= 1e-6, "{name}: {t:?}");
            let lp = VelocityLoop::new(&p, &t.after.filters).unwrap();
            let pi = VelocityPi {
                kvp: t.after.kvp,
                kvi: t.after.kvi,
            };
            let high = position::peak_db(&lp, pi, 0.7 * 4.0 * t.after.kpp);
            assert!(high > 0.5, "{name}: {high} dB");
        }
    }

    #[test]
    fn targets_out_of_range_are_refused() {
        let p = presets::load("worm-gear").unwrap();
        for (pm, gm) in [(0.0, 6.0), (190.0, 6.0), (50.0, -1.0), (f64::NAN, 6.0)] {
            let t = Targets {
                phase_margin_deg: pm,
                gain_margin_db: gm,
            };
            assert!(matches!(tune(&p, t), Err(TuneError::Targets { .. })));
        }
    }
}
