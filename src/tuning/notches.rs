//! Notch filters at the drive's resonances that the velocity loop would excite
//! (docs/tuning.md): the motor-free natural frequencies of the linear model — the
//! resonances of the compliance θm/T the velocity loop acts on — below the Nyquist
//! frequency, the lowest [`MAX_FILTERS`].
//!
//! Each mode's damping ratio ζ comes from the eigenvalue λ of the damped first-order
//! system nearest its undamped frequency, ζ = −Re λ/|λ|. The notch sits at the
//! undamped frequency with the depth [`DEPTH_DB`] and the width
//! max(4·ζ·f, [`MIN_RELATIVE_WIDTH`]·f): twice the resonance's half-power bandwidth
//! 2ζ·f, and never narrower than a fifth of its frequency, so that a resonance
//! identified a few per cent off still falls inside.

use std::f64::consts::TAU;

use crate::model::modes::{modes, LinearModel, SCHUR_ITERATIONS};
use crate::model::{ParamError, Params, SetpointFilter, MAX_FILTERS};

/// The notches' gain at their centre, dB.
pub const DEPTH_DB: f64 = -20.0;
/// The narrowest notch, as a fraction of its centre frequency.
pub const MIN_RELATIVE_WIDTH: f64 = 0.2;
/// The highest notch centre, as a fraction of the Nyquist frequency: the Tustin
/// notch is squeezed against Nyquist above it.
pub const MAX_RELATIVE_CENTRE: f64 = 0.8;

/// One resonance of the compliance: its undamped frequency, Hz, and damping ratio.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Resonance {
    pub hz: f64,
    pub damping: f64,
}

/// The resonances of `p`'s compliance θm/T below `max_hz`, ascending.
pub fn resonances(p: &Params, max_hz: f64) -> Result<Vec<Resonance>, ParamError> {
    let free = modes(p)?.free_hz;
    let s = LinearModel::new(p)?.state_matrix();
    let eigen: Vec<(f64, f64)> = match s.try_schur(f64::EPSILON, SCHUR_ITERATIONS) {
        Some(schur) => schur
            .complex_eigenvalues()
            .iter()
            .filter(|l| l.im > 0.0)
            .map(|l| (l.norm() / TAU, -l.re / l.norm()))
            .collect(),
        None => Vec::new(),
    };
    Ok(free
        .into_iter()
        .filter(|&hz| hz > 0.0 && hz < max_hz)
        .map(|hz| {
            let damping = eigen
                .iter()
                .min_by(|a, b| (a.0 - hz).abs().total_cmp(&(b.0 - hz).abs()))
                .map_or(0.0, |e| e.1);
            Resonance { hz, damping }
        })
        .collect())
}

/// A notch at each resonance below [`MAX_RELATIVE_CENTRE`]·Nyquist, the lowest
/// [`MAX_FILTERS`].
pub fn notches(p: &Params) -> Result<Vec<SetpointFilter>, ParamError> {
    notches_with(p, &super::Limits::default())
}

/// [`notches`] with the depth and narrowest width of `limits`.
pub fn notches_with(p: &Params, limits: &super::Limits) -> Result<Vec<SetpointFilter>, ParamError> {
    let nyquist = 0.5 / p.controller.tc;
    Ok(resonances(p, MAX_RELATIVE_CENTRE * nyquist)?
        .into_iter()
        .take(MAX_FILTERS)
        .map(|r| notch_with(r, limits.notch_depth_db, limits.notch_min_width))
        .collect())
}

/// [`notches_with`] for every machine of `machines` (the nominal first): each notch
/// at the geometric middle of where its resonance lies over the machines (the
/// nearest to the nominal one's frequency at each), widened by that span, at most as
/// wide as its centre. On the nominal machine alone, [`notches_with`].
pub fn notches_over(
    p: &Params,
    limits: &super::Limits,
    machines: &[Params],
) -> Result<Vec<SetpointFilter>, ParamError> {
    let nyquist = 0.5 / p.controller.tc;
    let max_hz = MAX_RELATIVE_CENTRE * nyquist;
    let nominal = resonances(p, max_hz)?;
    let others = machines
        .iter()
        .map(|q| resonances(q, nyquist))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(nominal
        .into_iter()
        .take(MAX_FILTERS)
        .map(|r| {
            let (lo, hi) = others
                .iter()
                .filter_map(|rs| {
                    rs.iter().min_by(|a, b| {
                        (a.hz / r.hz)
                            .ln()
                            .abs()
                            .total_cmp(&(b.hz / r.hz).ln().abs())
                    })
                })
                .fold((r.hz, r.hz), |(lo, hi), x| (lo.min(x.hz), hi.max(x.hz)));
            let centre = Resonance {
                hz: (lo * hi).sqrt().min(max_hz),
                damping: r.damping,
            };
            match notch_with(centre, limits.notch_depth_db, limits.notch_min_width) {
                SetpointFilter::Notch {
                    centre_hz,
                    width_hz,
                    depth_db,
                } => SetpointFilter::Notch {
                    centre_hz,
                    width_hz: (width_hz + hi - lo).min(centre_hz),
                    depth_db,
                },
                other => other,
            }
        })
        .collect())
}

/// The notch of one resonance.
pub fn notch(r: Resonance) -> SetpointFilter {
    notch_with(r, DEPTH_DB, MIN_RELATIVE_WIDTH)
}

/// The notch of one resonance with `depth_db` and at least `min_width` of its centre.
fn notch_with(r: Resonance, depth_db: f64, min_width: f64) -> SetpointFilter {
    SetpointFilter::Notch {
        centre_hz: r.hz,
        width_hz: (4.0 * r.damping * r.hz).max(min_width * r.hz),
        depth_db: Some(depth_db),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn the_two_mass_drive_gets_one_notch_at_its_coupling_mode() {
        let p = presets::load("two-mass").unwrap();
        let r = resonances(&p, 1250.0).unwrap();
        // The preset's notes: motor-free mode 76.3 Hz, damping ratio 0.02.
        assert_eq!(r.len(), 1, "{r:?}");
        assert!((r[0].hz - 76.3).abs() < 0.1, "{r:?}");
        assert!((r[0].damping - 0.02).abs() < 2e-3, "{r:?}");
        let f = notches(&p).unwrap();
        assert_eq!(f.len(), 1);
    }

    /// The two-mass drive with Jt from half to twice its value: the coupling mode
    /// moves from 108 to 60 Hz (√(Kw(1/Jm + 1/Jt))), and the notch covers it.
    #[test]
    fn a_notch_over_a_range_covers_where_its_resonance_goes() {
        let p = presets::load("two-mass").unwrap();
        let machines: Vec<Params> = [0.5, 2.0]
            .iter()
            .map(|k| Params {
                jt: k * p.jt,
                ..p.clone()
            })
            .collect();
        let f = notches_over(&p, &crate::tuning::Limits::default(), &machines).unwrap();
        let SetpointFilter::Notch {
            centre_hz,
            width_hz,
            ..
        } = f[0]
        else {
            panic!("{f:?}")
        };
        let mode = |jt: f64| (p.kw * (1.0 / p.jm + 1.0 / jt)).sqrt() / TAU;
        let (lo, hi) = (mode(2.0 * p.jt), mode(0.5 * p.jt));
        assert!((centre_hz - (lo * hi).sqrt()).abs() < 0.1, "{f:?}");
        assert!(
            centre_hz - width_hz / 2.0 < lo && centre_hz + width_hz / 2.0 > hi,
            "{f:?}"
        );
    }

    #[test]
    fn a_direct_drive_has_no_resonance_to_notch() {
        let p = presets::load("direct-drive").unwrap();
        assert!(notches(&p).unwrap().is_empty());
    }
}
