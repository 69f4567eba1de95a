//! What a measured experiment says, as the objectives read it: its resonances (the
//! manifest's, or the prominent peaks of its gain curve), the frequencies it was
//! measured at, and the conditions of the test the model must reproduce.

use super::registry::{SetupError, Source};
use crate::estimation::peaks::{self, Peak};
use crate::experiments::frequency_response::FrequencyTest;
use crate::io::experiment_file::{Data, Experiment, Kind};

/// A local maximum of a measured gain curve counts as a resonance when it stands
/// this far above the lowest point between it and any higher point (or the curve's
/// end) on each side — its topographic prominence ([`peaks::prominent`]).
/// Measurement noise makes many small maxima; a friction-damped worm resonance may
/// stand only ~1.6 dB out.
pub const PROMINENCE_DB: f64 = 1.0;

/// The nonlinear frequency-response test at an experiment's conditions.
pub fn frequency_test(exp: &Experiment) -> FrequencyTest {
    let c = &exp.manifest.conditions;
    let d = FrequencyTest::default();
    FrequencyTest {
        amplitude_nm: c.torque_amplitude_nm.unwrap_or(d.amplitude_nm),
        preload_nm: c.preload_nm.unwrap_or(d.preload_nm),
        ..d
    }
}

/// The measured resonances of an experiment: the manifest's peaks, or the prominent
/// peaks of the gain curve ([`PROMINENCE_DB`]), inside its band when it has one.
/// Heights are NaN where not given.
pub fn peaks(source: &Source<'_>) -> Result<Vec<Peak>, SetupError> {
    match &source.experiment.data {
        Data::Resonance {
            peaks_hz,
            peak_gain_db,
        } => Ok(peaks_hz
            .iter()
            .enumerate()
            .map(|(k, &f)| Peak {
                frequency_hz: f,
                gain_db: peak_gain_db
                    .as_ref()
                    .and_then(|g| g.get(k))
                    .copied()
                    .unwrap_or(f64::NAN),
            })
            .filter(|pk| in_band(source.experiment, pk.frequency_hz))
            .collect()),
        Data::FrequencyResponse { .. } => {
            let curve: Vec<(f64, f64)> = valid_points(source.experiment).collect();
            let found = peaks::prominent(&curve, None, PROMINENCE_DB);
            if found.is_empty() {
                return Err(SetupError::NoPeaks {
                    file: source.file.into(),
                });
            }
            Ok(found)
        }
        _ => Err(SetupError::Unsupported {
            file: source.file.into(),
            kind: source.kind().name(),
        }),
    }
}

/// The band of an experiment's resonances (`conditions.band_hz`), Hz.
pub fn band(exp: &Experiment) -> Option<(f64, f64)> {
    exp.manifest.conditions.band_hz.map(|[lo, hi]| (lo, hi))
}

/// Whether `hz` lies in the experiment's band (always, without one).
fn in_band(exp: &Experiment, hz: f64) -> bool {
    band(exp).map_or(true, |(lo, hi)| lo <= hz && hz <= hi)
}

/// The (frequency, gain) points of a gain curve that are measurements of the drive,
/// inside its band when it has one: points flagged `below_resolution` (the table did
/// not move more than the encoder resolves) are left out. Empty for other kinds.
pub(crate) fn valid_points(exp: &Experiment) -> impl Iterator<Item = (f64, f64)> + '_ {
    let (f, g, flags) = match &exp.data {
        Data::FrequencyResponse {
            frequency_hz,
            gain_db,
            extra,
            ..
        } => (
            frequency_hz.as_slice(),
            gain_db.as_slice(),
            extra.get("below_resolution"),
        ),
        _ => (&[][..], &[][..], None),
    };
    (0..f.len())
        .filter(move |&i| flags.map_or(true, |c| c.get(i).map_or(true, |&v| v < 0.5)))
        .filter(move |&i| in_band(exp, f[i]))
        .map(move |i| (f[i], g[i]))
}

/// The frequencies of a measured gain curve (ascending), on which the nonlinear
/// model's peaks are located like for like; `None` for other kinds.
pub fn grid(exp: &Experiment) -> Option<Vec<f64>> {
    if exp.manifest.kind != Kind::FrequencyResponse {
        return None;
    }
    let mut f: Vec<f64> = valid_points(exp).map(|(f, _)| f).collect();
    f.sort_by(f64::total_cmp);
    Some(f)
}
