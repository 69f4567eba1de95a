//! The evaluations as `rtid evaluate --json` prints them, one function per kind: the
//! command line prints them, the Python module returns them, so both give the same
//! keys and units (report units: arc-seconds or µm for positioning, N for a linear
//! axis's efforts).

use serde::Serialize;
use serde_json::{json, Value};

use crate::estimation::inverse_dynamics::IdimFit;
use crate::experiments::fluctuation::Evaluation as FluctuationEvaluation;
use crate::experiments::frequency_response::periodic_evaluation::Mode;
use crate::experiments::frequency_response::time_evaluation::Evaluation as TimeEvaluation;
use crate::experiments::friction_map::MapEvaluation;
use crate::experiments::positioning::iso230::{Iso230Report, ReportUnits};
use crate::experiments::servo_trace::{Misfit, TraceEvaluation};
use crate::experiments::torque_curve::TorqueReport;
use crate::io::experiment_file::{Axis, Kind};
use crate::io::json::{value, JsonError};

/// A torque curve's report; on a linear axis its `_nm` keys are `_n` (forces in N).
pub fn torque_curve(report: &TorqueReport, axis: Axis, source: &str) -> Result<Value, JsonError> {
    let mut v = value(report)?;
    if axis == Axis::Linear {
        in_newtons(&mut v);
    }
    v["kind"] = json!("torque_curve");
    v["source"] = json!(source);
    Ok(v)
}

/// A linear axis's report: the `_nm` keys (N·m) renamed `_n`, as its values are
/// forces in N.
fn in_newtons(value: &mut Value) {
    match value {
        Value::Object(map) => {
            let old = std::mem::take(map);
            for (k, mut v) in old {
                in_newtons(&mut v);
                let key = match k.strip_suffix("_nm") {
                    Some(stem) => format!("{stem}_n"),
                    None => k,
                };
                map.insert(key, v);
            }
        }
        Value::Array(items) => items.iter_mut().for_each(in_newtons),
        _ => {}
    }
}

/// An ISO 230-2 evaluation in the report units `u`: each target's statistics with
/// its position (`target_deg` or `target_mm`), and the axis values.
pub fn positioning(
    report: &Iso230Report,
    u: ReportUnits,
    source: &str,
) -> Result<Value, JsonError> {
    let k = u.deviation_per_si;
    let mut targets = Vec::with_capacity(report.targets.len());
    for t in &report.targets {
        let mut v = value(&t.scaled(k))?;
        v[format!("target_{}", u.target_key)] = value(&(t.target * u.target_per_si))?;
        targets.push(v);
    }
    Ok(json!({
        "kind": "positioning",
        "source": source,
        "unit": u.deviation_key,
        "axis": value(&report.axis.scaled(k))?,
        "targets": targets,
    }))
}

/// A fluctuation or unbalance test's deviation statistics, in arc-seconds.
pub fn fluctuation(
    e: &FluctuationEvaluation,
    kind: Kind,
    source: &str,
) -> Result<Value, JsonError> {
    let mut v = labelled(e, kind.name(), source)?;
    v["unit"] = json!("arcsec");
    Ok(v)
}

/// `e` as JSON with its `kind` and `source`.
fn labelled(e: &impl Serialize, kind: &str, source: &str) -> Result<Value, JsonError> {
    let mut v = value(e)?;
    v["kind"] = json!(kind);
    v["source"] = json!(source);
    Ok(v)
}

/// A raw time record's gain curve (stepped-sine demodulation, H1 with coherence) or a
/// periodic multisine's two channels, with the channels' mode frequencies as flat
/// `*_hz` keys for scripts.
pub fn frequency_response_time(
    e: &TimeEvaluation,
    kind: Kind,
    source: &str,
) -> Result<Value, JsonError> {
    let mut v = labelled(e, kind.name(), source)?;
    if let (TimeEvaluation::Periodic(p), Some(map)) = (e, v.as_object_mut()) {
        let hz = |m: &[Mode]| value(&m.iter().map(|m| m.frequency_hz).collect::<Vec<_>>());
        map.insert("table_resonances_hz".into(), hz(&p.table.resonances)?);
        map.insert(
            "table_antiresonances_hz".into(),
            hz(&p.table.antiresonances)?,
        );
        map.insert("motor_resonances_hz".into(), hz(&p.motor.resonances)?);
        map.insert(
            "motor_antiresonances_hz".into(),
            hz(&p.motor.antiresonances)?,
        );
    }
    Ok(v)
}

/// A friction map's laws and the one the data support.
pub fn friction_map(e: &MapEvaluation, source: &str) -> Result<Value, JsonError> {
    labelled(e, "friction_map", source)
}

/// What the evaluation of a servo trace reports (SI units).
#[derive(Clone, Debug, Serialize)]
pub struct TraceReport {
    pub kind: &'static str,
    pub source: String,
    pub axis: Axis,
    pub samples: usize,
    pub sample_period_s: f64,
    /// M, Fv, Fc, OF of F = M·a + Fv·v + Fc·sign(v) + OF (OF = −Tload).
    pub inverse_dynamics: IdimFit,
    /// Where they are: `motor` (the positions divided by `ratio`) or `as_recorded`
    /// (the effort over the loop encoder's position: on a geared axis neither the
    /// motor's frame nor the table's).
    pub frame: &'static str,
    /// Table turns per motor turn the positions were divided by.
    pub ratio: Option<f64>,
    /// The trace replayed on a model: position in m or rad, force in N or N·m.
    pub simulation_error: Option<Misfit>,
}

impl TraceReport {
    /// The report of a trace of `samples` samples every `sample_period_s` on `axis`.
    pub fn new(
        source: String,
        axis: Axis,
        (samples, sample_period_s): (usize, f64),
        e: TraceEvaluation,
    ) -> Self {
        let TraceEvaluation { fit, ratio, replay } = e;
        TraceReport {
            kind: "servo_trace",
            source,
            axis,
            samples,
            sample_period_s,
            inverse_dynamics: fit,
            frame: if ratio.is_some() {
                "motor"
            } else {
                "as_recorded"
            },
            ratio,
            simulation_error: replay.map(|(_, misfit)| misfit),
        }
    }
}
