//! Where the model's resonances are, for the objectives that compare peaks: those of
//! its exact linear response ([`crate::estimation::peaks::of_linear_response`]), or of the
//! nonlinear virtual test (a short scan of time simulations around the linear
//! prediction + two parabolic refinements, or like for like on a measured grid).
//!
//! The nonlinear search costs 9 simulations per peak (more if the peak lies outside
//! the first scan); the linear one a few hundred 4×4 complex solves.

use rayon::prelude::*;

use crate::estimation::peaks::{of_linear_response, vertex, Peak};
use crate::experiments::frequency_response::{simulate_point, FrequencyTest};
use crate::model::Params;
use crate::sim::SimError;

/// Relative offsets of the first nonlinear scan around the linear prediction: backlash
/// and friction soften the drive, so the scan reaches further down than up.
const SCAN: [f64; 6] = [-0.08, -0.06, -0.04, -0.02, 0.0, 0.02];
/// How far the scan may be extended when the maximum lies on its edge.
const SCAN_LIMIT: (f64, f64) = (-0.2, 0.1);
/// Relative half-width of the final parabola.
const FINE: f64 = 0.005;

/// The nonlinear gain (dB) at each frequency, in parallel.
pub(crate) fn nonlinear_gains(
    p: &Params,
    test: &FrequencyTest,
    freqs: &[f64],
) -> Result<Vec<f64>, SimError> {
    freqs
        .par_iter()
        .map(|&f| simulate_point(p, f, test).map(|pt| pt.gain_db))
        .collect()
}

/// The nonlinear gain (dB) and phase (deg) at each frequency, in parallel.
pub(crate) fn nonlinear_responses(
    p: &Params,
    test: &FrequencyTest,
    freqs: &[f64],
) -> Result<Vec<(f64, f64)>, SimError> {
    freqs
        .par_iter()
        .map(|&f| simulate_point(p, f, test).map(|pt| (pt.gain_db, pt.phase_deg)))
        .collect()
}

/// The peak of the nonlinear virtual test nearest above/below the linear prediction
/// `guess_hz`: a scan in 2 % steps (extended while the maximum is on its edge), a
/// parabola through the best scan point and its neighbours, then a parabola of
/// half-width 0.5 % around that vertex.
pub(crate) fn nonlinear_peak(
    p: &Params,
    test: &FrequencyTest,
    guess_hz: f64,
) -> Result<Peak, SimError> {
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
pub(crate) fn nonlinear_peak_on_grid(
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

/// How the objectives that compare peaks ([`crate::objectives::resonance`],
/// [`crate::objectives::peak_amplitude`]) find the model's: at which fidelity, in which band,
/// under which test conditions, and on which measured frequencies.
#[derive(Clone, Debug)]
pub struct ModelPeaks {
    pub fidelity: crate::objectives::Fidelity,
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
        fidelity: crate::objectives::Fidelity,
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
    pub fn locate(
        &self,
        p: &Params,
        n: usize,
    ) -> Result<Vec<Peak>, crate::objectives::ObjectiveError> {
        let guesses = of_linear_response(p, self.band.0, self.band.1, n)?;
        match self.fidelity {
            crate::objectives::Fidelity::Linear => Ok(guesses),
            crate::objectives::Fidelity::Nonlinear => guesses
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
