//! A drive's own measurement (a SINUMERIK/SINAMICS measuring-function file) as an
//! rtid experiment, without maps: the file says what it measured, so the primary
//! response from its stored spectra becomes a frequency response with the loop it
//! describes in its conditions (`response: "speed_loop"`), the coherence per line and
//! the spectra's averages (their noise), the speed controller's sample period, and
//! the settings the file carries (none, in the files seen: no `controller`). The
//! manifest's provenance adds what the file says of the test (loop, excitation,
//! offsets, directions, axis) under `import.measurement`.

use std::path::Path;

use serde_json::{json, Value};

use super::{manifest, ImportError, Imported, Request, Source};
use crate::io::experiment_file::{Columns, Conditions, Data, Response};
use crate::io::formats::sinumerik_trace::response::{self, MeasuredLoop, StoredResponse};
use crate::io::formats::sinumerik_trace::Measurement;
use crate::io::import::kinds::ImportKind;

/// The experiment of the stored response of `m`, read from `source`, with the
/// conditions and mechanism asked (`--condition`, `--mechanism`) over the file's own.
pub fn build(
    source: &Source,
    m: &Measurement,
    conditions: &Conditions,
    conditions_given: &[String],
    mechanism: Option<String>,
) -> Result<Imported, ImportError> {
    let fail = |e: response::ResponseError| ImportError(format!("{}: {e}", source.path.display()));
    let measured = response::measured_loop(m).map_err(fail)?;
    let r = response::stored_response(m).map_err(fail)?;
    let request = Request {
        kind: ImportKind::FrequencyResponse,
        maps: Vec::new(),
        conditions: conditions_of(m, &r, measured, conditions),
        conditions_given: conditions_given.to_vec(),
        mechanism,
    };
    let findings: Vec<String> = source
        .recording
        .notes
        .iter()
        .map(|n| format!("{}: {n}", source.path.display()))
        .collect();
    let mut manifest = manifest(std::slice::from_ref(source), &request, &findings)?;
    if let Some(Value::Object(import)) = manifest.extra.get_mut("import") {
        import.insert("measurement".into(), provenance(m, &r, measured));
    }
    Ok(Imported {
        data: data(&r),
        manifest,
        findings,
    })
}

/// The file's conditions with the asked ones over them.
fn conditions_of(
    m: &Measurement,
    r: &StoredResponse,
    measured: MeasuredLoop,
    asked: &Conditions,
) -> Conditions {
    let mut c = asked.clone();
    match measured {
        MeasuredLoop::SpeedClosed => {
            c.response.get_or_insert(Response::SpeedLoop);
        }
    }
    c.loop_period_s.get_or_insert(m.sample_time_s);
    c.averages.get_or_insert(r.averaged.max(1));
    c
}

/// The response: gain, phase, and per line its coherence and the file's own
/// frequency (which steps 0.15 % wide of the DFT's: [`response`]).
fn data(r: &StoredResponse) -> Data {
    let mut extra = Columns::new();
    extra.insert("coherence".into(), r.coherence.clone());
    extra.insert("file_frequency_hz".into(), r.file_frequency_hz.clone());
    Data::FrequencyResponse {
        frequency_hz: r.frequency_hz.clone(),
        gain_db: r.h.iter().map(|h| 20.0 * h.norm().log10()).collect(),
        phase_rad: Some(r.h.iter().map(|h| h.arg()).collect()),
        extra,
    }
}

/// What the file says of the test, for the manifest.
fn provenance(m: &Measurement, r: &StoredResponse, measured: MeasuredLoop) -> Value {
    let a = &m.excitation.axis;
    json!({
        "loop": measured.describe(),
        "control_loop_type": m.loop_type,
        "injection_point": m.injection_point,
        "closed_loop": m.excitation.closed_loop,
        "waveform_type": m.waveform,
        "prbs_order": m.excitation.prbs_order,
        "sample_time_s": m.sample_time_s,
        "samples_per_period": r.samples_per_period,
        "spectra_averaged": r.averaged,
        "directions": m.excitation.levels.iter().map(|l| json!({
            "role": l.role,
            "offset_rad_s": l.offset,
            "excitation_amplitude_rad_s": l.amplitude,
        })).collect::<Vec<_>>(),
        "axis": {
            "rotary": a.rotary,
            "direct_drive": a.direct_drive,
            "linear_motor": a.linear_motor,
            "motor_to_axis_ratio": a.motor_to_axis_ratio,
            "torque_constant_nm_per_a": a.torque_constant,
        },
        "platform": m.platform,
        "timestamp": m.timestamp.as_ref().map(|(d, t)| format!("{d} {t}")),
    })
}

/// Whether `path` was read as a drive measurement rtid imports without maps.
pub fn is_drive_measurement(source: &Source) -> bool {
    source.recording.format == crate::io::formats::sinumerik_trace::DEFINITION.name
}

/// The measurement of `source`, read typed.
pub fn measurement(path: &Path) -> Result<Measurement, ImportError> {
    crate::io::formats::sinumerik_trace::read_measurement(path)
        .map_err(|e| ImportError(e.to_string()))
}
