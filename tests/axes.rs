//! The direct-drive and two-mass topologies, the linear axis, the constant load Tload
//! and the servo as real drives have it, stated as physics (docs/model.md §1): the
//! two-mass drive oscillates at √(Kw·(1/Jm + 1/Jt)) and keeps its energy; a direct
//! drive under half its friction does not creep and above it accelerates at
//! (T − fc)/J; Tload moves the servo's equilibrium by Tload over the servo's
//! stiffness, and a position integrator removes that offset; the new presets settle a
//! step; every experiment that sets an initial state runs on every topology.

use std::f64::consts::PI;

use rtid::experiments::frequency_response::{simulate_point, FrequencyTest};
use rtid::experiments::positioning::{self, PositioningTest};
use rtid::input::{Move, NoTorque, Step};
use rtid::model::{idx::*, modes, presets, Axis, Drive, ParamError, Params, Topology};
use rtid::recorder::{NullRecorder, Recorder, Trace};
use rtid::sim::Simulation;

/// The EMPS axis (linear direct drive) as shipped in fixtures/real/emps/axis.json.
fn emps_axis() -> Params {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/real/emps/axis.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn an_undamped_two_mass_drive_rings_at_its_free_mode_and_keeps_its_energy() {
    let mut p = presets::load("two-mass").unwrap();
    (p.cm, p.ct, p.ciw, p.fm, p.ft) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let free_hz = (p.kw * (1.0 / p.jm + 1.0 / p.jt)).sqrt() / (2.0 * PI);
    assert!((modes::modes(&p).unwrap().free_hz[0] - free_hz).abs() < 1e-9 * free_hz);
    // A twist of 1e-3 rad with zero momentum: Jm·θm + Jt·θt = 0.
    let twist = 1e-3;
    let mut y = [0.0; rtid::model::NSTATE];
    y[THETA_M] = twist * p.jt / (p.jm + p.jt);
    y[THETA_T] = -twist * p.jm / (p.jm + p.jt);
    let mut sim = Simulation::with_default_step(&p).unwrap();
    sim.set_state(y);
    let d = *sim.drive();
    let e0 = d.energy(&sim.state());
    struct Crossings(Vec<f64>, f64);
    impl Recorder for Crossings {
        fn record(&mut self, t: f64, y: &[f64; rtid::model::NSTATE], _u: f64) {
            let twist = y[THETA_M] - y[THETA_T];
            if self.1 > 0.0 && twist <= 0.0 {
                self.0.push(t);
            }
            self.1 = twist;
        }
    }
    let mut crossings = Crossings(Vec::new(), twist);
    sim.run_open_loop(&mut NoTorque, 1.0, &mut crossings)
        .unwrap();
    let c = &crossings.0;
    let period = (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64;
    let hz = 1.0 / period;
    assert!((hz / free_hz - 1.0).abs() < 1e-4, "{hz} Hz vs {free_hz} Hz");
    let drift = (d.energy(&sim.state()) - e0).abs() / e0;
    assert!(drift < 1e-9, "energy drift {drift:e}");
    // The axial slots stay at rest and the shaft follows the motor.
    let y = sim.state();
    assert_eq!((y[X_W], y[V_W]), (0.0, 0.0));
    assert_eq!((y[THETA_W], y[OMEGA_W]), (y[THETA_M], y[OMEGA_M]));
}

#[test]
fn the_two_mass_table_over_motor_response_peaks_at_the_motor_held_mode() {
    let mut p = presets::load("two-mass").unwrap();
    let held_hz = (p.kw / p.jt).sqrt() / (2.0 * PI);
    let m = modes::modes(&p).unwrap();
    assert_eq!(m.clamped_hz.len(), 1);
    assert!((m.clamped_hz[0] - held_hz).abs() < 1e-9 * held_hz);
    // The nonlinear frequency-response test (open loop, preset friction) peaks there.
    p.controller.motor_encoder_counts = 0.0;
    let test = FrequencyTest {
        amplitude_nm: 0.5,
        ..Default::default()
    };
    let gain = |hz: f64| simulate_point(&p, hz, &test).unwrap().gain_db;
    let (below, at, above) = (gain(0.8 * held_hz), gain(held_hz), gain(1.25 * held_hz));
    assert!(
        at > below + 10.0 && at > above + 10.0,
        "{below} {at} {above} dB"
    );
}

#[test]
fn a_direct_drive_under_half_its_friction_does_not_creep() {
    for p in [presets::load("direct-drive").unwrap(), emps_axis()] {
        // As a parameter and as an external load: both act on the one body.
        let mut q = p.clone();
        q.tload = 0.5 * p.ft;
        for (params, load) in [(&q, 0.0), (&p, 0.5 * p.ft)] {
            let mut sim = Simulation::with_default_step(params).unwrap();
            sim.set_load(load);
            sim.run_open_loop(&mut NoTorque, 1.0, &mut NullRecorder)
                .unwrap();
            let y = sim.state();
            assert_eq!((y[THETA_T], y[OMEGA_T]), (0.0, 0.0), "{}", p.name);
            assert_eq!(sim.stuck(), [true; 3], "{}", p.name);
        }
    }
}

#[test]
fn a_direct_drive_above_its_friction_accelerates_at_t_minus_fc_over_j() {
    let mut p = presets::load("direct-drive").unwrap();
    p.ct = 0.0;
    let torque = 3.0 * p.ft;
    let mut sim = Simulation::with_default_step(&p).unwrap();
    let mut step = Step {
        torque_nm: torque,
        at_s: 0.0,
    };
    sim.run_open_loop(&mut step, 0.5, &mut NullRecorder)
        .unwrap();
    let expected = (torque - p.ft) / p.jt * sim.time();
    let y = sim.state();
    assert!(
        (y[OMEGA_T] / expected - 1.0).abs() < 1e-12,
        "{}",
        y[OMEGA_T]
    );
    assert_eq!((y[THETA_M], y[OMEGA_M]), (y[THETA_T], y[OMEGA_T]));
    // Tload in the positive sense adds to a positive torque.
    p.tload = p.ft;
    let mut sim = Simulation::with_default_step(&p).unwrap();
    sim.run_open_loop(&mut step, 0.5, &mut NullRecorder)
        .unwrap();
    let with_load = (torque + p.tload - p.ft) / p.jt * sim.time();
    assert!((sim.state()[OMEGA_T] / with_load - 1.0).abs() < 1e-12);
}

/// The table position held by the servo at reference 0, averaged over the last
/// 0.2 s of `seconds`.
fn held_position(p: &Params, seconds: f64) -> f64 {
    let mut sim = Simulation::with_default_step(p).unwrap();
    let mut controller = sim.controller(p).unwrap();
    let mut trace = Trace::every(10);
    sim.run_closed_loop(&mut controller, &|_t: f64| 0.0, seconds, &mut trace)
        .unwrap();
    let tail: Vec<f64> = trace
        .samples
        .iter()
        .filter(|s| s.t > seconds - 0.2)
        .map(|s| s.y[THETA_T])
        .collect();
    tail.iter().sum::<f64>() / tail.len() as f64
}

#[test]
fn tload_moves_the_servo_equilibrium_by_tload_over_the_servo_stiffness() {
    // P position, P velocity loop: at rest the output is Kvp·Kpp·(r − q), so the
    // drive holds a load T at q − r = T/(drive_gain·Kvp·Kpp) (ratio 1, friction 0).
    let mut rotary = presets::load("direct-drive").unwrap();
    rotary.controller.kvi = 0.0;
    let mut linear = emps_axis();
    linear.tload = 100.0;
    for mut p in [rotary, linear] {
        p.ft = 0.0;
        if p.axis == Axis::Rotary {
            p.tload = 5.0;
        }
        let c = &p.controller;
        let stiffness = c.drive_gain * c.kvp * c.kpp;
        let expected = p.tload / stiffness;
        let quantum = c.motor_quantum();
        let held = held_position(&p, 1.0);
        eprintln!(
            "{}: held at {held:.4e} with Tload {} (expected {expected:.4e}, quantum {quantum:.1e})",
            p.name, p.tload
        );
        assert!(
            expected > 50.0 * quantum,
            "the offset is many encoder counts"
        );
        assert!(
            (held - expected).abs() < 2.0 * quantum,
            "{held} vs {expected}"
        );
        // A position integrator holds the load without offset.
        p.controller.kpi = 0.2 * p.controller.kpp * p.controller.kpp;
        let held = held_position(&p, 2.0);
        assert!(held.abs() < 2.0 * quantum, "{}: {held}", p.name);
    }
}

#[test]
fn the_new_presets_settle_a_step_in_both_loops() {
    for name in ["direct-drive", "two-mass"] {
        for mode in [
            rtid::model::LoopMode::SemiClosed,
            rtid::model::LoopMode::FullClosed,
        ] {
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
            sim.run_closed_loop(&mut controller, &step, 3.0, &mut trace)
                .unwrap();
            let tail: Vec<f64> = trace
                .samples
                .iter()
                .filter(|s| s.t >= 2.5)
                .map(|s| s.y[THETA_T])
                .collect();
            let (lo, hi) = tail
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
            let quantum = p.controller.table_encoder_resolution;
            // In semi-closed loop the two-mass table may stop anywhere within the
            // coupling twist its friction holds, ±ft/Kw (45″ for the preset).
            let twist = if name == "two-mass" && mode == rtid::model::LoopMode::SemiClosed {
                p.ft / p.kw
            } else {
                0.0
            };
            let error = tail[tail.len() - 1] - target;
            let bound = twist + 3.0 * quantum.max(p.controller.motor_quantum());
            assert!(
                error.abs() < bound,
                "{name} {mode}: final error {error} (bound {bound})"
            );
            assert!(
                hi - lo < 2.0 * quantum,
                "{name} {mode}: moves {} at rest",
                hi - lo
            );
            let peak = trace
                .samples
                .iter()
                .map(|s| s.y[THETA_T])
                .fold(f64::MIN, f64::max);
            assert!(peak < 1.01 * target, "{name} {mode}: overshoot to {peak}");
        }
    }
}

#[test]
fn the_positioning_test_runs_on_every_topology() {
    // Two targets, one run: the initial state (at rest at the first stop) is set by
    // the model's rest state, whatever the layout.
    let test = PositioningTest {
        targets: vec![0.0, 10f64.to_radians()],
        runs: 1,
        ..Default::default()
    };
    for name in ["worm-gear", "roller-gear-cam", "direct-drive", "two-mass"] {
        let p = presets::load(name).unwrap();
        let readings = positioning::run(&p, &test, |_, _| {}).unwrap();
        assert_eq!(readings.len(), 4, "{name}");
        // The worm's lost motion is ±16″; the two-mass table stops within the
        // friction twist ±ft/Kw = ±45″ of the motor; the others within a few counts.
        let bound = match p.topology {
            Topology::TwoMass => (p.ft / p.kw).to_degrees() * 3600.0 + 5.0,
            _ => 40.0,
        };
        for r in &readings {
            let error = r.deviation.abs().to_degrees() * 3600.0;
            assert!(error < bound, "{name}: {r:?}");
        }
    }
}

#[test]
fn parameters_that_do_not_apply_are_refused_by_name() {
    let mut dd = presets::load("direct-drive").unwrap();
    assert_eq!(
        dd.set("Kw", 3e5),
        Err(ParamError::NotApplicable { name: "Kw" })
    );
    assert_eq!(dd.get("Jm").unwrap(), None);
    assert_eq!(dd.ratio(), 1.0);
    dd.kw = 3e5;
    assert_eq!(dd.validate(), Err(ParamError::NotApplicable { name: "Kw" }));

    let mut two = presets::load("two-mass").unwrap();
    assert_eq!(
        two.set("Kb", 1e7),
        Err(ParamError::NotApplicable { name: "Kb" })
    );
    assert_eq!(two.get("Kw").unwrap(), Some(two.kw));
    two.rw = 2.0;
    assert_eq!(
        two.validate(),
        Err(ParamError::NotApplicable { name: "Rw" })
    );

    let mut linear = emps_axis();
    assert_eq!(linear.topology, Topology::DirectDrive);
    assert_eq!(
        linear.set("unbalance_mass", 1.0),
        Err(ParamError::NotForAxis {
            name: "unbalance_mass",
            axis: Axis::Linear
        })
    );
    linear.controller.motor_encoder_counts = 1024.0;
    assert!(matches!(
        linear.validate(),
        Err(ParamError::NotForAxis {
            name: "motor_encoder_counts",
            ..
        })
    ));
    let mut worm = presets::load("worm-gear").unwrap();
    worm.axis = Axis::Linear;
    assert_eq!(
        worm.validate(),
        Err(ParamError::LinearTopology {
            topology: Topology::SpurGear
        })
    );
    let mut both = presets::load("worm-gear").unwrap();
    both.controller.motor_encoder_resolution = 1e-6;
    let err = both.validate().unwrap_err().to_string();
    assert!(err.contains("motor_encoder_resolution"), "{err}");
    let mut switch = presets::load("worm-gear").unwrap();
    switch.controller.output_delay_periods = 0.5;
    let err = switch.validate().unwrap_err().to_string();
    assert!(
        err.contains("output_delay_periods = 0.5 must be 0 or 1"),
        "{err}"
    );
}

#[test]
fn a_file_missing_a_field_its_topology_needs_names_it() {
    let mut v = serde_json::to_value(presets::load("two-mass").unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("Jm");
    let err = rtid::io::params_file::parse(&v.to_string(), std::path::Path::new("t.json"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("t.json") && err.contains("missing field `Jm`") && err.contains("two_mass"),
        "{err}"
    );
    // The linear EMPS file gives its encoder in metres, and reads back equal.
    let p = emps_axis();
    let text = serde_json::to_string_pretty(&p).unwrap();
    assert!(text.contains("\"axis\": \"linear\"") && !text.contains("motor_encoder_counts"));
    let back = rtid::io::params_file::parse(&text, std::path::Path::new("e.json")).unwrap();
    assert_eq!(back, p);
    assert_eq!(Drive::new(&p).unwrap().tload(), 3.1648);
}

/// A direct drive is one body: its table follows its motor at every frequency
/// (table/motor = 1), and its motor compliance is that of a free inertia with viscous
/// friction, 1/(−ω²J + iωC) — not a panic for a missing motor coordinate.
#[test]
fn the_linear_response_of_a_direct_drive_is_one_body() {
    use rtid::model::linear_response::{Channel, LinearResponse};
    let p = presets::load("direct-drive").unwrap();
    let ratio = LinearResponse::new(&p, Channel::TableOverMotor).unwrap();
    let compliance = LinearResponse::new(&p, Channel::MotorOverTorque).unwrap();
    for hz in [10.0, 100.0, 600.0] {
        let r = ratio.at(hz).unwrap();
        assert!(
            (r.re - 1.0).abs() < 1e-12 && r.im.abs() < 1e-12,
            "{hz} Hz: {r}"
        );
        let w = std::f64::consts::TAU * hz;
        let free = 1.0 / nalgebra::Complex::new(-w * w * p.jt, w * p.ct);
        let c = compliance.at(hz).unwrap();
        assert!(
            (c - free).norm() < 1e-9 * free.norm(),
            "{hz} Hz: {c} vs {free}"
        );
    }
}
