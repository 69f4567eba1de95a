//! The frequency-response test as experiment-file data: the points as a gain curve
//! with their diagnostics (contact loss per mesh, settled, below resolution) and the
//! exact linear gain beside them, the manifest, and the test solved on the linear
//! model alone (`--linear`).

use super::{linear_of, refinement, FrequencyTest, Point};
use crate::io::experiment_file::{Columns, Data, Kind, Manifest, Response};
use crate::model::{ParamError, Params};

/// The test on the linear model, solved in the frequency domain: the coarse grid,
/// then the refinement around each peak, sorted by frequency.
pub fn linear_points(
    p: &Params,
    test: &FrequencyTest,
    response: Response,
) -> Result<Vec<Point>, ParamError> {
    let solve = |freqs: &[f64]| -> Result<Vec<Point>, ParamError> {
        Ok(linear_of(p, response, freqs)?
            .into_iter()
            .zip(freqs)
            .map(|((gain_db, phase_deg), &frequency_hz)| Point {
                frequency_hz,
                gain_db,
                phase_deg,
                motor_amplitude_rad: f64::NAN,
                table_amplitude_rad: f64::NAN,
                contact_loss: [0.0, 0.0],
                settled: true,
                below_resolution: false,
                simulated_s: 0.0,
            })
            .collect())
    };
    let mut points = solve(&test.frequencies_hz)?;
    if test.refine_step_hz > 0.0 {
        let extra = refinement(&points, test);
        points.extend(solve(&extra)?);
        points.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    }
    Ok(points)
}

/// The experiment-file form of the points of `p`'s test: gain and phase, the
/// diagnostics as extra columns, and `linear_gain_db`, the exact linear response.
pub fn to_data(p: &Params, points: &[Point], response: Response) -> Result<Data, ParamError> {
    let frequency_hz: Vec<f64> = points.iter().map(|q| q.frequency_hz).collect();
    let flag = |f: fn(&Point) -> bool| -> Vec<f64> {
        points.iter().map(|q| f64::from(u8::from(f(q)))).collect()
    };
    let mut extra = Columns::new();
    extra.insert(
        "contact_loss_spur".into(),
        points.iter().map(|q| q.contact_loss[0]).collect(),
    );
    extra.insert(
        "contact_loss_drive".into(),
        points.iter().map(|q| q.contact_loss[1]).collect(),
    );
    extra.insert("settled".into(), flag(|q| q.settled));
    extra.insert("below_resolution".into(), flag(|q| q.below_resolution));
    extra.insert(
        "linear_gain_db".into(),
        linear_of(p, response, &frequency_hz)?
            .into_iter()
            .map(|g| g.0)
            .collect(),
    );
    Ok(Data::FrequencyResponse {
        gain_db: points.iter().map(|q| q.gain_db).collect(),
        phase_rad: Some(points.iter().map(|q| q.phase_deg.to_radians()).collect()),
        frequency_hz,
        extra,
    })
}

/// The manifest of a virtual frequency-response test (`linear`: solved on the
/// linear model).
pub fn manifest(p: &Params, test: &FrequencyTest, linear: bool, response: Response) -> Manifest {
    let mut m = Manifest::new(Kind::FrequencyResponse);
    if response != Response::TableOverMotor {
        m.conditions.response = Some(response);
    }
    m.mechanism = Some(p.name.clone());
    m.conditions.torque_amplitude_nm = Some(test.amplitude_nm);
    m.conditions.preload_nm = Some(test.preload_nm);
    m.notes = Some(
        if linear {
            "virtual test by rtid: linear response solved in the frequency domain"
        } else {
            "virtual test by rtid: nonlinear time simulation per frequency"
        }
        .into(),
    );
    m
}

/// What a virtual record is disturbed with to stand in for a measured one: Gaussian
/// noise on the amplitude ratio and on the complex ratio (percent), and a delay in
/// the phase that the manifest leaves unstated (`delay_s: "unknown"`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Disturbance {
    pub noise_percent: f64,
    pub complex_noise_percent: f64,
    pub seed: u64,
    pub unstated_delay_s: f64,
}

impl Disturbance {
    /// `data` (a frequency response with phase; any other is left as it is)
    /// disturbed, each disturbance said in the manifest's notes or conditions.
    pub fn apply(&self, data: &mut Data, manifest: &mut Manifest) {
        use crate::experiments::measurement_noise as noise;
        let Data::FrequencyResponse {
            gain_db,
            phase_rad: Some(phase),
            frequency_hz,
            ..
        } = data
        else {
            return;
        };
        let mut notes = manifest.notes.take().unwrap_or_default();
        if self.noise_percent > 0.0 {
            noise::perturb_gain_db(gain_db, self.noise_percent, self.seed);
            notes += &format!(
                "; {} % Gaussian noise on the amplitude ratio (seed {})",
                self.noise_percent, self.seed
            );
        }
        if self.complex_noise_percent > 0.0 {
            let seed = self.seed.wrapping_add(0x9e37_79b9);
            noise::perturb_complex(gain_db, phase, self.complex_noise_percent, seed);
            notes += &format!(
                "; {} % complex Gaussian noise on the ratio (seed {})",
                self.complex_noise_percent, self.seed
            );
        }
        manifest.notes = Some(notes);
        if self.unstated_delay_s > 0.0 {
            for (ph, f) in phase.iter_mut().zip(frequency_hz.iter()) {
                let delayed = *ph - std::f64::consts::TAU * f * self.unstated_delay_s;
                *ph = crate::angle::wrap(delayed);
            }
            manifest.conditions.delay_s = Some(crate::io::experiment_file::Delay::Unknown);
        }
    }
}
