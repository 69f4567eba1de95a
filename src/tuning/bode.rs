//! A [`Setting`]'s open loops as a Bode plot draws them — the velocity loop alone
//! ([`bode`]) and the cascade as it runs ([`cascade`]): gain in dB and phase in
//! degrees (unwrapped along the grid) on a log grid from [`LOWEST_HZ`] to
//! 0.99·Nyquist, with the points where the margins are read.

use super::margins::{log_grid, unwrapped_deg};
use super::open_loop::{VelocityLoop, VelocityPi};
use super::Setting;
use crate::model::{ParamError, Params};

/// The lowest frequency drawn, Hz (that of the margins' grid).
pub const LOWEST_HZ: f64 = 0.1;
/// Points of the grid.
const POINTS: usize = 800;

/// A setting's open loop on the grid, and its margins' points.
#[derive(Clone, Debug, PartialEq)]
pub struct Bode {
    /// (Hz, |L| dB).
    pub gain_db: Vec<(f64, f64)>,
    /// (Hz, arg L deg, unwrapped).
    pub phase_deg: Vec<(f64, f64)>,
    /// Where the phase margin is read: (Hz, the phase there, deg; the margin, deg);
    /// |L| = 0 dB.
    pub phase_margin: Option<(f64, f64, f64)>,
    /// Where the gain margin is read: (Hz, |L| dB there, the phase there, deg).
    pub gain_margin: Option<(f64, f64, f64)>,
}

/// The open loop of `s` on the drive `p` (its plant, sampling and delays).
pub fn bode(p: &Params, s: &Setting) -> Result<Bode, ParamError> {
    let lp = VelocityLoop::new(p, &s.filters)?;
    let pi = VelocityPi {
        kvp: s.kvp,
        kvi: s.kvi,
    };
    let values = on_grid(lp.nyquist_hz(), |f| lp.at(pi, f));
    Ok(drawn(&values, unwrapped_deg(&values), &s.velocity_loop))
}

/// The cascade as it runs of `s` on the drive `p` (`s.filters` and gains in `p`'s
/// controller, its loop type), exact on the sampled loop ([`super::sampled`]), on the
/// same grid, its phase unwrapped from the branch of its low-frequency asymptote
/// (−270°: three integrators), the margins of `s.cascade` marked.
pub fn cascade(p: &Params, s: &Setting) -> Result<Bode, ParamError> {
    let plant = super::sampled::DiscretePlant::new(p)?;
    let c = s.controller(&p.controller);
    let l = super::sampled::SampledLoop::new(&plant, &c, super::sampled::Closure::Cascade);
    let values = on_grid(l.nyquist_hz(), |f| l.at(f));
    let mut phase = unwrapped_deg(&values);
    if phase.first().is_some_and(|&a| a > 0.0) {
        phase.iter_mut().for_each(|a| *a -= 360.0);
    }
    Ok(drawn(&values, phase, &s.cascade.margins))
}

/// The closed loops of `s` on the drive `p` on the same grid
/// ([`super::closed_loop::curves`]).
pub fn closed(p: &Params, s: &Setting) -> Result<super::closed_loop::Curves, ParamError> {
    let plant = super::sampled::DiscretePlant::new(p)?;
    let c = s.controller(&p.controller);
    Ok(super::closed_loop::curves(&plant, &c, LOWEST_HZ, POINTS))
}

/// A loop's values on the drawn grid up to 0.99·`nyquist_hz`.
fn on_grid(
    nyquist_hz: f64,
    l: impl Fn(f64) -> Option<nalgebra::Complex<f64>>,
) -> Vec<(f64, nalgebra::Complex<f64>)> {
    log_grid(LOWEST_HZ, 0.99 * nyquist_hz, POINTS)
        .into_iter()
        .filter_map(|f| l(f).map(|v| (f, v)))
        .collect()
}

/// The curves of `values` with their phase `phase` (deg, one per value), the margins
/// `m` marked on them.
fn drawn(values: &[(f64, nalgebra::Complex<f64>)], phase: Vec<f64>, m: &super::Margins) -> Bode {
    let phase_deg: Vec<(f64, f64)> = values.iter().map(|v| v.0).zip(phase).collect();
    let gain_db = values
        .iter()
        .map(|(f, v)| (*f, 20.0 * v.norm().log10()))
        .collect();
    let phase_margin = m
        .phase_margin_hz
        .zip(m.phase_margin_deg)
        .map(|(f, pm)| (f, interpolate(&phase_deg, f), pm));
    let gain_margin = m
        .gain_margin_hz
        .zip(m.gain_margin_db)
        .map(|(f, gm)| (f, -gm, interpolate(&phase_deg, f)));
    Bode {
        gain_db,
        phase_deg,
        phase_margin,
        gain_margin,
    }
}

/// `curve` (ascending in x) at `x`, linear in log x between its points; its end
/// values beyond them.
fn interpolate(curve: &[(f64, f64)], x: f64) -> f64 {
    let k = curve.partition_point(|p| p.0 < x);
    match (curve.get(k.wrapping_sub(1)), curve.get(k)) {
        (Some(a), Some(b)) if b.0 > a.0 => {
            let t = (x / a.0).ln() / (b.0 / a.0).ln();
            a.1 + t * (b.1 - a.1)
        }
        (_, Some(b)) => b.1,
        (Some(a), None) => a.1,
        (None, None) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use crate::tuning::{rule, Setting, Targets};

    /// The tuned worm-gear loop: its gain is 0 dB and its phase −180° + the phase
    /// margin where the margin is read; the gain margin's point lies at −180°.
    #[test]
    fn the_margins_points_lie_on_the_curves() {
        let p = presets::load("worm-gear").unwrap();
        let after = Setting::of(&p, &rule(&p, Targets::default()).unwrap()).unwrap();
        let b = bode(&p, &after).unwrap();
        let (f, phase, pm) = b.phase_margin.unwrap();
        assert_eq!(Some(pm), after.velocity_loop.phase_margin_deg);
        assert!((180.0 - phase.abs() - pm).abs() < 0.5, "{phase} vs {pm}");
        assert!(interpolate(&b.gain_db, f).abs() < 0.1);
        if let Some((_, db, phase)) = b.gain_margin {
            assert!((phase.rem_euclid(360.0) - 180.0).abs() < 1.0, "{phase}");
            assert!(db < 0.0);
        }
        assert_eq!(b.gain_db.len(), POINTS);
        assert!((b.gain_db[0].0 - LOWEST_HZ).abs() < 1e-12);
    }
}
