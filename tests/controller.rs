//! The default servo settles a 30° step in both presets and both loops.

use rtid::input::Move;
use rtid::model::{idx::*, presets, LoopMode};
use rtid::recorder::Trace;
use rtid::sim::Simulation;

const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;

#[test]
fn a_30_degree_step_settles_without_sustained_oscillation() {
    for name in ["worm-gear", "roller-gear-cam"] {
        for mode in [LoopMode::SemiClosed, LoopMode::FullClosed] {
            let mut p = presets::load(name).unwrap();
            p.controller.loop_mode = mode;
            let mut sim = Simulation::with_default_step(&p).unwrap();
            let mut controller = sim.controller(&p).unwrap();
            let target = 30f64.to_radians();
            let step = Move {
                from: 0.0,
                to: target,
                speed: None,
            };
            let mut trace = Trace::every(10);
            sim.run_closed_loop(&mut controller, &step, 2.0, &mut trace)
                .unwrap();
            let tail: Vec<_> = trace.samples.iter().filter(|s| s.t >= 1.5).collect();
            let range = |f: &dyn Fn(&rtid::recorder::Sample) -> f64| {
                let v: Vec<f64> = tail.iter().map(|s| f(s)).collect();
                v.iter().cloned().fold(f64::MIN, f64::max)
                    - v.iter().cloned().fold(f64::MAX, f64::min)
            };
            // The table has arrived (within the worm's lost motion, semi-closed) …
            let error = (tail.last().unwrap().y[THETA_T] - target).abs() / ARCSEC;
            assert!(
                error < 30.0,
                "{name} {mode}: final error {error:.1} arc-sec"
            );
            // … and is still over the last half second: no limit cycle at the table
            // (less than two table-encoder counts), none at the motor either.
            let table = range(&|s| s.y[THETA_T]) / ARCSEC;
            let motor = range(&|s| s.y[THETA_M] * p.ratio()) / ARCSEC;
            assert!(
                table < 0.72,
                "{name} {mode}: table moves {table:.3} arc-sec at rest"
            );
            assert!(
                motor < 0.72,
                "{name} {mode}: motor moves {motor:.3} arc-sec (table units) at rest"
            );
            // It got there: never overshot by more than 1 % of the move.
            let peak = trace
                .samples
                .iter()
                .map(|s| s.y[THETA_T])
                .fold(f64::MIN, f64::max);
            assert!(
                peak < 1.01 * target,
                "{name} {mode}: overshoot to {:.3}°",
                peak.to_degrees()
            );
        }
    }
}

#[test]
fn an_unstable_gain_is_reported_as_divergence_not_nan() {
    let mut p = presets::load("worm-gear").unwrap();
    p.controller.kvp = 200.0; // far beyond what the sampled loop tolerates
    p.controller.torque_limit = 1e9;
    let mut sim = Simulation::with_default_step(&p).unwrap();
    let mut controller = sim.controller(&p).unwrap();
    let step = Move {
        from: 0.0,
        to: 1.0,
        speed: None,
    };
    let err = sim
        .run_closed_loop(
            &mut controller,
            &step,
            2.0,
            &mut rtid::recorder::NullRecorder,
        )
        .unwrap_err();
    assert!(err.to_string().contains("diverged at t ="), "{err}");
}
