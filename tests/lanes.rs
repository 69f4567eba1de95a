//! Lockstep lanes compute exactly what lone simulations compute: a `LaneSimulation<8>`
//! (a `Kernel<8>`) against eight `Simulation`s (`Kernel<1>`), bit for bit, with
//! contact events, stick and fluctuation resynchronisations happening in different
//! lanes at different steps — of one model, and of eight parameter sets (every
//! number of the model different in every lane); and a batched sweep against
//! `simulate_point`.

use rtid::experiments::frequency_response::{simulate_point, sweep, FrequencyTest};
use rtid::experiments::positioning;
use rtid::experiments::torque_curve::{simulate_torque, simulate_torque_batch, TorqueTest};
use rtid::input::{Sine, TorqueInput};
use rtid::model::{idx::*, presets, Params, NSTATE};
use rtid::recorder::Recorder;
use rtid::sim::{LaneSimulation, Simulation};
use rtid::sweep::TestLength;

const DT: f64 = 1e-5;

/// One lane's run: frequency, amplitude and offset of the motor torque, table
/// load, initial state.
#[derive(Clone, Copy)]
struct Case {
    hz: f64,
    amplitude: f64,
    offset: f64,
    load: f64,
    y0: [f64; NSTATE],
}

/// Counts of steps with a body stuck, and the trajectory, of a lone simulation.
struct Lone {
    states: Vec<[f64; NSTATE]>,
    stuck_steps: usize,
    events: u64,
}

fn lone(p: &Params, c: &Case, steps: usize) -> Lone {
    struct Keep(Vec<[f64; NSTATE]>);
    impl Recorder for Keep {
        fn record(&mut self, _t: f64, y: &[f64; NSTATE], _u: f64) {
            self.0.push(*y);
        }
    }
    let mut sim = Simulation::new(p, DT).unwrap();
    sim.set_state(c.y0);
    sim.set_load(c.load);
    let mut input = Sine::new(c.hz, c.amplitude, c.offset);
    let mut keep = Keep(Vec::new());
    let mut stuck_steps = 0;
    for _ in 0..steps {
        sim.run_open_loop(&mut input, DT, &mut keep).unwrap();
        stuck_steps += usize::from(sim.stuck().iter().any(|&s| s));
    }
    // The first record is the initial state.
    keep.0.remove(0);
    Lone {
        states: keep.0,
        stuck_steps,
        events: sim.contact_events(),
    }
}

/// Eight sines from rest: lane `l` at `hz + l·dhz` Hz with amplitude `a + l·da`.
fn sines(hz: f64, dhz: f64, a: f64, da: f64) -> [Case; 8] {
    std::array::from_fn(|l| Case {
        hz: hz + dhz * l as f64,
        amplitude: a + da * l as f64,
        offset: 0.0,
        load: 0.0,
        y0: [0.0; NSTATE],
    })
}

fn compare(p: &Params, cases: &[Case; 8], steps: usize) -> Vec<Lone> {
    compare_sets(&std::array::from_fn(|_| p.clone()), cases, steps)
}

/// Lane `l` runs `params[l]` on `cases[l]`; every state of every step must equal
/// the lone run's bit for bit.
fn compare_sets(params: &[Params; 8], cases: &[Case; 8], steps: usize) -> Vec<Lone> {
    let mut lanes = LaneSimulation::<8>::of(params, DT).unwrap();
    for (l, c) in cases.iter().enumerate() {
        lanes.start(l, c.y0, c.load);
    }
    let mut inputs = cases.map(|c| Sine::new(c.hz, c.amplitude, c.offset));
    let lone: Vec<Lone> = (0..8).map(|l| lone(&params[l], &cases[l], steps)).collect();
    for k in 0..steps {
        let mut motor = [[0.0; 8]; 3];
        for (l, input) in inputs.iter_mut().enumerate() {
            let m = input.step_torques(lanes.time(l), DT);
            for s in 0..3 {
                motor[s][l] = m[s];
            }
        }
        lanes.step(&motor).unwrap();
        for (l, run) in lone.iter().enumerate() {
            let (a, b) = (lanes.state(l), run.states[k]);
            let same = (0..NSTATE).all(|i| a[i].to_bits() == b[i].to_bits());
            assert!(same, "step {k}, lane {l}: {a:?} in lanes, {b:?} alone");
        }
    }
    let events: u64 = lone.iter().map(|r| r.events).sum();
    assert_eq!(lanes.contact_events(), events, "same contact events");
    lone
}

#[test]
fn eight_lanes_equal_eight_lone_simulations() {
    let p = presets::load("worm-gear").unwrap();
    let base = Case {
        hz: 230.0,
        amplitude: 5.0,
        offset: 0.0,
        load: 0.0,
        y0: [0.0; NSTATE],
    };
    let mut fast = [0.0; NSTATE];
    // A shaft turning ~0.012 rad per step: the fluctuation phase is recomputed by
    // the library at every step of this lane only.
    fast[OMEGA_M] = 1500.0;
    fast[OMEGA_W] = 1200.0;
    fast[OMEGA_T] = 1200.0 / 72.0;
    let cases = [
        base,
        Case { hz: 180.0, ..base },
        Case {
            hz: 410.0,
            amplitude: 2.0,
            ..base
        },
        // Below the motor's friction: it sticks, then breaks away.
        Case {
            hz: 60.0,
            amplitude: 0.3,
            ..base
        },
        Case {
            hz: 95.0,
            amplitude: 0.12,
            offset: 0.05,
            ..base
        },
        // Preloaded: flanks loaded, fewer contact events.
        Case {
            hz: 250.0,
            offset: 2.0 * p.ratio(),
            load: -2.0,
            ..base
        },
        Case {
            hz: 300.0,
            amplitude: 8.0,
            y0: fast,
            ..base
        },
        // A table under a load within its friction band.
        Case {
            hz: 20.0,
            amplitude: 0.05,
            load: 0.1,
            ..base
        },
    ];
    let lone = compare(&p, &cases, 30_000);
    // The lanes really differ: events and stick at different steps.
    let events: Vec<u64> = lone.iter().map(|r| r.events).collect();
    let stuck: Vec<usize> = lone.iter().map(|r| r.stuck_steps).collect();
    eprintln!("events per lane {events:?}, steps with a body stuck {stuck:?}");
    assert!(events.iter().filter(|&&e| e > 0).count() >= 4, "{events:?}");
    assert!(events.windows(2).any(|w| w[0] != w[1]));
    assert!(stuck.iter().any(|&s| s > 0) && stuck.iter().any(|&s| s < 30_000));
    assert!(stuck.windows(2).any(|w| w[0] != w[1]), "{stuck:?}");
}

#[test]
fn lanes_of_the_direct_topology_with_unbalance_equal_lone_simulations() {
    let mut p = presets::load("roller-gear-cam").unwrap();
    p.unbalance_mass = 20.0;
    p.unbalance_radius = 0.1;
    let cases: [Case; 8] = std::array::from_fn(|l| Case {
        hz: 30.0 + 70.0 * l as f64,
        amplitude: 0.5 + l as f64,
        offset: 0.0,
        load: 0.0,
        y0: [0.0; NSTATE],
    });
    compare(&p, &cases, 20_000);
}

#[test]
fn a_batched_sweep_equals_lone_points() {
    // More frequencies than lanes, settling at different times: lanes are refilled.
    let p = presets::load("worm-gear").unwrap();
    let test = FrequencyTest {
        frequencies_hz: (0..19).map(|i| 40.0 + 29.0 * i as f64).collect(),
        max_duration_s: 0.12,
        refine_step_hz: 0.0,
        tolerance_db: 0.05,
        ..Default::default()
    };
    let batched = sweep(&p, &test, &|| {}).unwrap();
    assert_eq!(batched.len(), test.frequencies_hz.len());
    let durations: Vec<f64> = batched.iter().map(|q| q.simulated_s).collect();
    assert!(
        durations.windows(2).any(|w| w[0] != w[1]),
        "points settle at different times: {durations:?}"
    );
    for q in &batched {
        let alone = simulate_point(&p, q.frequency_hz, &test).unwrap();
        assert_eq!(*q, alone, "{} Hz", q.frequency_hz);
    }
}

#[test]
fn lanes_of_the_direct_drive_and_two_mass_topologies_equal_lone_simulations() {
    // Two-mass with backlash in the coupling, fluctuation and a constant load: contact
    // events, stick and phase resynchronisations in different lanes.
    let mut two_mass = presets::load("two-mass").unwrap();
    two_mass.theta_bw = 2e-4;
    two_mass.w = 1e-4;
    two_mass.tload = 2e-3;
    let cases: [Case; 8] = std::array::from_fn(|l| Case {
        hz: 20.0 + 9.0 * l as f64,
        amplitude: if l == 3 { 4e-3 } else { 0.02 + 0.01 * l as f64 },
        offset: 0.0,
        load: if l == 5 { -3e-3 } else { 0.0 },
        y0: [0.0; NSTATE],
    });
    let lone = compare(&two_mass, &cases, 20_000);
    let events: Vec<u64> = lone.iter().map(|r| r.events).collect();
    assert!(events.iter().filter(|&&e| e > 0).count() >= 4, "{events:?}");
    // The direct drive with unbalance and load: stick below the friction band.
    let mut direct = presets::load("direct-drive").unwrap();
    direct.unbalance_mass = 10.0;
    direct.unbalance_radius = 0.01;
    direct.tload = 0.3;
    let cases: [Case; 8] = std::array::from_fn(|l| Case {
        hz: 2.0 + 3.0 * l as f64,
        amplitude: 0.5 + 1.5 * l as f64,
        offset: 0.0,
        load: if l == 2 { 0.4 } else { 0.0 },
        y0: [0.0; NSTATE],
    });
    let lone = compare(&direct, &cases, 20_000);
    let stuck: Vec<usize> = lone.iter().map(|r| r.stuck_steps).collect();
    assert!(
        stuck.iter().any(|&s| s > 0) && stuck.windows(2).any(|w| w[0] != w[1]),
        "{stuck:?}"
    );
}

#[test]
fn lanes_with_a_stribeck_law_equal_lone_simulations() {
    // The worm with a Stribeck rise on every body, driven slowly enough that bodies
    // stick and break away at their static levels in different lanes, and the
    // direct drive's one body likewise.
    let mut worm = presets::load("worm-gear").unwrap();
    (worm.fsm, worm.vsm) = (0.5 * worm.fm, 2.0);
    (worm.fsw, worm.vsw) = (0.5 * worm.fw, 1.0);
    (worm.fst, worm.vst, worm.stribeck_shape) = (0.5 * worm.ft, 0.05, 1.0);
    let cases: [Case; 8] = std::array::from_fn(|l| Case {
        hz: 5.0 + 7.0 * l as f64,
        amplitude: 0.3 + 0.4 * l as f64,
        offset: 0.0,
        load: if l == 4 { 2.0 } else { 0.0 },
        y0: [0.0; NSTATE],
    });
    let lone = compare(&worm, &cases, 20_000);
    let stuck: Vec<usize> = lone.iter().map(|r| r.stuck_steps).collect();
    assert!(stuck.windows(2).any(|w| w[0] != w[1]), "{stuck:?}");
    let mut direct = presets::load("direct-drive").unwrap();
    (direct.fst, direct.vst) = (0.5, 0.2);
    let cases: [Case; 8] = sines(2.0, 3.0, 0.5, 1.5);
    let lone = compare(&direct, &cases, 20_000);
    let stuck: Vec<usize> = lone.iter().map(|r| r.stuck_steps).collect();
    assert!(stuck.iter().any(|&s| s > 0), "{stuck:?}");
}

/// The worm-gear preset with every number scaled in lane `l`'s own way: stiffnesses,
/// dampings, inertias, gaps, friction levels, fluctuation, unbalance and load.
fn varied_worm(l: usize) -> Params {
    let mut p = presets::load("worm-gear").unwrap();
    let f = 1.0 + 0.07 * l as f64;
    let g = 1.0 - 0.05 * l as f64;
    p.kw *= f;
    p.kg = p.kg.map(|k| k * g);
    p.kb *= g;
    p.ciw *= f;
    p.cig = p.cig.map(|c| c * f);
    (p.cm, p.cw, p.ct) = (p.cm * g, p.cw * f, p.ct * g);
    (p.jm, p.jw, p.jt) = (p.jm * f, p.jw * g, p.jt * f);
    (p.fm, p.fw, p.ft) = (p.fm * g, p.fw * f, p.ft * (1.0 + 0.3 * l as f64));
    p.theta_bw *= f;
    p.theta_bg = p.theta_bg.map(|b| b * g);
    p.w = 2e-5 * f;
    p.fluct_phase = 0.3 * l as f64;
    p.unbalance_mass = 5.0 + l as f64;
    p.unbalance_radius = 0.05;
    p.unbalance_phase = 0.2 * l as f64;
    p.tload = 0.1 * l as f64 - 0.35;
    p
}

#[test]
fn lanes_of_eight_parameter_sets_equal_their_lone_simulations() {
    // Every number of the worm-gear model differs between lanes; the lanes also
    // differ in their inputs, so events, stick and resynchronisations fall at
    // different steps.
    let params: [Params; 8] = std::array::from_fn(varied_worm);
    let cases: [Case; 8] = std::array::from_fn(|l| Case {
        hz: [230.0, 180.0, 60.0, 95.0, 250.0, 300.0, 20.0, 410.0][l],
        amplitude: [5.0, 5.0, 0.3, 0.12, 5.0, 8.0, 0.05, 2.0][l],
        offset: if l == 4 { 0.1 } else { 0.0 },
        load: if l == 6 { 0.1 } else { 0.0 },
        y0: [0.0; NSTATE],
    });
    let lone = compare_sets(&params, &cases, 20_000);
    let events: Vec<u64> = lone.iter().map(|r| r.events).collect();
    let stuck: Vec<usize> = lone.iter().map(|r| r.stuck_steps).collect();
    assert!(events.iter().filter(|&&e| e > 0).count() >= 4, "{events:?}");
    assert!(stuck.windows(2).any(|w| w[0] != w[1]), "{stuck:?}");
}

#[test]
fn lanes_of_different_stribeck_laws_and_direct_drives_equal_their_lone_simulations() {
    let worm: [Params; 8] = std::array::from_fn(|l| {
        let mut p = varied_worm(l);
        (p.fsm, p.vsm) = (0.2 * (l + 1) as f64 * p.fm, 0.5 + l as f64);
        (p.fst, p.vst) = (0.1 * (l + 1) as f64 * p.ft, 0.02 * (l + 1) as f64);
        p.stribeck_shape = [2.0, 1.0, 0.5, 1.5][l % 4];
        p
    });
    let slow: [Case; 8] = sines(5.0, 7.0, 0.3, 0.4);
    let lone = compare_sets(&worm, &slow, 20_000);
    let stuck: Vec<usize> = lone.iter().map(|r| r.stuck_steps).collect();
    assert!(stuck.windows(2).any(|w| w[0] != w[1]), "{stuck:?}");
    let direct: [Params; 8] = std::array::from_fn(|l| {
        let mut p = presets::load("direct-drive").unwrap();
        (p.jt, p.ct, p.ft) = (p.jt * (1.0 + 0.1 * l as f64), p.ct * 2.0, 0.2 * l as f64);
        (p.unbalance_mass, p.unbalance_radius) = (1.0 + l as f64, 0.01);
        p
    });
    let stuck: Vec<usize> = compare_sets(&direct, &slow, 20_000)
        .iter()
        .map(|r| r.stuck_steps)
        .collect();
    assert!(stuck.windows(2).any(|w| w[0] != w[1]), "{stuck:?}");
}

#[test]
fn parameter_sets_of_different_shapes_are_refused_with_the_lane() {
    let mut params: [Params; 8] = std::array::from_fn(varied_worm);
    params[5].theta_bw = 0.0;
    let err = LaneSimulation::<8>::of(&params, DT).unwrap_err();
    assert!(err.to_string().contains("lane 5"), "{err}");
}

#[test]
fn a_batch_of_positioning_tests_equals_its_lone_runs() {
    // Eight sets: stiffness, gains, friction, encoder and loop mode vary; one set has
    // no drive-mesh gap (another shape: it runs in a group of its own), one set's
    // servo is unstable (it diverges alone, the others go on).
    let test = TestLength::Short.positioning();
    let sets: Vec<Params> = (0..8)
        .map(|l| {
            let mut p = varied_worm(l % 4);
            p.controller.kvp *= 1.0 + 0.1 * l as f64;
            if l == 2 {
                p.theta_bw = 0.0;
            }
            if l == 5 {
                p.controller.kvp *= 1e4;
                p.controller.torque_limit = 1e12;
            }
            p
        })
        .collect();
    let batch = positioning::run_batch(&sets, &test);
    for (l, (p, got)) in sets.iter().zip(&batch).enumerate() {
        let alone = positioning::run(p, &test, |_, _| {});
        assert_eq!(got, &alone, "set {l}");
    }
    assert!(batch[5].is_err(), "the unstable servo diverges");
    assert!(batch.iter().filter(|r| r.is_ok()).count() == 7);
}

#[test]
fn the_torque_test_in_lanes_gives_each_set_its_lone_torque() {
    // Five sets: three of one shape (friction and stiffness differ), one without
    // the drive mesh's gap, one with a stiffer mesh (another step): batched by
    // shape and step, each must get its lone torque bit for bit.
    let test = TorqueTest {
        period: 0.5,
        run_in_periods: 1.0,
        ..TorqueTest::default()
    };
    let times: Vec<f64> = (0..200).map(|i| 0.0025 * i as f64 + 1e-4).collect();
    let sets: Vec<Params> = (0..5)
        .map(|l| {
            let mut p = varied_worm(l % 3);
            p.fm *= 1.0 + 0.2 * l as f64;
            if l == 3 {
                p.theta_bw = 0.0;
            }
            if l == 4 {
                p.kw *= 3.0;
            }
            p
        })
        .collect();
    let batch = simulate_torque_batch(&sets, &test, &times);
    for (l, (p, got)) in sets.iter().zip(&batch).enumerate() {
        let alone = simulate_torque(p, &test, &times).unwrap();
        assert_eq!(got.as_ref().unwrap(), &alone, "set {l}");
    }
    assert_ne!(batch[0], batch[1], "the sets differ");
}
