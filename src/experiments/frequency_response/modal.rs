//! The modal parameters of a complex frequency response: each resonance's undamped
//! frequency and damping ratio, with standard errors, from a rational fit over a band
//! around it ([`crate::estimation::local_mode_fit`]).
//!
//! **Resonances.** The prominent peaks ([`peaks::prominent`], at least
//! [`PROMINENCE_DB`] plus twice the gain's noise at the peak and at its base: the
//! stated noise, or where the file states none the curve's own
//! ([`curve_noise::second_difference`]), so that a noisy curve's ripples are not
//! resonances) of the gain with the
//! integrators removed (|H|·ω^p: p = 0 for the table over the motor, 2 for a
//! compliance, whose 1/ω² slope would otherwise tilt the peaks).
//!
//! **Band.** Two fits. The first over 0.8…1.2× the peak's frequency, as the
//! multisine evaluation fits a lone extremum (docs/multisine.md), cut at the geometric
//! midpoint to a neighbouring resonance so that the band holds one pole pair. The
//! second over ±[`BANDWIDTHS`] half-power widths (2ζ·f) around the first fit's pole,
//! at least [`MIN_SIDE_LINES`] lines a side, inside the first band: a neighbouring
//! mode's tail, which the one-pole-pair model cannot follow, then weighs little (on
//! the worm preset's exact response, 187 and 237 Hz, the first band's ζ of the lower
//! mode is 2.9 % low and its residual 0.06; the second's 2.1 % and 0.015). An
//! antiresonance in the band is the model's zero pair.
//!
//! **Weights and standard errors.** Each line is weighted by its stated relative
//! noise (the root mean square of σ(ln|H|) and σ(phase)), or alike when the file
//! states none. The standard errors scale with the fit's own residual, so they hold
//! without a stated noise level too; `residual_rms` is then the relative misfit per
//! component (≈ the complex noise's σ when the model explains the band), and ≈ 1 when
//! the stated noise is right.
//!
//! A pole pair outside its band, or with a non-finite standard error, is not this
//! resonance's: the mode is reported without it (`pole: None`) and says why.

use rustfft::num_complex::Complex;
use serde::Serialize;

use super::measured::{ComplexPoints, DB_PER_NEPER, PROMINENCE_DB};
use crate::estimation::curve_noise;
use crate::estimation::local_mode_fit::{fit, ModeFitOptions, SecondOrder};
use crate::estimation::peaks::{self, Peak};

/// One resonance of a complex frequency response.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Mode {
    /// The peak of the gain (with the integrators removed), located by the parabola
    /// through its three highest lines.
    pub peak: Peak,
    /// The lines fitted, Hz (inclusive).
    pub band_hz: (f64, f64),
    /// Lines in the band.
    pub lines: usize,
    /// The pole pair: undamped frequency and damping ratio, with standard errors.
    pub pole: Option<SecondOrder>,
    /// The zero pair (antiresonance) the band holds, when the fit finds one in it.
    pub zero: Option<SecondOrder>,
    /// The fit's residual (module docs); NaN where the fit failed.
    pub residual_rms: f64,
    /// Why there is no pole pair, when there is none.
    pub note: Option<String>,
}

/// Relative half-width of the band around a peak.
pub const BAND: f64 = 0.2;

/// The most resonances fitted: a drive shows a few; a curve with more prominent
/// peaks than this is noise-like at its resolution, and its highest are fitted.
pub const MOST_MODES: usize = 12;

/// The modes found, and how many prominent peaks the gain has.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModeSearch {
    /// The modes fitted, ascending in frequency: every prominent peak's, or the
    /// [`MOST_MODES`] highest.
    pub modes: Vec<Mode>,
    /// The gain's prominent peaks: more than [`MOST_MODES`] says the curve is
    /// noise-like, and that the modes are its highest peaks only.
    pub prominent: usize,
}

/// The modes of `points` (any order of lines), `integrators` as in
/// [`ModeFitOptions`]: 0 for an angle over an angle, 2 for an angle over a torque.
/// Ascending in frequency; empty when the gain has no prominent peak.
pub fn modes(points: &ComplexPoints, integrators: u32) -> ModeSearch {
    let mut order: Vec<usize> = (0..points.frequency_hz.len())
        .filter(|&k| {
            points.frequency_hz[k] > 0.0
                && points.ln_gain[k].is_finite()
                && points.phase_rad[k].is_finite()
        })
        .collect();
    order.sort_by(|&a, &b| points.frequency_hz[a].total_cmp(&points.frequency_hz[b]));
    let f: Vec<f64> = order.iter().map(|&k| points.frequency_hz[k]).collect();
    let p = f64::from(integrators);
    let h: Vec<Complex<f64>> = order
        .iter()
        .map(|&k| Complex::from_polar(points.ln_gain[k].exp(), points.phase_rad[k]))
        .collect();
    let sigma: Vec<f64> = match (&points.sigma_ln, &points.sigma_phase) {
        (Some(sl), Some(sp)) => order
            .iter()
            .map(|&k| ((sl[k] * sl[k] + sp[k] * sp[k]) / 2.0).sqrt())
            .collect(),
        (Some(s), None) | (None, Some(s)) => order.iter().map(|&k| s[k]).collect(),
        (None, None) => vec![1.0; order.len()],
    };
    let stated = points.sigma_ln.is_some() || points.sigma_phase.is_some();
    // A line whose stated noise is not a positive number is left out.
    let usable: Vec<usize> = (0..f.len())
        .filter(|&i| sigma[i].is_finite() && sigma[i] > 0.0)
        .collect();
    let pick = |v: &[f64]| usable.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let (f, sigma) = (pick(&f), pick(&sigma));
    let h: Vec<Complex<f64>> = usable.iter().map(|&i| h[i]).collect();
    let curve: Vec<(f64, f64)> = f
        .iter()
        .zip(&h)
        .map(|(&x, g)| {
            let w = std::f64::consts::TAU * x;
            (x, DB_PER_NEPER * (g.norm().ln() + p * w.ln()))
        })
        .collect();
    let sigma_db: Option<Vec<f64>> = if stated {
        Some(sigma.iter().map(|s| DB_PER_NEPER * s).collect())
    } else {
        let gain: Vec<f64> = curve.iter().map(|c| c.1).collect();
        curve_noise::second_difference(&gain).map(|noise| vec![noise; gain.len()])
    };
    let found = peaks::prominent(&curve, sigma_db.as_deref(), PROMINENCE_DB);
    let prominent = found.len();
    let found = peaks::highest(found, MOST_MODES);
    let modes = (0..found.len())
        .map(|k| {
            let centre = found[k].frequency_hz;
            let mut lo = (1.0 - BAND) * centre;
            let mut hi = (1.0 + BAND) * centre;
            if k > 0 {
                lo = lo.max((found[k - 1].frequency_hz * centre).sqrt());
            }
            if k + 1 < found.len() {
                hi = hi.min((found[k + 1].frequency_hz * centre).sqrt());
            }
            let first = one(&f, &h, &sigma, found[k], (lo, hi), integrators);
            narrowed(&f, &h, &sigma, first, integrators)
        })
        .collect();
    ModeSearch { modes, prominent }
}

/// Bandwidths (2ζ·f, the half-power width) on each side of the pole in the second fit.
pub const BANDWIDTHS: f64 = 2.0;

/// Fewest lines on each side of the pole in the second fit.
pub const MIN_SIDE_LINES: usize = 8;

/// The fit again over ±[`BANDWIDTHS`] half-power widths around the first fit's pole,
/// at least [`MIN_SIDE_LINES`] lines on each side, inside the first band; the first
/// fit when that band is no narrower or the second fails.
fn narrowed(f: &[f64], h: &[Complex<f64>], sigma: &[f64], first: Mode, integrators: u32) -> Mode {
    let Some(p) = first.pole else {
        return first;
    };
    let half = BANDWIDTHS * 2.0 * p.damping_ratio * p.frequency_hz;
    let (outer_lo, outer_hi) = first.band_hz;
    // `f` ascends: the sides are slices, found by bisection (a scan of every line
    // per peak made a noisy 400 000-line record take minutes).
    let at = |edge: f64| f.partition_point(|&x| x <= edge);
    let low = f.partition_point(|&x| x < outer_lo).min(at(p.frequency_hz));
    let below = &f[low..at(p.frequency_hz)];
    let above = &f[at(p.frequency_hz)..at(outer_hi).max(at(p.frequency_hz))];
    let mut lo = p.frequency_hz - half;
    let mut hi = p.frequency_hz + half;
    if below.len() > MIN_SIDE_LINES {
        lo = lo.min(below[below.len() - MIN_SIDE_LINES]);
    }
    if above.len() > MIN_SIDE_LINES {
        hi = hi.max(above[MIN_SIDE_LINES - 1]);
    }
    let band = (lo.max(outer_lo), hi.min(outer_hi));
    if band.0 <= outer_lo && band.1 >= outer_hi {
        return first;
    }
    let second = one(f, h, sigma, first.peak, band, integrators);
    if second.pole.is_some() {
        second
    } else {
        first
    }
}

/// The fit around one peak, on the lines of `band` (`f` ascending: a slice, found by
/// bisection, so the work per peak is its band's, not the record's).
fn one(
    f: &[f64],
    h: &[Complex<f64>],
    sigma: &[f64],
    peak: Peak,
    band: (f64, f64),
    integrators: u32,
) -> Mode {
    let start = f.partition_point(|&x| x < band.0);
    // An empty band (its ends crossed: no line) is the fit's to refuse.
    let end = f.partition_point(|&x| x <= band.1).max(start);
    let (f, h, sigma) = (&f[start..end], &h[start..end], &sigma[start..end]);
    let lines = f.len();
    let mut mode = Mode {
        peak,
        band_hz: band,
        lines,
        pole: None,
        zero: None,
        residual_rms: f64::NAN,
        note: None,
    };
    let fitted = match fit(f, h, sigma, &ModeFitOptions::new(band, integrators)) {
        Ok(m) => m,
        Err(e) => {
            mode.note = Some(e.to_string());
            return mode;
        }
    };
    mode.residual_rms = fitted.residual_rms;
    let in_band = |p: &SecondOrder| {
        (band.0..=band.1).contains(&p.frequency_hz)
            && p.frequency_se_hz.is_finite()
            && p.damping_se.is_finite()
    };
    mode.pole = fitted.pole.filter(in_band);
    mode.zero = fitted.zero.filter(in_band);
    if mode.pole.is_none() {
        mode.note = Some(match fitted.pole {
            None => "the fitted pole pair is real (overdamped): no resonance in the band".into(),
            Some(p) => format!(
                "the fitted pole pair ({:.2} Hz) lies outside the band or has no standard error",
                p.frequency_hz
            ),
        });
    }
    mode
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A single mode, table over motor of a two-mass drive: (c·s + k)/(m·s² + c·s + k)
    /// plus a bearing damping: pole ω² = k/m, 2ζω = (c + cb)/m.
    fn response(f: &[f64], seed: u64, percent: f64) -> (ComplexPoints, f64, f64) {
        let (m, k, c, cb): (f64, f64, f64, f64) = (2.0e-4, 23.0, 1.92e-3, 1.0e-4);
        let w0 = (k / m).sqrt();
        let zeta = (c + cb) / m / (2.0 * w0);
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let noise = Normal::new(0.0, percent / 100.0).unwrap();
        let h: Vec<Complex<f64>> = f
            .iter()
            .map(|&x| {
                let s = Complex::new(0.0, std::f64::consts::TAU * x);
                let e = Complex::new(1.0 + noise.sample(&mut rng), noise.sample(&mut rng));
                (c * s + k) / (m * s * s + (c + cb) * s + k) * e
            })
            .collect();
        let points = ComplexPoints {
            frequency_hz: f.to_vec(),
            ln_gain: h.iter().map(|g| g.norm().ln()).collect(),
            phase_rad: h.iter().map(|g| g.arg()).collect(),
            sigma_ln: None,
            sigma_phase: None,
        };
        (points, w0 / std::f64::consts::TAU, zeta)
    }

    #[test]
    fn a_noisy_single_mode_gives_back_its_frequency_and_damping_within_three_se() {
        let f: Vec<f64> = (20..=300).map(|i| f64::from(i) * 0.5).collect();
        for seed in 0..5 {
            let (points, f0, zeta) = response(&f, seed, 1.0);
            let found = modes(&points, 0).modes;
            assert_eq!(found.len(), 1, "{found:?}");
            let m = &found[0];
            let pole = m.pole.expect("a pole pair");
            assert!(
                (pole.frequency_hz - f0).abs() < 3.0 * pole.frequency_se_hz,
                "seed {seed}: {pole:?} against {f0} Hz"
            );
            assert!(
                (pole.damping_ratio - zeta).abs() < 3.0 * pole.damping_se,
                "seed {seed}: {pole:?} against ζ = {zeta}"
            );
            // Small standard errors: 1 % noise on ~45 lines.
            assert!(
                pole.frequency_se_hz < 0.05 && pole.damping_se < 1e-3,
                "{m:?}"
            );
            // The band: ±2 half-power widths (±3.2 Hz), widened to 8 lines a side.
            assert!(
                m.band_hz.1 - m.band_hz.0 < 9.0 && (15..=18).contains(&m.lines),
                "{m:?}"
            );
            // No stated noise: the residual is the relative misfit, the 1 % noise.
            assert!((0.007..0.013).contains(&m.residual_rms), "{m:?}");
        }
    }

    #[test]
    fn the_stated_noise_weights_the_lines_and_scales_the_residual() {
        let f: Vec<f64> = (20..=300).map(|i| f64::from(i) * 0.5).collect();
        let (mut points, f0, _) = response(&f, 7, 2.0);
        points.sigma_ln = Some(vec![0.02; f.len()]);
        points.sigma_phase = Some(vec![0.02; f.len()]);
        let m = &modes(&points, 0).modes[0];
        let pole = m.pole.unwrap();
        assert!((pole.frequency_hz - f0).abs() < 3.0 * pole.frequency_se_hz);
        assert!((0.7..1.3).contains(&m.residual_rms), "{m:?}");
    }

    #[test]
    fn an_exact_response_is_exact_and_a_flat_one_has_no_mode() {
        let f: Vec<f64> = (20..=300).map(|i| f64::from(i) * 0.5).collect();
        let (points, f0, zeta) = response(&f, 0, 0.0);
        let pole = modes(&points, 0).modes[0].pole.unwrap();
        assert!((pole.frequency_hz - f0).abs() < 1e-6 * f0, "{pole:?}");
        assert!((pole.damping_ratio - zeta).abs() < 1e-6 * zeta, "{pole:?}");
        let flat = ComplexPoints {
            ln_gain: vec![0.0; f.len()],
            phase_rad: vec![0.0; f.len()],
            frequency_hz: f,
            sigma_ln: None,
            sigma_phase: None,
        };
        assert!(modes(&flat, 0).modes.is_empty());
    }

    /// The exact damped poles of the worm-gear preset's motor-held model (the
    /// eigenvalues λ of its state matrix: ω = |λ|, ζ = −Re λ/|λ|), ascending.
    fn motor_held_poles(name: &str) -> Vec<(f64, f64)> {
        let p = crate::model::presets::load(name).unwrap();
        let held = crate::model::modes::LinearModel::new(&p)
            .unwrap()
            .motor_held();
        let mut poles: Vec<(f64, f64)> = held
            .state_matrix()
            .complex_eigenvalues()
            .iter()
            .filter(|l| l.im > 0.0)
            .map(|l| (l.norm() / std::f64::consts::TAU, -l.re / l.norm()))
            .collect();
        poles.sort_by(|a, b| a.0.total_cmp(&b.0));
        poles
    }

    /// Close modes (worm: 187 and 237 Hz; a band around one holds the other's tail)
    /// and a very light one (roller: ζ = 7e-5, half-power width 0.024 Hz on a 1 Hz
    /// grid): the modes of the presets' exact linear responses against the damped
    /// poles of their motor-held models.
    #[test]
    fn the_presets_linear_responses_give_their_damped_motor_held_poles() {
        use crate::model::linear_response::{Channel, LinearResponse};
        // (preset, relative tolerance of f, of ζ)
        for (name, tol_f, tol_z) in [("worm-gear", 3e-3, 0.05), ("roller-gear-cam", 1e-6, 1e-3)] {
            let p = crate::model::presets::load(name).unwrap();
            let r = LinearResponse::new(&p, Channel::TableOverMotor).unwrap();
            let f: Vec<f64> = (5..=2000).map(f64::from).collect();
            let h: Vec<Complex<f64>> = f.iter().map(|&x| r.at(x).unwrap()).collect();
            let points = ComplexPoints {
                frequency_hz: f.clone(),
                ln_gain: h.iter().map(|g| g.norm().ln()).collect(),
                phase_rad: h.iter().map(|g| g.arg()).collect(),
                sigma_ln: None,
                sigma_phase: None,
            };
            let exact = motor_held_poles(name);
            let found = modes(&points, 0).modes;
            assert_eq!(found.len(), exact.len(), "{name}: {found:?}");
            for (m, &(f0, zeta)) in found.iter().zip(&exact) {
                let pole = m.pole.unwrap();
                assert!(
                    (pole.frequency_hz / f0 - 1.0).abs() < tol_f
                        && (pole.damping_ratio / zeta - 1.0).abs() < tol_z,
                    "{name}: {m:?} against {f0} Hz, ζ = {zeta}"
                );
            }
        }
    }
}
