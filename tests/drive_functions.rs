//! The controller's functions as drives have them (docs/model.md §1 "Servo as real
//! drives have it"), on the model in closed loop: velocity and torque feed-forward
//! take the following error of a constant-speed move away; the symmetrising lag puts
//! it back where feed-forward and feedback meet; a setpoint filter leaves the move's
//! end where it was; and the CNC's backlash compensation by the mean reversal value
//! cancels the worm-gear table's reversal in the ISO 230-2 test.

use rtid::controller::Compensation;
use rtid::experiments::positioning::{self, iso230, PositioningTest};
use rtid::input::Move;
use rtid::model::{idx::*, presets, rest::rest_state, rest::Preload, Params, SetpointFilter};
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;

/// The table's following error (reference − table angle, rad) `at` s into a 20°
/// move at 60°/s of the direct-drive table, and the error at the end after settling.
fn following_error(p: &Params, at: f64) -> (f64, f64) {
    let mut sim = Simulation::with_default_step(p).unwrap();
    sim.set_state(rest_state(p, 0.0, Preload::None));
    let mut controller = sim.controller(p).unwrap();
    let m = Move {
        from: 0.0,
        to: 20f64.to_radians(),
        speed: Some(60f64.to_radians()),
    };
    let reference = |t: f64| rtid::input::Trajectory::angle(&m, t);
    sim.run_closed_loop(&mut controller, &reference, at, &mut NullRecorder)
        .unwrap();
    let moving = reference(sim.time()) - sim.state()[THETA_T];
    sim.run_closed_loop(&mut controller, &reference, 1.0, &mut NullRecorder)
        .unwrap();
    (moving, m.to - sim.state()[THETA_T])
}

#[test]
fn feed_forward_takes_the_following_error_of_a_constant_speed_move_away() {
    let p = presets::load("direct-drive").unwrap();
    let (plain, plain_end) = following_error(&p, 0.2);
    // Without feed-forward the P position loop lags by speed/Kpp.
    let lag = 60f64.to_radians() / p.controller.kpp;
    assert!((plain / lag - 1.0).abs() < 0.05, "{plain} vs {lag}");
    let mut ff = p.clone();
    ff.controller.kvff = 1.0;
    ff.controller.kaff = p.jt / p.controller.drive_gain;
    let (with_ff, ff_end) = following_error(&ff, 0.2);
    assert!(with_ff.abs() < 0.02 * lag, "{with_ff} vs {lag}");
    // Both come to rest at the target (within the encoder's counts).
    assert!(
        plain_end.abs() < 1e-5 && ff_end.abs() < 1e-5,
        "{plain_end} {ff_end}"
    );
}

#[test]
fn the_symmetrising_lag_delays_the_position_loops_reference_by_its_time_constant() {
    let p = presets::load("direct-drive").unwrap();
    let mut sym = p.clone();
    sym.controller.kvff = 1.0;
    sym.controller.symmetrising_s = 2e-3;
    // At constant speed the lagged reference trails by speed·T: the loop leaves the
    // table that far behind (the feed-forward does not know the lag).
    let (error, end) = following_error(&sym, 0.2);
    let behind = 60f64.to_radians() * 2e-3;
    assert!((error / behind - 1.0).abs() < 0.1, "{error} vs {behind}");
    assert!(end.abs() < 1e-5, "{end}");
}

#[test]
fn a_setpoint_filter_leaves_the_move_where_it_ends() {
    let mut p = presets::load("direct-drive").unwrap();
    p.controller.filters = vec![
        SetpointFilter::LowPass {
            frequency_hz: 1500.0,
            damping: 0.7,
        },
        SetpointFilter::Notch {
            centre_hz: 900.0,
            width_hz: 300.0,
            depth_db: Some(-20.0),
        },
    ];
    p.validate().unwrap();
    let (_, end) = following_error(&p, 0.2);
    assert!(end.abs() < 1e-5, "{end}");
    // Above Nyquist: refused, naming the filter and the field.
    p.controller.filters[1] = SetpointFilter::Notch {
        centre_hz: 2500.0,
        width_hz: 300.0,
        depth_db: None,
    };
    let e = p.validate().unwrap_err().to_string();
    assert!(
        e.contains("setpoint filter 2: centre_hz = 2500 Hz") && e.contains("Nyquist"),
        "{e}"
    );
}

/// The worm-gear table's ISO 230-2 axis values over 5 targets, 2 runs.
fn positioning_values(compensation: Compensation) -> iso230::AxisStats {
    let p = presets::load("worm-gear").unwrap();
    let test = PositioningTest {
        targets: (0..5).map(|i| (10.0 * i as f64).to_radians()).collect(),
        runs: 2,
        dwell: 0.5,
        compensation,
        ..Default::default()
    };
    let readings = positioning::run(&p, &test, |_, _| {}).unwrap();
    iso230::evaluate(&readings).unwrap().axis
}

#[test]
fn backlash_compensation_by_the_mean_reversal_cancels_the_reversal() {
    let arcsec = |x: f64| x.to_degrees() * 3600.0;
    let plain = positioning_values(Compensation::default());
    // The worm's lost motion: about −35″ (docs/validation.md).
    assert!(arcsec(plain.b_mean) < -20.0, "{}", arcsec(plain.b_mean));
    let compensated = positioning_values(Compensation {
        backlash: Some(plain.b_mean),
        ..Default::default()
    });
    assert!(
        arcsec(compensated.b_mean).abs() < 2.0,
        "B̄ {}″ → {}″",
        arcsec(plain.b_mean),
        arcsec(compensated.b_mean)
    );
    assert!(
        compensated.a < 0.6 * plain.a,
        "A {} → {}",
        arcsec(plain.a),
        arcsec(compensated.a)
    );
}

#[test]
fn a_trace_recorded_with_feed_forward_replays_from_its_stated_functions() {
    use rtid::experiments::servo_trace::{replay, simulation_error, virtual_trace};
    use rtid::io::experiment_file::DriveFunctions;
    let model = presets::load("direct-drive").unwrap();
    let mut drive = model.clone();
    let functions = DriveFunctions {
        kvff: Some(1.0),
        kaff: Some(model.jt / model.controller.drive_gain),
        symmetrising_s: Some(5e-4),
        filters: Some(vec![SetpointFilter::LowPass {
            frequency_hz: 1200.0,
            damping: 0.7,
        }]),
        ..Default::default()
    };
    functions.apply(&mut drive.controller);
    let recorded = virtual_trace(&drive, &Default::default(), None).unwrap();
    // The model's own controller, without the drive's functions: off.
    let plain = replay(&model, &recorded).unwrap();
    let off = simulation_error(&recorded, &plain).unwrap();
    // With the functions the manifest states: the record itself, bit for bit.
    let stated = rtid::experiments::servo_trace::ServoTrace {
        drive_functions: Some(functions),
        ..recorded.clone()
    };
    let run = replay(&model, &stated).unwrap();
    let on = simulation_error(&stated, &run).unwrap();
    assert_eq!((on.position_max, on.force_rms), (0.0, 0.0), "{on:?}");
    assert!(off.force_rms > 0.1, "{off:?}");
    // A filter the trace's loop cannot run is refused, naming it.
    let bad = rtid::experiments::servo_trace::ServoTrace {
        drive_functions: Some(DriveFunctions {
            filters: Some(vec![SetpointFilter::LowPass {
                frequency_hz: 1e5,
                damping: 0.7,
            }]),
            ..Default::default()
        }),
        ..recorded
    };
    let e = replay(&model, &bad).unwrap_err().to_string();
    assert!(
        e.contains("conditions.controller") && e.contains("Nyquist"),
        "{e}"
    );
}

/// The direct-drive table following a sine of ±10° over 2 s: the largest following
/// error (rad) over the second period, with `compensation` in the controller.
fn sine_following_error(p: &Params, compensation: Compensation) -> f64 {
    let mut sim = Simulation::with_default_step(p).unwrap();
    sim.set_state(rest_state(p, 0.0, Preload::None));
    let mut controller = sim.controller(p).unwrap();
    controller.set_compensation(compensation);
    let amplitude = 10f64.to_radians();
    let reference = |t: f64| amplitude * (1.0 - (std::f64::consts::PI * t).cos());
    sim.run_closed_loop(&mut controller, &reference, 2.0, &mut NullRecorder)
        .unwrap();
    let mut worst = 0.0f64;
    for _ in 0..2000 {
        sim.run_closed_loop(&mut controller, &reference, 1e-3, &mut NullRecorder)
            .unwrap();
        worst = worst.max((reference(sim.time()) - sim.state()[THETA_T]).abs());
    }
    worst
}

#[test]
fn friction_compensation_by_the_drives_own_law_shrinks_the_reversal_error() {
    use rtid::controller::FrictionCompensation;
    use rtid::model::friction::Body;
    // Feed-forward on in both: what is left of the following error is the friction's.
    let mut p = presets::load("direct-drive").unwrap();
    p.controller.kvff = 1.0;
    p.controller.kaff = p.jt / p.controller.drive_gain;
    let plain = sine_following_error(&p, Compensation::default());
    let law = FrictionCompensation {
        law: p.steady(Body::Table),
        offset: 0.0,
        pulse: None,
    };
    let compensated = sine_following_error(
        &p,
        Compensation {
            friction: Some(law),
            ..Default::default()
        },
    );
    assert!(compensated < 0.5 * plain, "{plain} → {compensated} rad");
}
