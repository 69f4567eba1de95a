//! The measured resonances an objective compares: the manifest's peaks, or the
//! prominent peaks of a gain curve; the curve's own helpers are
//! [`crate::experiments::frequency_response::measured`]'s.

use crate::estimation::peaks::{self, Peak};
use crate::experiments::frequency_response::measured::{
    form, in_band, valid_points, PROMINENCE_DB,
};
use crate::io::experiment_file::{Data, Response};
use crate::objectives::definition::{SetupError, Source};

/// The measured resonances of an experiment: the manifest's peaks, or the prominent
/// peaks of the gain curve ([`PROMINENCE_DB`]), inside its band when it has one.
/// Heights are NaN where not given.
pub fn measured_peaks(source: &Source<'_>) -> Result<Vec<Peak>, SetupError> {
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
        Data::FrequencyResponse { .. }
            if form(source.experiment).response != Response::TableOverMotor =>
        {
            Err(SetupError::Data {
                file: source.file.into(),
                reason: format!(
                    "a {} response's peaks are not the motor-held resonances the \
                     resonance objectives compare: it is fitted by its whole curve \
                     (--objective gain_curve, the default)",
                    form(source.experiment).response.name()
                ),
            })
        }
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
