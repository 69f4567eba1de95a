//! Virtual servo traces: the model run along a reference of trapezoidal moves and
//! recorded the way a drive records itself, so that rtid makes traces of its own
//! presets (to test replays and fits against known parameters).

use super::replay::{run_servo, Start};
use super::{ServoTrace, TraceError};
use crate::io::experiment_file::{Axis, CommandUnit, Data, Kind, Manifest};
use crate::model::params::Params;

/// One point-to-point move of a [`TrapezoidalMoves`] reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveTo {
    /// Where to, rad or m.
    pub target: f64,
    /// Cruise speed (> 0), rad/s or m/s.
    pub speed: f64,
}

/// A reference of point-to-point moves with trapezoidal velocity (constant
/// acceleration, cruise, constant deceleration; triangular when a move is too short
/// to reach its cruise speed), starting at 0 after a dwell, each move followed by a
/// dwell. Units: rad, rad/s, rad/s² on a rotary axis, m, m/s, m/s² on a linear one
/// (table side). The default moves to +0.1 at 0.2 per s, to −0.1 at 0.1 per s and
/// back to 0 at 0.05 per s, accelerating at 2 per s², with 0.2 s dwells (5.5 s): on a
/// rotary table a 5.7° swing at up to 1.9 rpm, on a feed axis a 100 mm stroke at up to
/// 12 m/min; three speeds in both directions, so that a friction fit separates the
/// viscous from the Coulomb friction (one speed alone cannot).
#[derive(Clone, Debug, PartialEq)]
pub struct TrapezoidalMoves {
    /// The moves in turn, from 0.
    pub moves: Vec<MoveTo>,
    /// Acceleration and deceleration (> 0).
    pub acceleration: f64,
    /// Rest before the first move and after each, s (≥ 0).
    pub dwell_s: f64,
}

impl Default for TrapezoidalMoves {
    fn default() -> Self {
        let to = |target, speed| MoveTo { target, speed };
        TrapezoidalMoves {
            moves: vec![to(0.1, 0.2), to(-0.1, 0.1), to(0.0, 0.05)],
            acceleration: 2.0,
            dwell_s: 0.2,
        }
    }
}

impl TrapezoidalMoves {
    /// Checks that every value can make a profile.
    pub fn check(&self) -> Result<(), TraceError> {
        let bad = |name, value, reason| {
            Err(TraceError::Moves {
                name,
                value,
                reason,
            })
        };
        if !(self.acceleration > 0.0 && self.acceleration.is_finite()) {
            return bad(
                "acceleration",
                self.acceleration,
                "must be positive and finite",
            );
        }
        if !(self.dwell_s >= 0.0 && self.dwell_s.is_finite()) {
            return bad("dwell_s", self.dwell_s, "must be finite and not negative");
        }
        for m in &self.moves {
            if !m.target.is_finite() {
                return bad("target", m.target, "must be finite");
            }
            if !(m.speed > 0.0 && m.speed.is_finite()) {
                return bad("speed", m.speed, "must be positive and finite");
            }
        }
        Ok(())
    }

    /// The whole profile's duration, s.
    pub fn duration(&self) -> f64 {
        self.segments()
            .map(|(.., time)| time + self.dwell_s)
            .sum::<f64>()
            + self.dwell_s
    }

    /// The reference at `t` s (0 before the first move; the last target after the
    /// end).
    pub fn position(&self, t: f64) -> f64 {
        let mut start = self.dwell_s;
        let mut at = 0.0;
        for (from, m, time) in self.segments() {
            if t < start {
                return at;
            }
            if t < start + time {
                return from + self.travel(m.target - from, m.speed, t - start);
            }
            at = m.target;
            start += time + self.dwell_s;
        }
        at
    }

    /// (from, move, duration) of each move.
    fn segments(&self) -> impl Iterator<Item = (f64, MoveTo, f64)> + '_ {
        let froms = std::iter::once(0.0).chain(self.moves.iter().map(|m| m.target));
        froms
            .zip(self.moves.iter().copied())
            .map(|(from, m)| (from, m, self.move_time((m.target - from).abs(), m.speed)))
    }

    /// Duration of a move over `distance` at cruise speed `v`, s.
    fn move_time(&self, distance: f64, v: f64) -> f64 {
        let a = self.acceleration;
        if distance * a >= v * v {
            distance / v + v / a
        } else {
            2.0 * (distance / a).sqrt()
        }
    }

    /// Signed distance travelled `tau` s into a move over `signed` at speed `v`.
    fn travel(&self, signed: f64, v: f64, tau: f64) -> f64 {
        let (distance, a) = (signed.abs(), self.acceleration);
        let total = self.move_time(distance, v);
        let ramp = (v / a).min(0.5 * total);
        let peak = a * ramp;
        let d = if tau < ramp {
            0.5 * a * tau * tau
        } else if tau < total - ramp {
            0.5 * a * ramp * ramp + peak * (tau - ramp)
        } else {
            distance - 0.5 * a * (total - tau).powi(2)
        };
        d.min(distance).copysign(signed)
    }
}

/// Runs the model `params` (its controller, loop and encoders) along `moves` from
/// rest at 0 and records it as a servo trace sampled at the controller period:
/// positions table-side (module docs), quantised by the encoders; the table encoder
/// recorded too; the controller output; and, if given, `added(t)` (controller output
/// unit) added to the output at every sample and recorded. A trace of the model
/// replayed with the same parameters reproduces itself exactly (tests/servo_trace.rs).
pub fn virtual_trace(
    params: &Params,
    moves: &TrapezoidalMoves,
    added: Option<&dyn Fn(f64) -> f64>,
) -> Result<ServoTrace, TraceError> {
    moves.check()?;
    params.validate().map_err(crate::sim::SimError::from)?;
    let tc = params.controller.tc;
    let n = (moves.duration() / tc + 1e-9).floor() as usize + 1;
    let time_s: Vec<f64> = (0..n).map(|k| k as f64 * tc).collect();
    let reference: Vec<f64> = time_s.iter().map(|&t| moves.position(t)).collect();
    let added: Option<Vec<f64>> = added.map(|f| time_s.iter().map(|&t| f(t)).collect());
    let start = Start {
        position: 0.0,
        velocity: 0.0,
    };
    let run = run_servo(params, &time_s, &reference, added.as_deref(), start)?;
    Ok(ServoTrace {
        time_s,
        reference,
        position: run.position,
        table_position: Some(run.table_position),
        force: run.force,
        controller_output: Some(run.controller_output),
        controller_added: added,
        drive_functions: None,
    })
}

/// The unit a drive's controller output is recorded in: volts where a drive gain
/// stands between it and the effort, else the effort's own (N·m, or N on a linear
/// axis).
pub fn command_unit(params: &Params) -> CommandUnit {
    match (params.controller.drive_gain == 1.0, params.axis) {
        (false, _) => CommandUnit::Volt,
        (true, Axis::Rotary) => CommandUnit::NewtonMetre,
        (true, Axis::Linear) => CommandUnit::Newton,
    }
}

/// A virtual trace of `params` along `moves` as an experiment file holds it (the
/// manifest with the moves in its notes, the data in the axis's units), as
/// `rtid experiment servo-trace` writes it.
pub fn to_file(params: &Params, moves: &TrapezoidalMoves, trace: &ServoTrace) -> (Manifest, Data) {
    let mut manifest = Manifest::new(Kind::ServoTrace);
    manifest.mechanism = Some(params.name.clone());
    manifest.notes = Some(format!(
        "virtual servo trace by rtid: {} trapezoidal move(s) from rest at 0 (targets and speeds {}), acceleration {}, dwell {} s; sampled at the control period {} s, encoders quantised",
        moves.moves.len(),
        moves
            .moves
            .iter()
            .map(|x| format!("{}@{}", x.target, x.speed))
            .collect::<Vec<_>>()
            .join(", "),
        moves.acceleration,
        moves.dwell_s,
        params.controller.tc
    ));
    let data = Data::ServoTrace(trace.to_file(params.axis, command_unit(params)));
    (manifest, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_profile_reaches_each_target_at_the_set_speed_and_acceleration() {
        let m = TrapezoidalMoves::default();
        // Move 1: 0 → 0.1 at 0.2/s, 2/s²: ramps of 0.1 s, cruise 0.4 s.
        assert_eq!(m.position(0.1), 0.0);
        assert!((m.position(0.2 + 0.1) - 0.01).abs() < 1e-12);
        assert!((m.position(0.2 + 0.3) - (0.01 + 0.2 * 0.2)).abs() < 1e-12);
        assert!((m.position(0.2 + 0.6 + 0.1) - 0.1).abs() < 1e-12);
        // Move 2: 0.1 → −0.1 at 0.1/s: 2 s + 0.05 s; move 3: 0.1 at 0.05/s: 2.025 s.
        let total = 0.2 + 0.6 + 0.2 + 2.05 + 0.2 + 2.025 + 0.2;
        assert!((m.duration() - total).abs() < 1e-12);
        assert!(m.position(0.2 + 0.6 + 0.2 + 1.025).abs() < 1e-12);
        assert_eq!(m.position(100.0), 0.0);
        // A short move is triangular: 0.005 at 2/s² takes 2·√(0.0025) = 0.1 s.
        let short = TrapezoidalMoves {
            moves: vec![MoveTo {
                target: 0.005,
                speed: 0.2,
            }],
            dwell_s: 0.0,
            ..m
        };
        assert!((short.duration() - 0.1).abs() < 1e-12);
        assert!((short.position(0.05) - 0.0025).abs() < 1e-12);
    }

    #[test]
    fn bad_moves_are_named() {
        let m = TrapezoidalMoves {
            acceleration: 0.0,
            ..Default::default()
        };
        let err = m.check().unwrap_err().to_string();
        assert!(err.contains("acceleration = 0"), "{err}");
    }
}
