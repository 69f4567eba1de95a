//! The paper's Table 3 (§5, "Comparison between driving mechanisms"): one [`Summary`]
//! per folder of experiment files, each experiment evaluated by its own evaluator.
//!
//! [`summarize`] reads every `*.json` in a folder (not its subfolders) whose top level is
//! an object with a `kind` key, i.e. an experiment manifest (`docs/experiment-files.md`);
//! other JSON, such as a parameter file written by `rtid params --out`, is skipped
//! quietly. A file that is not JSON at all, a manifest that cannot be read, or an
//! experiment that cannot be evaluated is an error naming the file. When a folder holds
//! several experiments of one kind, the first by file name is used (all are listed in
//! [`Summary::sources`]); a `frequency_response` and a `resonance` file fill the same row,
//! again the first by file name.
//!
//! Verdicts use one physical threshold, [`THRESHOLD_ARCSEC`]: two counts of the paper's
//! table encoder (0.0001° = 0.36″ a count, the same encoder on both tables). A deviation
//! of one count can be the quantisation of a reading, so only what exceeds two counts is
//! taken as a feature of the drive:
//! * rotational fluctuation is *present* when the amplitude of the dominant order of the
//!   deviation θt − θm·Rg·Rw exceeds it (the worm's 72 cycles/rev are several arc-sec,
//!   the roller's spectrum holds quantisation only);
//! * the motion is *influenced* by the unbalance mass when the largest step of the
//!   deviation (the backlash crossed where the unbalance moment overcomes the friction)
//!   exceeds it in magnitude.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::positioning::iso230;
use super::{fluctuation, positioning, torque_curve};
use crate::io::experiment_file::{self, Data, Experiment, ExperimentFileError};

/// Two table-encoder counts of the paper's tables (2 × 0.0001°), arc-sec: the smallest
/// fluctuation amplitude or unbalance step counted as real (module docs).
pub const THRESHOLD_ARCSEC: f64 = 2.0 * 0.0001 * 3600.0;

/// Largest resonance peaks reported (the paper lists two per table).
pub const RESONANCES: usize = 3;

/// The rotational-fluctuation row.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fluctuation {
    /// Cycles per table revolution of the largest spectral peak (none if the spectrum
    /// has no peak).
    pub dominant_order: Option<f64>,
    /// Its amplitude, arc-sec (0 if no peak).
    pub amplitude_arcsec: f64,
    /// Amplitude above [`THRESHOLD_ARCSEC`]: "exists"; else "cannot be identified".
    pub present: bool,
}

/// The unbalance row.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Unbalance {
    /// Magnitude of the largest step of the deviation, arc-sec.
    pub step_arcsec: f64,
    /// Step above [`THRESHOLD_ARCSEC`].
    pub influenced: bool,
}

/// One folder's column of Table 3; `None`: no experiment of that kind in the folder.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// The `mechanism` of the manifests (distinct values joined by ", ").
    pub mechanism: Option<String>,
    /// The manifests evaluated or skipped as duplicates, by file name.
    pub sources: Vec<PathBuf>,
    /// Resonances, Hz, ascending: the largest [`RESONANCES`] peaks of a frequency
    /// response (or a resonance file's `peaks_hz`).
    pub resonances_hz: Option<Vec<f64>>,
    /// Coulomb friction at the motor from the torque curve (half the jump at the velocity
    /// reversals), N·m. `None` also when the curve has no usable reversal.
    pub friction_torque_nm: Option<f64>,
    /// ISO 230-2 mean reversal value |B̄|, arc-sec (the paper's "B").
    pub b_mean_arcsec: Option<f64>,
    /// ISO 230-2 bidirectional repeatability R, arc-sec.
    pub r_arcsec: Option<f64>,
    /// ISO 230-2 bidirectional accuracy A, arc-sec.
    pub a_arcsec: Option<f64>,
    pub fluctuation: Option<Fluctuation>,
    pub unbalance: Option<Unbalance>,
    /// Lost motion at the table, arc-sec: |B̄| of the positioning test, else the gap
    /// between the CW and CCW curves of the fluctuation test.
    pub backlash_arcsec: Option<f64>,
    /// Where [`Summary::backlash_arcsec`] comes from: `positioning` or `fluctuation`.
    pub backlash_from: Option<&'static str>,
}

/// Why a folder cannot be summarised.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CompareError {
    #[error("cannot list {dir}: {source}")]
    Dir {
        dir: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not JSON: {message}")]
    NotJson { path: PathBuf, message: String },
    #[error(transparent)]
    File(#[from] ExperimentFileError),
    #[error("{path}: cannot evaluate: {source}")]
    Evaluate {
        path: PathBuf,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// Whether the JSON file at `path` is an experiment manifest (an object with `kind`).
fn is_manifest(path: &Path) -> Result<bool, CompareError> {
    let text = crate::io::read_input(path).map_err(|source| ExperimentFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let value: serde_json::Value =
        serde_json::from_str(crate::io::without_bom(&text)).map_err(|e| CompareError::NotJson {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    Ok(value.get("kind").is_some())
}

/// Summarises every experiment in `dir` (module docs).
pub fn summarize(dir: &Path) -> Result<Summary, CompareError> {
    let dir_error = |source| CompareError::Dir {
        dir: dir.to_path_buf(),
        source,
    };
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(dir_error)? {
        let path = entry.map_err(dir_error)?.path();
        if path.is_file() && path.extension().is_some_and(|e| e == "json") {
            files.push(path);
        }
    }
    files.sort();
    let mut s = Summary::default();
    let mut mechanisms: Vec<String> = Vec::new();
    for path in files {
        if !is_manifest(&path)? {
            continue;
        }
        let exp = experiment_file::read(&path)?;
        if let Some(m) = &exp.manifest.mechanism {
            if !mechanisms.contains(m) {
                mechanisms.push(m.clone());
            }
        }
        s.sources.push(path.clone());
        add(&mut s, &exp).map_err(|source| CompareError::Evaluate { path, source })?;
    }
    if !mechanisms.is_empty() {
        s.mechanism = Some(mechanisms.join(", "));
    }
    if let Some(b) = s.b_mean_arcsec {
        s.backlash_arcsec = Some(b);
        s.backlash_from = Some("positioning");
    } else if let Some(gap) = s.backlash_arcsec {
        s.backlash_arcsec = Some(gap.abs());
        s.backlash_from = Some("fluctuation");
    }
    Ok(s)
}

/// Why one experiment could not be evaluated (each evaluator's own error).
type BoxedError = Box<dyn std::error::Error + Send + Sync>;

/// Evaluates one experiment into the rows it fills (if not filled already). The
/// fluctuation gap is parked in `backlash_arcsec` until [`summarize`] decides.
fn add(s: &mut Summary, exp: &Experiment) -> Result<(), BoxedError> {
    match &exp.data {
        Data::FrequencyResponse {
            frequency_hz,
            gain_db,
            ..
        } if s.resonances_hz.is_none()
            && crate::experiments::frequency_response::measured::of_the_mechanics(exp) =>
        {
            let curve: Vec<(f64, f64)> = frequency_hz
                .iter()
                .copied()
                .zip(gain_db.iter().copied())
                .collect();
            let peaks = crate::estimation::peaks::maxima(&curve, RESONANCES);
            s.resonances_hz = Some(peaks.iter().map(|p| p.frequency_hz).collect());
        }
        Data::Resonance { peaks_hz, .. } if s.resonances_hz.is_none() => {
            let mut p = peaks_hz.clone();
            p.sort_by(f64::total_cmp);
            s.resonances_hz = Some(p);
        }
        Data::TorqueCurve { .. } if s.friction_torque_nm.is_none() => {
            let curve = torque_curve::from_data(&exp.data).ok_or("not a torque curve")?;
            let test = torque_curve::TorqueTest::from_conditions(&exp.manifest.conditions);
            let report = torque_curve::evaluate(&curve, &test)?;
            s.friction_torque_nm = report.friction_nm;
        }
        Data::Positioning { .. } if s.b_mean_arcsec.is_none() => {
            let readings = positioning::from_data(&exp.data).ok_or("not positioning data")?;
            let axis = iso230::evaluate(&readings)?.axis.in_arcsec();
            s.b_mean_arcsec = Some(axis.b_mean.abs());
            s.r_arcsec = Some(axis.r);
            s.a_arcsec = Some(axis.a);
        }
        Data::Fluctuation { .. } if s.fluctuation.is_none() => {
            let e = fluctuation::evaluate_experiment(exp)?;
            let top = e.dominant.first();
            let amplitude = top.map_or(0.0, |p| p.amplitude);
            s.fluctuation = Some(Fluctuation {
                dominant_order: top.map(|p| p.order),
                amplitude_arcsec: amplitude,
                present: amplitude > THRESHOLD_ARCSEC,
            });
            if s.backlash_arcsec.is_none() {
                s.backlash_arcsec = e.gap_arcsec;
            }
        }
        Data::Unbalance { .. } if s.unbalance.is_none() => {
            let e = fluctuation::evaluate_experiment(exp)?;
            let step = e.step.size_arcsec.abs();
            s.unbalance = Some(Unbalance {
                step_arcsec: step,
                influenced: step > THRESHOLD_ARCSEC,
            });
        }
        _ => {}
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::positioning::iso230::ARCSEC_PER_RAD;

    #[test]
    fn the_threshold_is_two_counts_of_a_tenthousandth_degree() {
        let count = 1e-4f64.to_radians() * ARCSEC_PER_RAD;
        assert!((THRESHOLD_ARCSEC - 2.0 * count).abs() < 1e-12);
        assert!((THRESHOLD_ARCSEC - 0.72).abs() < 1e-12);
    }

    #[test]
    fn an_empty_folder_has_no_rows_and_other_json_is_skipped() {
        let dir = std::env::temp_dir().join(format!("rtid-compare-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("params.json"), r#"{"name": "x", "Kw": 1.0}"#).unwrap();
        let s = summarize(&dir).unwrap();
        assert_eq!(s, Summary::default());
        std::fs::write(dir.join("broken.json"), "{ not json").unwrap();
        let e = summarize(&dir).unwrap_err().to_string();
        assert!(e.contains("broken.json"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
