//! Servo-trace output error: the recorded trace replayed on the model through its
//! sampled servo, closed loop, over the whole record (`experiments::servo_trace`), and
//! the replayed force and loop-encoder position compared with the recorded ones,
//! sample by sample. The output-error refinement of the IDIM-LS start: unlike
//! the inverse model it sees the whole loop (the controller, its delay, the encoder's
//! quantisation), and its residuals are the benchmark's simulation error.
//!
//! Scales: 1 % of the recorded force's RMS per force sample and 1 % of the recorded
//! following error's RMS (reference − position) per position sample. They set the
//! relative weight of the two signals only: the standard errors come from the
//! residuals' own scatter (σ² = Σr²/(m − n)), so the absolute scale cancels. They are
//! not the measurement noise: an encoder's noise (EMPS: 5e-8 m/√12 ≈ 14 nm) lies some
//! 140 times below the replay's model error (2 µm), and weighting by it would make
//! the fit a position-only one; by each signal's RMS both count.

use super::definition::{Definition, Estimated, SetupError, Source};
use super::{Detail, Fidelity, Objective, ObjectiveError, Properties, Smoothness};
use crate::estimation::inverse_dynamics::IdimSettings;
use crate::experiments::servo_trace::{replay, replay_batch, Replay, ServoTrace, TraceError};
use crate::io::experiment_file::{Data, Kind};
use crate::model::{Params, Topology};

/// The servo-trace objective: a closed-loop replay with quantised encoders (rough);
/// determines the rigid core of the axis — inertia, viscous and Coulomb friction and
/// the constant load — and, for a geared table, the motor's friction.
pub static DEFINITION: Definition = Definition {
    name: "servo_trace",
    summary:
        "output error of the trace replayed through the servo: force and position, sample by sample",
    reads: &[Kind::ServoTrace],
    needs: "a servo_trace experiment",
    properties: Properties {
        smoothness: Smoothness::Grainy,
        frequency_response: false,
    },
    determines: |_, p| determines(p),
    default_weight: |exp, _| (exp.manifest.kind == Kind::ServoTrace).then_some(1.0),
    build,
    first_estimate: Some(inverse_dynamics_start),
    describe,
};

fn determines(p: &Params) -> Vec<&'static str> {
    match p.topology {
        Topology::DirectDrive | Topology::TwoMass => vec!["Jt", "Ct", "ft", "Tload"],
        Topology::SpurGear | Topology::Direct => vec!["fm", "Cm"],
    }
}

fn build(source: &Source<'_>, _: Fidelity) -> Result<Box<dyn Objective>, SetupError> {
    let Some(trace) = ServoTrace::from_experiment(source.experiment) else {
        return Err(SetupError::Unsupported {
            file: source.file.into(),
            kind: source.kind().name(),
        });
    };
    Ok(Box::new(TraceResidual::new(trace)))
}

/// The IDIM-LS estimate of a direct-drive axis's rigid core (M, Fv, Fc, OF → Jt, Ct,
/// ft, Tload = −OF), the filters carried to the record's sampling rate: where the
/// output error starts. None for a geared or two-mass axis, whose recorded force
/// moves more than one body.
fn inverse_dynamics_start(
    source: &Source<'_>,
    base: &Params,
) -> Result<Option<Estimated>, SetupError> {
    let Data::ServoTrace(file) = &source.experiment.data else {
        return Ok(None);
    };
    if base.topology != Topology::DirectDrive {
        return Ok(None);
    }
    let trace = ServoTrace::from_file(file);
    let data = |reason: String| SetupError::Data {
        file: source.file.into(),
        reason,
    };
    let period = trace.check().map_err(|e| data(e.to_string()))?;
    let settings = IdimSettings::for_sample_period(period);
    let fit = trace
        .fit_friction(&settings)
        .map_err(|e| data(format!("inverse-dynamics start: {e}")))?;
    Ok(Some(Estimated {
        values: vec![
            ("Jt".into(), fit.inertia.value),
            ("Ct".into(), fit.viscous.value),
            ("ft".into(), fit.coulomb.value),
            ("Tload".into(), -fit.offset.value),
        ],
        method: format!(
            "IDIM-LS on {}: position low-passed at {:.0} Hz (Butterworth order {}, zero phase), decimated by {}, {} samples trimmed at each end, {} rows",
            source.file, settings.cutoff_hz, settings.filter_order, settings.decimation, settings.trim, fit.rows
        ),
    }))
}

/// One scaled residual is this fraction of the recorded signal's RMS.
pub const SCALE_OF_RMS: f64 = 0.01;

/// A recorded trace and the scales of its two signals.
#[derive(Clone, Debug)]
pub struct TraceResidual {
    pub trace: ServoTrace,
    /// N or N·m per unit of scaled force residual.
    pub force_scale: f64,
    /// m or rad per unit of scaled position residual.
    pub position_scale: f64,
}

impl TraceResidual {
    pub fn new(trace: ServoTrace) -> Self {
        let following: Vec<f64> = trace
            .reference
            .iter()
            .zip(&trace.position)
            .map(|(r, q)| r - q)
            .collect();
        TraceResidual {
            force_scale: (SCALE_OF_RMS * rms(&trace.force)).max(1e-9),
            position_scale: (SCALE_OF_RMS * rms(&following)).max(1e-12),
            trace,
        }
    }

    /// The scaled residuals of `run`: force, then position, (replayed − recorded) /
    /// scale sample by sample.
    fn scaled(&self, run: &Replay) -> Vec<f64> {
        let force = run
            .force
            .iter()
            .zip(&self.trace.force)
            .map(|(m, f)| (m - f) / self.force_scale);
        let position = run
            .position
            .iter()
            .zip(&self.trace.position)
            .map(|(m, q)| (m - q) / self.position_scale);
        force.chain(position).collect()
    }
}

/// Largest − smallest of `x` (0 when empty).
fn span(x: &[f64]) -> f64 {
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if hi >= lo {
        hi - lo
    } else {
        0.0
    }
}

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

fn objective_error(e: TraceError) -> ObjectiveError {
    match e {
        TraceError::Simulation(s) => ObjectiveError::Sim(s),
        other => ObjectiveError::Data {
            what: "servo trace".into(),
            reason: other.to_string(),
        },
    }
}

impl Objective for TraceResidual {
    fn name(&self) -> &'static str {
        "servo_trace"
    }

    fn residuals(&self, p: &Params) -> Result<Vec<f64>, ObjectiveError> {
        let run = replay(p, &self.trace).map_err(objective_error)?;
        Ok(self.scaled(&run))
    }

    fn residuals_batch(&self, points: &[Params]) -> Vec<Result<Vec<f64>, ObjectiveError>> {
        replay_batch(points, &self.trace)
            .into_iter()
            .map(|run| Ok(self.scaled(&run.map_err(objective_error)?)))
            .collect()
    }

    fn in_lanes(&self) -> bool {
        true
    }

    fn len(&self) -> usize {
        2 * self.trace.len()
    }

    fn scale(&self) -> String {
        format!(
            "{:.3e} of force and {:.3e} of position per sample (1 % of the recorded force's and following error's RMS)",
            self.force_scale, self.position_scale
        )
    }

    fn detail(&self, _: &Params, r: &[f64]) -> Option<Detail> {
        let (force, position) = r.split_at(r.len() / 2);
        Some(Detail::Trace {
            force_rms: rms(force) * self.force_scale,
            position_rms: rms(position) * self.position_scale,
            position_max: position.iter().fold(0.0, |m: f64, v| m.max(v.abs()))
                * self.position_scale,
            position_span: span(&self.trace.position),
        })
    }
}

/// The replay's simulation error.
fn describe(d: &Detail) -> Option<String> {
    let Detail::Trace {
        force_rms,
        position_rms,
        position_max,
        ..
    } = d
    else {
        return None;
    };
    Some(format!(
        "  replay: force {force_rms:.4} RMS; position {position_rms:.4e} RMS, {position_max:.4e} max (SI)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_detail_is_the_simulation_error() {
        let trace = ServoTrace {
            time_s: vec![0.0, 1.0],
            reference: vec![1.0, 1.0],
            position: vec![0.0, 0.0],
            force: vec![3.0, 4.0],
            ..Default::default()
        };
        let o = TraceResidual::new(trace.clone());
        let run = crate::experiments::servo_trace::Replay {
            time_s: trace.time_s.clone(),
            position: vec![0.5, -1.0],
            table_position: vec![0.0; 2],
            force: vec![3.0, 6.0],
            controller_output: vec![0.0; 2],
        };
        let r: Vec<f64> = run
            .force
            .iter()
            .zip(&trace.force)
            .map(|(m, f)| (m - f) / o.force_scale)
            .chain(
                run.position
                    .iter()
                    .zip(&trace.position)
                    .map(|(m, q)| (m - q) / o.position_scale),
            )
            .collect();
        let want = crate::experiments::servo_trace::simulation_error(&trace, &run).unwrap();
        let Some(Detail::Trace {
            force_rms,
            position_rms,
            position_max,
            position_span,
        }) = o.detail(&crate::model::presets::load("direct-drive").unwrap(), &r)
        else {
            panic!("a trace detail")
        };
        assert!((force_rms - want.force_rms).abs() < 1e-12);
        assert!((position_rms - want.position_rms).abs() < 1e-12);
        assert!((position_max - want.position_max).abs() < 1e-12);
        assert_eq!(position_span, 0.0, "the record stood still");
        assert_eq!(span(&[0.5, -1.0, 2.0]), 3.0);
    }
}
