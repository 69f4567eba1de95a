//! The natural frequency and damping ratio of a resonance (pole pair) and an
//! antiresonance (zero pair) from a measured frequency response, by a rational fit
//! over a band around them.
//!
//! Why not the extremum of the gain. A lightly damped mode sampled at lines 1 Hz
//! apart has only two or three lines on its peak, and on a real drive those are the
//! lines a nonlinearity disturbs most (friction when the motor stands almost still at
//! its antiresonance): on the two-mass bench record the extremum of the gain
//! ([`super::extrema`]) lies 0.3–0.5 Hz from the pole and zero that the flanks of
//! the same curve determine. A fit uses every line of the band, magnitude and phase.
//!
//! Model, in s = jω/ω_ref (ω_ref the band's geometric centre, for conditioning), of
//! the response times s^p (p integrators removed: 2 for an angle over a torque or a
//! current, 0 for an angle over an angle):
//!
//! ```text
//! H(s)·s^p ≈ (n₂·s² + n₁·s + n₀) / (s² + d₁·s + d₀)
//! ```
//!
//! fitted by the Sanathanan–Koerner iteration (C. K. Sanathanan, J. Koerner,
//! "Transfer function synthesis as a ratio of two complex polynomials", IEEE Trans.
//! Automatic Control 8(1), 56–58, 1963) of Levy's linearised least squares (E. C. Levy,
//! "Complex-curve fitting", IRE Trans. Automatic Control AC-4(1), 37–43, 1959): each
//! step minimises Σ |N(s_k) − G_k·D(s_k)|² / (|D_prev(s_k)|²·σ_k²), σ_k the standard
//! deviation of G_k, which at convergence is the weighted output error Σ |N/D − G|²/σ².
//! The pole pair gives ω = √d₀·ω_ref, ζ = d₁/(2√d₀); the zero pair ω = √(n₀/n₂)·ω_ref,
//! ζ = n₁/(2·n₂·√(n₀/n₂)) — undamped frequencies, the quantities of the two-mass
//! formulas ([`super::two_mass_ratios`]). A pair that comes out real (overdamped) or
//! absent (n₂ ≈ 0: the load over the motor has no zero pair) is `None`.

use nalgebra::{DMatrix, DVector};
use rustfft::num_complex::Complex;
use serde::Serialize;

/// Settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeFitOptions {
    /// The lines fitted, Hz (inclusive).
    pub band_hz: (f64, f64),
    /// p: integrators removed before the fit (module docs).
    pub integrators: u32,
    /// Most Sanathanan–Koerner iterations (default 50; the first is Levy's fit).
    pub iterations: usize,
}

impl ModeFitOptions {
    /// `band_hz`, `integrators`, 50 iterations.
    pub fn new(band_hz: (f64, f64), integrators: u32) -> Self {
        ModeFitOptions {
            band_hz,
            integrators,
            iterations: 50,
        }
    }
}

/// A pole pair or a zero pair, with standard errors from the fit's residual (the
/// covariance s²·(JᵀJ)⁻¹ of the weighted least squares at convergence, J the weighted
/// design matrix, s² the residual variance; first-order propagation to ω and ζ).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SecondOrder {
    /// Undamped natural frequency, Hz.
    pub frequency_hz: f64,
    pub frequency_se_hz: f64,
    /// Damping ratio ζ.
    pub damping_ratio: f64,
    pub damping_se: f64,
}

/// The fit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ModeFit {
    /// The resonance.
    pub pole: Option<SecondOrder>,
    /// The antiresonance.
    pub zero: Option<SecondOrder>,
    /// Lines fitted.
    pub lines: usize,
    /// √(Σ|N/D − G|²/σ² / (2·lines − 5)): ≈ 1 when the model explains the band within
    /// the stated σ, larger when it does not (more modes, nonlinearity, σ too small).
    pub residual_rms: f64,
    /// Iterations made.
    pub iterations: usize,
}

/// Why the fit cannot be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModeFitError {
    #[error("freq_hz, h and sigma_rel have {freq}, {h} and {sigma} points: they must be as long")]
    Lengths { freq: usize, h: usize, sigma: usize },
    #[error("{field}[{index}] is not a finite number (sigma_rel: and positive)")]
    BadValue { field: &'static str, index: usize },
    #[error("band_hz = ({0}, {1}) must be 0 < from < to")]
    Band(f64, f64),
    #[error("the band holds {lines} lines: at least 5 are needed for 5 coefficients")]
    TooFewLines { lines: usize },
    #[error("the least-squares problem is singular in the band: the lines do not determine a second-order model")]
    Singular,
}

/// Fits the pole and zero pairs of `h` (at `freq_hz`, with relative standard deviation
/// `sigma_rel` of each |H|, e.g. `noise_sigma_rel`) over `opts.band_hz` (module docs).
pub fn fit(
    freq_hz: &[f64],
    h: &[Complex<f64>],
    sigma_rel: &[f64],
    opts: &ModeFitOptions,
) -> Result<ModeFit, ModeFitError> {
    let band = lines_in_band(freq_hz, h, sigma_rel, opts)?;
    let (lo, hi) = opts.band_hz;
    let w_ref = std::f64::consts::TAU * (lo * hi).sqrt();
    let points: Vec<(Complex<f64>, Complex<f64>, f64)> = band
        .map(|i| {
            let s = Complex::new(0.0, std::f64::consts::TAU * freq_hz[i] / w_ref);
            let g = h[i] * s.powu(opts.integrators);
            (s, g, sigma_rel[i] * g.norm())
        })
        .collect();
    let mut theta = [0.0; 5];
    let mut iterations = 0;
    for _ in 0..opts.iterations.max(1) {
        let next = weighted_step(&points, &theta, iterations == 0)?;
        iterations += 1;
        let change = next
            .iter()
            .zip(&theta)
            .map(|(a, b)| (a - b).abs() / a.abs().max(1e-12));
        let converged = change.fold(0.0, f64::max) < 1e-10;
        theta = next;
        if converged {
            break;
        }
    }
    Ok(summarise(&points, &theta, w_ref, iterations))
}

fn lines_in_band<'a>(
    f: &'a [f64],
    h: &[Complex<f64>],
    s: &[f64],
    opts: &ModeFitOptions,
) -> Result<impl Iterator<Item = usize> + 'a, ModeFitError> {
    if f.len() != h.len() || f.len() != s.len() {
        let (freq, h, sigma) = (f.len(), h.len(), s.len());
        return Err(ModeFitError::Lengths { freq, h, sigma });
    }
    let bad = |field, index| Err(ModeFitError::BadValue { field, index });
    if let Some(i) = f.iter().position(|v| !v.is_finite()) {
        return bad("freq_hz", i);
    }
    if let Some(i) = h
        .iter()
        .position(|v| !(v.re.is_finite() && v.im.is_finite()))
    {
        return bad("h", i);
    }
    if let Some(i) = s.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
        return bad("sigma_rel", i);
    }
    let (lo, hi) = opts.band_hz;
    if !(lo > 0.0 && lo < hi && hi.is_finite()) {
        return Err(ModeFitError::Band(lo, hi));
    }
    let lines = f.iter().filter(|&&v| v >= lo && v <= hi).count();
    if lines < 5 {
        return Err(ModeFitError::TooFewLines { lines });
    }
    Ok((0..f.len()).filter(move |&i| f[i] >= lo && f[i] <= hi))
}

/// One Sanathanan–Koerner step: θ = (n₂, n₁, n₀, d₁, d₀) minimising
/// Σ |N − G·D|²/(|D_prev|²·σ²); the first step (`levy`) without D_prev.
fn weighted_step(
    points: &[(Complex<f64>, Complex<f64>, f64)],
    prev: &[f64; 5],
    levy: bool,
) -> Result<[f64; 5], ModeFitError> {
    let (a, b) = design(points, prev, levy);
    let x = a
        .svd(true, true)
        .solve(&b, 1e-12)
        .map_err(|_| ModeFitError::Singular)?;
    if x.iter().any(|v| !v.is_finite()) {
        return Err(ModeFitError::Singular);
    }
    Ok([x[0], x[1], x[2], x[3], x[4]])
}

/// The weighted linear system of one step, real and imaginary parts stacked:
/// N(s) − G·(d₁·s + d₀) = G·s², each line divided by |D_prev(s)|·σ.
fn design(
    points: &[(Complex<f64>, Complex<f64>, f64)],
    prev: &[f64; 5],
    levy: bool,
) -> (DMatrix<f64>, DVector<f64>) {
    let mut a = DMatrix::<f64>::zeros(2 * points.len(), 5);
    let mut b = DVector::<f64>::zeros(2 * points.len());
    for (k, &(s, g, sigma)) in points.iter().enumerate() {
        let d_prev = if levy {
            Complex::new(1.0, 0.0)
        } else {
            s * s + prev[3] * s + prev[4]
        };
        let weight = 1.0 / (d_prev.norm() * sigma);
        let row = [s * s, s, Complex::new(1.0, 0.0), -g * s, -g];
        for (j, c) in row.iter().enumerate() {
            a[(2 * k, j)] = c.re * weight;
            a[(2 * k + 1, j)] = c.im * weight;
        }
        let rhs = g * s * s * weight;
        (b[2 * k], b[2 * k + 1]) = (rhs.re, rhs.im);
    }
    (a, b)
}

fn summarise(
    points: &[(Complex<f64>, Complex<f64>, f64)],
    theta: &[f64; 5],
    w_ref: f64,
    iterations: usize,
) -> ModeFit {
    let [n2, n1, n0, d1, d0] = *theta;
    let chi2: f64 = points
        .iter()
        .map(|&(s, g, sigma)| {
            let model = (n2 * s * s + n1 * s + n0) / (s * s + d1 * s + d0);
            (model - g).norm_sqr() / (sigma * sigma)
        })
        .sum();
    let dof = (2 * points.len()).saturating_sub(5).max(1) as f64;
    // Covariance of θ: s²·(JᵀJ)⁻¹, J the converged step's matrix (at a good fit the
    // Jacobian of the output error N/D − G, weighted).
    let (j, _) = design(points, theta, false);
    let cov = (j.transpose() * &j)
        .try_inverse()
        .map(|m| m * (chi2 / dof))
        .unwrap_or_else(|| DMatrix::from_element(5, 5, f64::NAN));
    let pole = pair(1.0, d1, d0, w_ref).map(|p| {
        let w = d0.sqrt();
        let gf = [0.0, 0.0, 0.0, 0.0, p.frequency_hz / (2.0 * d0)];
        let gz = [0.0, 0.0, 0.0, 0.5 / w, -d1 / (4.0 * d0 * w)];
        SecondOrder {
            frequency_se_hz: se(&cov, &gf),
            damping_se: se(&cov, &gz),
            ..p
        }
    });
    let zero = pair(n2, n1, n0, w_ref).map(|z| {
        let (f, zeta) = (z.frequency_hz, z.damping_ratio);
        let gf = [-f / (2.0 * n2), 0.0, f / (2.0 * n0), 0.0, 0.0];
        let gz = [
            -zeta / (2.0 * n2),
            0.5 / (n0 * n2).sqrt(),
            -zeta / (2.0 * n0),
            0.0,
            0.0,
        ];
        SecondOrder {
            frequency_se_hz: se(&cov, &gf),
            damping_se: se(&cov, &gz),
            ..z
        }
    });
    ModeFit {
        pole,
        zero,
        lines: points.len(),
        residual_rms: (chi2 / dof).sqrt(),
        iterations,
    }
}

/// √(gᵀ·C·g); NaN where C is.
fn se(cov: &DMatrix<f64>, g: &[f64; 5]) -> f64 {
    let g = DVector::from_column_slice(g);
    (g.transpose() * cov * &g)[(0, 0)].max(0.0).sqrt()
}

/// The complex root pair of a·s² + b·s + c, as frequency (× `w_ref`) and damping,
/// standard errors not yet known (zero).
fn pair(a: f64, b: f64, c: f64, w_ref: f64) -> Option<SecondOrder> {
    // Complex roots iff b² < 4ac, which also makes c/a positive.
    let discriminant = b * b - 4.0 * a * c;
    if discriminant.is_nan() || discriminant >= 0.0 {
        return None;
    }
    let w = (c / a).sqrt();
    Some(SecondOrder {
        frequency_hz: w * w_ref / std::f64::consts::TAU,
        frequency_se_hz: 0.0,
        damping_ratio: b / a / (2.0 * w),
        damping_se: 0.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// Motor angle over torque of a two-mass drive (docs/model.md §1): zero pair at
    /// √(k/Jl), pole pair at √(k(1/Jm + 1/Jl)), both lightly damped.
    fn motor(f: f64) -> Complex<f64> {
        let (jm, jl, k, c) = (1.1e-3, 1.0e-3, 115.0, 0.012);
        let s = Complex::new(0.0, std::f64::consts::TAU * f);
        (jl * s * s + c * s + k) / (s * s * (jm * jl * s * s + c * (jm + jl) * s + k * (jm + jl)))
    }

    #[test]
    fn a_two_mass_motor_response_gives_back_its_pole_and_zero() {
        let (jm, jl, k, c) = (1.1e-3f64, 1.0e-3f64, 115.0f64, 0.012f64);
        let fa = (k / jl).sqrt() / std::f64::consts::TAU;
        let fr = (k * (1.0 / jm + 1.0 / jl)).sqrt() / std::f64::consts::TAU;
        let za = c / (2.0 * (k * jl).sqrt());
        let f: Vec<f64> = (11..=250).map(f64::from).collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(2);
        let noise = Normal::new(0.0, 0.01).unwrap();
        // 1 % complex noise on every line, σ stated as such.
        let h: Vec<Complex<f64>> = f
            .iter()
            .map(|&x| motor(x) * Complex::new(1.0 + noise.sample(&mut rng), noise.sample(&mut rng)))
            .collect();
        let sigma = vec![0.01; f.len()];
        let m = fit(&f, &h, &sigma, &ModeFitOptions::new((40.0, 90.0), 2)).unwrap();
        let (pole, zero) = (m.pole.unwrap(), m.zero.unwrap());
        // Within 3 standard errors, which are small (1 % noise, 51 lines).
        assert!(
            (zero.frequency_hz - fa).abs() < 3.0 * zero.frequency_se_hz,
            "{zero:?} vs {fa}"
        );
        assert!(
            (pole.frequency_hz - fr).abs() < 3.0 * pole.frequency_se_hz,
            "{pole:?} vs {fr}"
        );
        assert!(
            (zero.damping_ratio - za).abs() < 3.0 * zero.damping_se,
            "{zero:?} vs {za}"
        );
        assert!(
            zero.frequency_se_hz < 0.05 && pole.frequency_se_hz < 0.05,
            "{m:?}"
        );
        // The model is exact: the residual is the noise.
        assert!((0.7..1.3).contains(&m.residual_rms), "{m:?}");
        // The load over the motor has a pole pair and no zero pair.
        let ratio: Vec<Complex<f64>> = f
            .iter()
            .map(|&x| {
                let s = Complex::new(0.0, std::f64::consts::TAU * x);
                (c * s + k) / (jl * s * s + c * s + k)
            })
            .collect();
        let m = fit(&f, &ratio, &sigma, &ModeFitOptions::new((30.0, 80.0), 0)).unwrap();
        assert!((m.pole.unwrap().frequency_hz - fa).abs() < 1e-6, "{m:?}");
        assert!(m.zero.is_none(), "{m:?}");
    }

    #[test]
    fn the_standard_errors_are_calibrated() {
        let (jm, jl, k) = (1.1e-3f64, 1.0e-3f64, 115.0f64);
        let fa = (k / jl).sqrt() / std::f64::consts::TAU;
        let fr = (k * (1.0 / jm + 1.0 / jl)).sqrt() / std::f64::consts::TAU;
        let f: Vec<f64> = (11..=250).map(f64::from).collect();
        let noise = Normal::new(0.0, 0.02).unwrap();
        let sigma = vec![0.02; f.len()];
        let (mut z2, runs) = ([0.0; 2], 200);
        for seed in 0..runs {
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let h: Vec<Complex<f64>> = f
                .iter()
                .map(|&x| {
                    motor(x) * Complex::new(1.0 + noise.sample(&mut rng), noise.sample(&mut rng))
                })
                .collect();
            let m = fit(&f, &h, &sigma, &ModeFitOptions::new((40.0, 90.0), 2)).unwrap();
            let (p, z) = (m.pole.unwrap(), m.zero.unwrap());
            z2[0] += ((p.frequency_hz - fr) / p.frequency_se_hz).powi(2) / runs as f64;
            z2[1] += ((z.frequency_hz - fa) / z.frequency_se_hz).powi(2) / runs as f64;
        }
        // Mean square of the normalised errors ≈ 1 (± 0.1 for 200 runs).
        assert!(z2.iter().all(|v| (0.75..1.3).contains(v)), "{z2:?}");
    }

    #[test]
    fn bad_input_is_a_typed_error() {
        let f = [10.0, 11.0, 12.0, 13.0, 14.0, 15.0];
        let h = [Complex::new(1.0, 0.0); 6];
        let s = [0.01; 6];
        let o = ModeFitOptions::new((10.0, 15.0), 0);
        assert!(matches!(
            fit(&f, &h[..5], &s, &o),
            Err(ModeFitError::Lengths { .. })
        ));
        let bad = [0.01, 0.01, 0.0, 0.01, 0.01, 0.01];
        assert!(matches!(
            fit(&f, &h, &bad, &o),
            Err(ModeFitError::BadValue {
                field: "sigma_rel",
                index: 2
            })
        ));
        let narrow = ModeFitOptions::new((10.0, 12.0), 0);
        assert!(matches!(
            fit(&f, &h, &s, &narrow),
            Err(ModeFitError::TooFewLines { lines: 3 })
        ));
        let inverted = ModeFitOptions::new((15.0, 10.0), 0);
        assert!(matches!(
            fit(&f, &h, &s, &inverted),
            Err(ModeFitError::Band(..))
        ));
    }
}
