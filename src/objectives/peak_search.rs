//! Where the model's resonances are: peaks of its gain curve, either of the exact
//! linear response (grid scan + golden-section refinement on the smooth curve) or of
//! the nonlinear virtual test (a short scan of time simulations around the linear
//! prediction + two parabolic refinements).
//!
//! The nonlinear search costs 9 simulations per peak (more if the peak lies outside
//! the first scan); the linear one a few hundred 4×4 complex solves.

use nalgebra::{Complex, DVector};
use rayon::prelude::*;

use crate::experiments::frequency_response::{simulate_point, FrequencyTest, Peak};
use crate::model::modes::LinearModel;
use crate::model::{ParamError, Params};
use crate::sim::SimError;

/// The exact linear gain |θt/(θm·Rg·Rw)| of one parameter set, in dB.
pub struct LinearGain {
    model: LinearModel,
    force: DVector<Complex<f64>>,
    motor: usize,
    table: usize,
    ratio: f64,
}

impl LinearGain {
    pub fn new(p: &Params) -> Result<Self, ParamError> {
        let model = LinearModel::new(p)?;
        let motor = model.index("theta_m").expect("every topology has theta_m");
        let table = model.index("theta_t").expect("every topology has theta_t");
        let mut force = DVector::from_element(model.n_dof(), Complex::new(0.0, 0.0));
        force[motor] = Complex::new(1.0, 0.0);
        Ok(LinearGain {
            model,
            force,
            motor,
            table,
            ratio: p.ratio(),
        })
    }

    /// Gain at `hz`, dB (−∞ where the system is singular).
    pub fn gain_db(&self, hz: f64) -> f64 {
        match self.model.response(std::f64::consts::TAU * hz, &self.force) {
            Some(x) => {
                20.0 * (x[self.table] / (x[self.motor] * self.ratio))
                    .norm()
                    .log10()
            }
            None => f64::NEG_INFINITY,
        }
    }

    /// Every local maximum of the gain in [lo_hz, hi_hz], located to 1e-7 relative.
    pub fn peaks(&self, lo_hz: f64, hi_hz: f64) -> Vec<Peak> {
        const GRID: usize = 600;
        let ratio = (hi_hz / lo_hz).powf(1.0 / (GRID - 1) as f64);
        let f: Vec<f64> = (0..GRID).map(|i| lo_hz * ratio.powi(i as i32)).collect();
        let g: Vec<f64> = f.iter().map(|&hz| self.gain_db(hz)).collect();
        (1..GRID - 1)
            .filter(|&i| g[i] > g[i - 1] && g[i] >= g[i + 1])
            .map(|i| self.golden_max(f[i - 1], f[i + 1]))
            .collect()
    }

    /// The maximum of the gain in [a, b] (unimodal there) by golden-section search.
    fn golden_max(&self, mut a: f64, mut b: f64) -> Peak {
        let r = 0.5 * (5f64.sqrt() - 1.0);
        let mut c = b - r * (b - a);
        let mut d = a + r * (b - a);
        let (mut gc, mut gd) = (self.gain_db(c), self.gain_db(d));
        while b - a > 1e-7 * b {
            if gc > gd {
                (b, d, gd) = (d, c, gc);
                c = b - r * (b - a);
                gc = self.gain_db(c);
            } else {
                (a, c, gc) = (c, d, gd);
                d = a + r * (b - a);
                gd = self.gain_db(d);
            }
        }
        let f = 0.5 * (a + b);
        Peak {
            frequency_hz: f,
            gain_db: self.gain_db(f),
        }
    }
}

/// The `n` highest local maxima of the linear gain in [lo_hz, hi_hz], ascending in
/// frequency (fewer if the curve has fewer).
pub fn linear_peaks(p: &Params, lo_hz: f64, hi_hz: f64, n: usize) -> Result<Vec<Peak>, ParamError> {
    let mut peaks = LinearGain::new(p)?.peaks(lo_hz, hi_hz);
    peaks.sort_by(|a, b| b.gain_db.total_cmp(&a.gain_db));
    peaks.truncate(n);
    peaks.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    Ok(peaks)
}

/// Relative offsets of the first nonlinear scan around the linear prediction: backlash
/// and friction soften the drive, so the scan reaches further down than up.
const SCAN: [f64; 6] = [-0.08, -0.06, -0.04, -0.02, 0.0, 0.02];
/// How far the scan may be extended when the maximum lies on its edge.
const SCAN_LIMIT: (f64, f64) = (-0.2, 0.1);
/// Relative half-width of the final parabola.
const FINE: f64 = 0.005;

/// The nonlinear gain (dB) at each frequency, in parallel.
pub fn nonlinear_gains(
    p: &Params,
    test: &FrequencyTest,
    freqs: &[f64],
) -> Result<Vec<f64>, SimError> {
    freqs
        .par_iter()
        .map(|&f| simulate_point(p, f, test).map(|pt| pt.gain_db))
        .collect()
}

/// The peak of the nonlinear virtual test nearest above/below the linear prediction
/// `guess_hz`: a scan in 2 % steps (extended while the maximum is on its edge), a
/// parabola through the best scan point and its neighbours, then a parabola of
/// half-width 0.5 % around that vertex.
pub fn nonlinear_peak(p: &Params, test: &FrequencyTest, guess_hz: f64) -> Result<Peak, SimError> {
    let mut offsets: Vec<f64> = SCAN.to_vec();
    let mut freqs: Vec<f64> = offsets.iter().map(|s| guess_hz * (1.0 + s)).collect();
    let mut gains = nonlinear_gains(p, test, &freqs)?;
    loop {
        let j = argmax(&gains);
        let step = 0.02;
        let extend = if j == 0 && offsets[0] - step >= SCAN_LIMIT.0 - 1e-12 {
            Some((0, offsets[0] - step))
        } else if j == offsets.len() - 1 && offsets[j] + step <= SCAN_LIMIT.1 + 1e-12 {
            Some((offsets.len(), offsets[j] + step))
        } else {
            None
        };
        let Some((at, s)) = extend else { break };
        let f = guess_hz * (1.0 + s);
        let g = simulate_point(p, f, test)?.gain_db;
        offsets.insert(at, s);
        freqs.insert(at, f);
        gains.insert(at, g);
    }
    let j = argmax(&gains).clamp(1, freqs.len() - 2);
    let coarse = vertex(
        (freqs[j - 1], gains[j - 1]),
        (freqs[j], gains[j]),
        (freqs[j + 1], gains[j + 1]),
    );
    let h = FINE * guess_hz;
    let fine = [
        coarse.frequency_hz - h,
        coarse.frequency_hz,
        coarse.frequency_hz + h,
    ];
    let g = nonlinear_gains(p, test, &fine)?;
    Ok(vertex((fine[0], g[0]), (fine[1], g[1]), (fine[2], g[2])))
}

/// Relative half-width of the band of measured frequencies in which
/// [`nonlinear_peak_on_grid`] samples the model.
pub const GRID_BAND: f64 = 0.03;

/// The peak of the nonlinear virtual test near `guess_hz`, located as a measurement
/// on the frequencies `grid_hz` locates its own: the test run at the grid's
/// frequencies within ±[`GRID_BAND`] of the guess, a parabola through the highest
/// point and its neighbours — like for like, so that at the parameters that made a
/// measurement the model reproduces its peak exactly, whatever the nonlinear test's
/// irregularities. If the band holds fewer than three frequencies, or its highest
/// point is on its edge (the peak moved out of it), the grid-free
/// [`nonlinear_peak`] is used instead.
pub fn nonlinear_peak_on_grid(
    p: &Params,
    test: &FrequencyTest,
    grid_hz: &[f64],
    guess_hz: f64,
) -> Result<Peak, SimError> {
    let near: Vec<f64> = grid_hz
        .iter()
        .copied()
        .filter(|&f| (f - guess_hz).abs() <= GRID_BAND * guess_hz)
        .collect();
    if near.len() < 3 {
        return nonlinear_peak(p, test, guess_hz);
    }
    let gains = nonlinear_gains(p, test, &near)?;
    let k = argmax(&gains);
    if k == 0 || k + 1 == near.len() {
        return nonlinear_peak(p, test, guess_hz);
    }
    Ok(vertex(
        (near[k - 1], gains[k - 1]),
        (near[k], gains[k]),
        (near[k + 1], gains[k + 1]),
    ))
}

/// How the objectives that compare peaks ([`super::resonance`],
/// [`super::peak_amplitude`]) find the model's: at which fidelity, in which band,
/// under which test conditions, and on which measured frequencies.
#[derive(Clone, Debug)]
pub struct ModelPeaks {
    pub fidelity: super::Fidelity,
    /// Conditions of the nonlinear virtual test.
    pub test: FrequencyTest,
    /// Band in which the model's peaks are sought, Hz.
    pub band: (f64, f64),
    /// The measured frequencies, when the peaks come from a measured gain curve: the
    /// nonlinear model is then sampled on them (like for like).
    pub grid_hz: Option<Vec<f64>>,
}

impl ModelPeaks {
    /// For measured peaks from `lowest_hz` to `highest_hz`: the band is a third of the
    /// lowest to three times the highest.
    pub fn new(
        lowest_hz: f64,
        highest_hz: f64,
        fidelity: super::Fidelity,
        test: FrequencyTest,
    ) -> Self {
        ModelPeaks {
            fidelity,
            test,
            band: (lowest_hz / 3.0, highest_hz * 3.0),
            grid_hz: None,
        }
    }

    /// The model's `n` resonances in the band: the highest linear peaks, each located
    /// in the nonlinear virtual test when the fidelity asks for it (peaks in parallel)
    /// — on the measured frequencies when they are given ([`nonlinear_peak_on_grid`]).
    pub fn locate(&self, p: &Params, n: usize) -> Result<Vec<Peak>, super::ObjectiveError> {
        let guesses = linear_peaks(p, self.band.0, self.band.1, n)?;
        match self.fidelity {
            super::Fidelity::Linear => Ok(guesses),
            super::Fidelity::Nonlinear => guesses
                .par_iter()
                .map(|g| {
                    match &self.grid_hz {
                        Some(grid) => nonlinear_peak_on_grid(p, &self.test, grid, g.frequency_hz),
                        None => nonlinear_peak(p, &self.test, g.frequency_hz),
                    }
                    .map_err(Into::into)
                })
                .collect(),
        }
    }
}

fn argmax(v: &[f64]) -> usize {
    v.iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i)
}

/// The vertex of the parabola through three points (x ascending), clamped to
/// [x0, x2]; the middle point if the parabola is not concave.
pub fn vertex((x0, y0): (f64, f64), (x1, y1): (f64, f64), (x2, y2): (f64, f64)) -> Peak {
    let d = (x0 - x1) * (x0 - x2) * (x1 - x2);
    let a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
    let b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
    if a >= 0.0 || !a.is_finite() || !b.is_finite() {
        let best = [(x0, y0), (x1, y1), (x2, y2)]
            .into_iter()
            .max_by(|p, q| p.1.total_cmp(&q.1))
            .unwrap_or((x1, y1));
        return Peak {
            frequency_hz: best.0,
            gain_db: best.1,
        };
    }
    let xv = (-b / (2.0 * a)).clamp(x0, x2);
    // Evaluate in centred form for accuracy.
    let c = y1 - a * x1 * x1 - b * x1;
    Peak {
        frequency_hz: xv,
        gain_db: a * xv * xv + b * xv + c,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn linear_peaks_are_the_maxima_of_the_linear_gain() {
        let p = presets::load("worm-gear").unwrap();
        let lin = LinearGain::new(&p).unwrap();
        let peaks = linear_peaks(&p, 10.0, 600.0, 2).unwrap();
        assert_eq!(peaks.len(), 2, "{peaks:?}");
        for pk in &peaks {
            for d in [-0.01, 0.01] {
                assert!(lin.gain_db(pk.frequency_hz + d) < pk.gain_db, "{pk:?}");
            }
        }
        // Near the damped motor-held modes (186.5 and 236.9 Hz undamped).
        assert!((peaks[0].frequency_hz - 186.9).abs() < 0.5, "{peaks:?}");
        assert!((peaks[1].frequency_hz - 234.1).abs() < 1.0, "{peaks:?}");
    }

    #[test]
    fn the_vertex_of_a_parabola_is_exact() {
        let y = |x: f64| 3.0 - 0.5 * (x - 1.3) * (x - 1.3);
        let pk = vertex((1.0, y(1.0)), (1.5, y(1.5)), (2.0, y(2.0)));
        assert!((pk.frequency_hz - 1.3).abs() < 1e-12 && (pk.gain_db - 3.0).abs() < 1e-12);
    }
}
