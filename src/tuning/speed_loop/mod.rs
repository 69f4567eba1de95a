//! The speed loop's reference response — what a drive's measuring function records
//! with the speed loop closed (docs/tuning.md, "The drive's own measurement"): actual
//! speed over speed setpoint, one line per DFT bin of a PRBS period.
//!
//! - [`model`]: the model's closed loop, exact on the sampled loop;
//! - [`measured`]: a measured response against it (residuals, misfit, Bode curves);
//! - [`overlay`]: a measurement beside the model with today's and proposed settings;
//! - [`time_series`]: a measurement's response recomputed from its own time series
//!   with rtid's periodic estimator, and how it agrees with the drive's spectra;
//! - this file: the virtual measurement — the model's closed loop at the lines a
//!   drive measures (k/(N·Tc), k = 1 … (N − 1)/2 − 1, N = 2^order − 1), with seeded
//!   complex noise and the coherence it implies, in the form `rtid import` writes a
//!   drive's file in (a frequency response with `response: "speed_loop"`).

pub mod measured;
pub mod model;
pub mod overlay;
pub mod time_series;

use nalgebra::Complex;

use crate::experiments::measurement_noise;
use crate::io::experiment_file::{Columns, Data, DriveFunctions, Kind, Manifest, Response};
use crate::model::{ParamError, Params};
use model::ClosedSpeedLoop;

/// A virtual speed-loop measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedLoopTest {
    /// The PRBS's order: a period of 2^order − 1 control periods (the shared file: 11).
    pub prbs_order: u32,
    /// Complex noise on each line, % of the response (σ of each part).
    pub noise_percent: f64,
    /// Spectra averaged per line (the drive averages the two directions: 2).
    pub averages: u32,
    pub seed: u64,
    /// Whether the manifest states the speed controller's gains (a measurement saved
    /// with the drive's settings); by default it does not, as a drive's file does not.
    pub state_gains: bool,
}

impl Default for SpeedLoopTest {
    fn default() -> Self {
        SpeedLoopTest {
            prbs_order: 11,
            noise_percent: 1.0,
            averages: 2,
            seed: 1,
            state_gains: false,
        }
    }
}

/// Why a virtual speed-loop measurement cannot be made.
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum SpeedLoopError {
    #[error(transparent)]
    Param(#[from] ParamError),
    #[error("the speed loop of these settings is unstable (a closed-loop pole outside the unit circle): no drive measures its response")]
    Unstable,
    #[error("prbs_order {0}: a PRBS period of 2^order − 1 samples needs an order of 4 … 20")]
    Order(u32),
}

/// The lines of one record: frequencies, the response measured and the model's own.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedLoopRecord {
    pub frequency_hz: Vec<f64>,
    pub measured: Vec<Complex<f64>>,
    pub exact: Vec<Complex<f64>>,
}

/// The measurement on `p`'s closed speed loop.
pub fn run(p: &Params, test: &SpeedLoopTest) -> Result<SpeedLoopRecord, SpeedLoopError> {
    if !(4..=20).contains(&test.prbs_order) {
        return Err(SpeedLoopError::Order(test.prbs_order));
    }
    let t = ClosedSpeedLoop::new(p)?;
    if t.stable() != Some(true) {
        return Err(SpeedLoopError::Unstable);
    }
    let n = (1usize << test.prbs_order) - 1;
    let step = 1.0 / (n as f64 * p.controller.tc);
    let (frequency_hz, exact): (Vec<f64>, Vec<Complex<f64>>) = (1..(n - 1) / 2)
        .filter_map(|k| {
            let f = k as f64 * step;
            t.at(f).map(|h| (f, h))
        })
        .unzip();
    let mut gain_db: Vec<f64> = exact.iter().map(|h| 20.0 * h.norm().log10()).collect();
    let mut phase: Vec<f64> = exact.iter().map(|h| h.arg()).collect();
    measurement_noise::perturb_complex(&mut gain_db, &mut phase, test.noise_percent, test.seed);
    let measured = gain_db
        .iter()
        .zip(&phase)
        .map(|(g, ph)| Complex::from_polar(10f64.powf(g / 20.0), *ph))
        .collect();
    Ok(SpeedLoopRecord {
        frequency_hz,
        measured,
        exact,
    })
}

/// The record as experiment-file data: gain, phase, the coherence the noise implies
/// for `averages` spectra (γ² = 1/(1 + 2n·σ²), the inverse of the σ rtid reads from
/// it: `measured::complex_points`) and the exact response beside them.
pub fn to_data(record: &SpeedLoopRecord, test: &SpeedLoopTest) -> Data {
    let sigma = test.noise_percent / 100.0;
    let n = f64::from(test.averages.max(1));
    let coherence = 1.0 / (1.0 + 2.0 * n * sigma * sigma);
    let mut extra = Columns::new();
    extra.insert(
        "coherence".into(),
        vec![coherence; record.frequency_hz.len()],
    );
    extra.insert(
        "exact_gain_db".into(),
        record
            .exact
            .iter()
            .map(|h| 20.0 * h.norm().log10())
            .collect(),
    );
    Data::FrequencyResponse {
        frequency_hz: record.frequency_hz.clone(),
        gain_db: record
            .measured
            .iter()
            .map(|h| 20.0 * h.norm().log10())
            .collect(),
        phase_rad: Some(record.measured.iter().map(|h| h.arg()).collect()),
        extra,
    }
}

/// The manifest: a speed-loop response at `p`'s control period, its averages, and
/// the gains only where the test states them.
pub fn manifest(p: &Params, test: &SpeedLoopTest) -> Manifest {
    let mut m = Manifest::new(Kind::FrequencyResponse);
    m.mechanism = Some(p.name.clone());
    let c = &mut m.conditions;
    c.response = Some(Response::SpeedLoop);
    c.loop_period_s = Some(p.controller.tc);
    c.averages = Some(test.averages.max(1));
    if test.state_gains {
        c.controller = Some(DriveFunctions {
            kvp: Some(p.controller.kvp),
            kvi: Some(p.controller.kvi),
            ..Default::default()
        });
    }
    m.notes = Some(format!(
        "virtual speed-loop measurement by rtid: the closed speed loop exact on the sampled \
         loop at the DFT lines of a {}-sample PRBS period, {} % complex noise (seed {})",
        (1u64 << test.prbs_order) - 1,
        test.noise_percent,
        test.seed
    ));
    m
}
