//! Physics the kernel must reproduce: modal frequencies, energy conservation, backlash
//! contact, Coulomb stick, the rigid limit, and the equivalence of the topologies.

use rtid::input::{NoTorque, Sine};
use rtid::model::modes;
use rtid::model::{idx::*, presets, Drive, Params, Topology, NSTATE};
use rtid::recorder::{NullRecorder, Recorder, Trace};
use rtid::sim::Simulation;

const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// A preset made conservative: no damping, no friction; backlash and fluctuation
/// kept unless `linear`.
fn conservative(name: &str, linear: bool) -> Params {
    let mut p = presets::load(name).unwrap();
    for n in ["Cm", "Cw", "Cb", "Ct", "Ciw", "fm", "fw", "ft"] {
        p.set(n, 0.0).unwrap();
    }
    if p.topology == Topology::SpurGear {
        p.set("Cig", 0.0).unwrap();
        if linear {
            p.set("theta_bg", 0.0).unwrap();
        }
    }
    if linear {
        p.theta_bw = 0.0;
        p.w = 0.0;
    }
    p
}

/// Generalised coordinates of the modal analysis → state slots.
fn slots(dofs: &[&str]) -> Vec<usize> {
    dofs.iter()
        .map(|d| match *d {
            "theta_m" => THETA_M,
            "theta_w" => THETA_W,
            "x_w" => X_W,
            "theta_t" => THETA_T,
            other => panic!("unknown dof {other}"),
        })
        .collect()
}

/// Frequency of a signal from its upward zero crossings (linear interpolation).
fn crossing_frequency(t: &[f64], x: &[f64]) -> f64 {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let mut ups = vec![];
    for i in 1..x.len() {
        let (a, b) = (x[i - 1] - mean, x[i] - mean);
        if a < 0.0 && b >= 0.0 {
            ups.push(t[i - 1] + (t[i] - t[i - 1]) * (-a) / (b - a));
        }
    }
    assert!(ups.len() > 10, "too few cycles");
    (ups.len() - 1) as f64 / (ups[ups.len() - 1] - ups[0])
}

#[test]
fn undamped_linear_model_oscillates_at_its_modal_frequencies() {
    for name in ["worm-gear", "roller-gear-cam"] {
        let p = conservative(name, true);
        let m = modes::modes(&p).unwrap();
        let map = slots(&m.free_dofs);
        for (f, shape) in m.free_hz.iter().zip(&m.free_shapes) {
            let mut sim = Simulation::with_default_step(&p).unwrap();
            let mut y = [0.0; NSTATE];
            for (&slot, &v) in map.iter().zip(shape) {
                y[slot] = 1e-4 * v;
            }
            sim.set_state(y);
            let mut trace = Trace::every(1);
            sim.run_open_loop(&mut NoTorque, 40.0 / f, &mut trace)
                .unwrap();
            // Follow the coordinate with the largest amplitude in this mode.
            let (k, _) = shape
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .unwrap();
            let t: Vec<f64> = trace.samples.iter().map(|s| s.t).collect();
            let x: Vec<f64> = trace.samples.iter().map(|s| s.y[map[k]]).collect();
            let measured = crossing_frequency(&t, &x);
            assert!(
                ((measured - f) / f).abs() < 1e-3,
                "{name}: mode {f:.2} Hz simulated at {measured:.3} Hz"
            );
        }
    }
}

#[test]
fn motor_held_modes_appear_when_the_motor_is_very_heavy() {
    let mut p = conservative("worm-gear", true);
    let m = modes::modes(&p).unwrap();
    p.jm = 1e6; // the motor barely moves: the clamped modes
    let held = modes::modes(&p).unwrap();
    for (a, b) in m.clamped_hz.iter().zip(&held.free_hz) {
        assert!(((a - b) / a).abs() < 1e-4, "{a} vs {b}");
    }
}

/// Relative energy drift over `duration` from state `y0`.
fn energy_drift(p: &Params, y0: [f64; NSTATE], duration: f64, dt: Option<f64>) -> f64 {
    let dt = dt.unwrap_or_else(|| rtid::sim::default_step(p).unwrap());
    let mut sim = Simulation::new(p, dt).unwrap();
    sim.set_state(y0);
    let drive = Drive::new(p).unwrap();
    let e0 = drive.energy(&sim.state());
    struct Worst<'a>(&'a Drive, f64, f64);
    impl Recorder for Worst<'_> {
        fn record(&mut self, _t: f64, y: &[f64; NSTATE], _u: f64) {
            self.2 = self.2.max((self.0.energy(y) - self.1).abs());
        }
    }
    let mut worst = Worst(&drive, e0, 0.0);
    sim.run_open_loop(&mut NoTorque, duration, &mut worst)
        .unwrap();
    worst.2 / e0
}

/// An initial twist of the drive: the table turned against a held shaft by `twist`,
/// the axial bearing and spur stage in the static equilibrium of that twist, so the
/// release excites the drive's modes as a twisted-and-let-go table does.
fn twisted(p: &Params, twist: f64) -> [f64; NSTATE] {
    let mut y = [0.0; NSTATE];
    // Series springs Kw and Kb·r²: the axial bearing takes its share of the twist.
    let kbr2 = p.kb * p.r * p.r;
    let torque = twist / (1.0 / p.kw + 1.0 / kbr2);
    y[X_W] = -torque / p.r / p.kb;
    y[THETA_T] = -twist - p.theta_bw.copysign(twist);
    y
}

#[test]
fn energy_is_conserved_without_damping_and_friction() {
    for (name, linear) in [("worm-gear", true), ("roller-gear-cam", true)] {
        let p = conservative(name, linear);
        let drift = energy_drift(&p, twisted(&p, 2e-4), 1.0, None);
        assert!(drift < 1e-5, "{name} linear={linear}: drift {drift:.3e}");
    }
    // Gear fluctuation W ≠ 0 (no backlash): e(θw) enters the mesh energy exactly.
    let mut p = conservative("worm-gear", true);
    p.w = 1.5e-5;
    let drift = energy_drift(&p, twisted(&p, 2e-4), 1.0, None);
    assert!(drift < 1e-5, "W ≠ 0: drift {drift:.3e}");
}

#[test]
fn contact_events_keep_the_integration_fourth_order() {
    // With backlash the table flies through the gap and hits the flanks ~900 times a
    // second. Steps split at each contact change keep RK4's order: halving dt
    // divides the drift by ~2⁵ (without event location it fell only ~2-4×). What
    // remains is RK4's dissipation of the 1.5 kHz axial mode that the impacts excite.
    let mut p = conservative("worm-gear", true);
    p.theta_bw = 8e-5;
    let y0 = twisted(&p, 2e-4);
    let coarse = energy_drift(&p, y0, 1.0, Some(5e-6));
    let fine = energy_drift(&p, y0, 1.0, Some(2.5e-6));
    assert!(
        coarse / fine > 16.0,
        "order lost: {coarse:.3e} → {fine:.3e}"
    );
    // Full nonlinear preset (both backlashes, W ≠ 0) at a fine step.
    let p = conservative("worm-gear", false);
    let drift = energy_drift(&p, twisted(&p, 2e-4), 1.0, Some(2.5e-6));
    assert!(drift < 1e-5, "nonlinear: drift {drift:.3e}");
}

#[test]
fn fluctuation_with_motion_conserves_energy() {
    // The shaft spinning through many fluctuation cycles: e(θw) does work on the
    // table and back; the total must still be conserved.
    let p = conservative("worm-gear", false);
    let mut y = twisted(&p, 2e-4);
    y[OMEGA_M] = 50.0;
    y[OMEGA_W] = 50.0 * 0.8;
    y[OMEGA_T] = 50.0 * p.ratio();
    let drift = energy_drift(&p, y, 1.0, None);
    assert!(drift < 1e-5, "drift {drift:.3e}");
}

#[test]
fn no_torque_crosses_a_dead_zone_inside_the_gap() {
    // Table spinning freely inside a wide gap: no torque, constant velocity.
    let mut p = conservative("worm-gear", true);
    p.theta_bw = 1e-2;
    let mut sim = Simulation::with_default_step(&p).unwrap();
    let mut y = [0.0; NSTATE];
    y[OMEGA_T] = 0.05; // crosses 5e-3 rad in 0.1 s, still inside the gap
    sim.set_state(y);
    let drive = Drive::new(&p).unwrap();
    struct Check<'a>(&'a Drive, f64);
    impl Recorder for Check<'_> {
        fn record(&mut self, _t: f64, y: &[f64; NSTATE], _u: f64) {
            self.1 = self.1.max(self.0.mesh_torques(y)[1].abs());
        }
    }
    let mut check = Check(&drive, 0.0);
    sim.run_open_loop(&mut NoTorque, 0.1, &mut check).unwrap();
    assert_eq!(check.1, 0.0);
    assert_eq!(sim.state()[OMEGA_T], 0.05);
}

#[test]
fn separating_teeth_never_pull() {
    // Worm preset with strong mesh damping, driven hard at a resonance so the teeth
    // hit and separate: the mesh torque never opposes the sign of the contact.
    let mut p = presets::load("worm-gear").unwrap();
    p.ciw = 20.0;
    p.cig = Some(5.0);
    let drive = Drive::new(&p).unwrap();
    struct Check<'a>(&'a Drive, usize);
    impl Recorder for Check<'_> {
        fn record(&mut self, _t: f64, y: &[f64; NSTATE], _u: f64) {
            let t = self.0.mesh_torques(y);
            let dz = self.0.mesh_deflections(y);
            for i in 0..2 {
                if dz[i] == 0.0 {
                    self.1 += 1;
                    assert_eq!(t[i], 0.0);
                } else {
                    assert!(
                        t[i] * dz[i] >= 0.0,
                        "mesh {i} pulls: T={} dz={}",
                        t[i],
                        dz[i]
                    );
                }
            }
        }
    }
    let mut sim = Simulation::with_default_step(&p).unwrap();
    let mut check = Check(&drive, 0);
    sim.run_open_loop(&mut Sine::new(250.0, 5.0, 0.0), 0.2, &mut check)
        .unwrap();
    assert!(
        check.1 > 100,
        "the teeth separated ({} samples in a gap)",
        check.1
    );
}

#[test]
fn a_table_under_half_its_friction_torque_does_not_creep() {
    for name in ["worm-gear", "roller-gear-cam"] {
        let p = presets::load(name).unwrap();
        let mut sim = Simulation::with_default_step(&p).unwrap();
        sim.set_load(0.5 * p.ft);
        // Let the drive settle into the load, then measure the creep.
        sim.run_open_loop(&mut NoTorque, 0.5, &mut NullRecorder)
            .unwrap();
        let before = sim.state()[THETA_T];
        sim.run_open_loop(&mut NoTorque, 1.0, &mut NullRecorder)
            .unwrap();
        let creep = (sim.state()[THETA_T] - before).abs() / ARCSEC;
        assert!(creep < 1e-3, "{name}: creeps {creep:.3e} arc-sec/s");
        assert!(sim.stuck()[2], "{name}: table stuck");
    }
}

#[test]
fn a_table_above_its_friction_torque_slides_with_exactly_fc_opposing() {
    // Inside a wide gap the table is a free body: Jt·ωt' = Tload − ft.
    let mut p = presets::load("worm-gear").unwrap();
    p.theta_bw = 1.0;
    p.ct = 0.0;
    let load = 2.0 * p.ft;
    let mut sim = Simulation::with_default_step(&p).unwrap();
    sim.set_load(load);
    sim.run_open_loop(&mut NoTorque, 0.2, &mut NullRecorder)
        .unwrap();
    let expected = (load - p.ft) / p.jt * sim.time();
    let got = sim.state()[OMEGA_T];
    assert!(
        ((got - expected) / expected).abs() < 1e-12,
        "{got} vs {expected}"
    );
    // And below the friction torque, in the same gap, it never starts.
    let mut sim = Simulation::with_default_step(&p).unwrap();
    sim.set_load(0.99 * p.ft);
    sim.run_open_loop(&mut NoTorque, 0.2, &mut NullRecorder)
        .unwrap();
    assert_eq!(sim.state()[OMEGA_T], 0.0);
}

#[test]
fn very_stiff_meshes_make_the_table_follow_the_motor_through_the_ratio() {
    for name in ["worm-gear", "roller-gear-cam"] {
        let mut p = presets::load(name).unwrap();
        p.kw *= 1e3;
        p.kb *= 1e3;
        p.theta_bw = 0.0;
        if p.topology == Topology::SpurGear {
            p.kg = Some(850.0 * 1e3);
            p.theta_bg = Some(0.0);
        }
        let mut sim = Simulation::with_default_step(&p).unwrap();
        let mut trace = Trace::every(100);
        sim.run_open_loop(&mut Sine::new(5.0, 2.0, 1.0), 0.1, &mut trace)
            .unwrap();
        let y = sim.state();
        let follow = y[THETA_M] * p.ratio();
        let rel = ((y[THETA_T] - follow) / follow).abs();
        assert!(
            rel < 1e-3,
            "{name}: table {} vs motor·ratio {follow} ({rel:.2e})",
            y[THETA_T]
        );
    }
}

#[test]
fn direct_topology_equals_a_very_stiff_spur_stage() {
    // Worm preset with a 1:1 spur stage of growing stiffness versus the same drive
    // with the motor coupled directly (shaft inertia, damping and friction merged).
    // No drive backlash: a table rattling in a gap is chaotic, so two equivalent
    // models part ways from any rounding difference.
    let difference = |kg: f64, friction: bool| {
        let mut spur = presets::load("worm-gear").unwrap();
        spur.rg = Some(1.0);
        spur.kg = Some(kg);
        spur.cig = Some(20.0);
        spur.theta_bg = Some(0.0);
        spur.theta_bw = 0.0;
        if !friction {
            (spur.fm, spur.fw, spur.ft) = (0.0, 0.0, 0.0);
        }
        let mut direct = spur.clone();
        direct.topology = Topology::Direct;
        (direct.kg, direct.rg, direct.cig, direct.theta_bg) = (None, None, None, None);
        direct.ranges.remove("theta_bg");
        let dt = rtid::sim::default_step(&spur).unwrap();
        let run = |p: &Params| {
            let mut sim = Simulation::new(p, dt).unwrap();
            let mut trace = Trace::every(20);
            sim.run_open_loop(&mut Sine::new(40.0, 3.0, 0.5), 0.25, &mut trace)
                .unwrap();
            trace.samples
        };
        let (a, b) = (run(&spur), run(&direct));
        let scale = a.iter().map(|s| s.y[THETA_T].abs()).fold(0.0, f64::max);
        a.iter()
            .zip(&b)
            .map(|(x, y)| (x.y[THETA_T] - y.y[THETA_T]).abs())
            .fold(0.0, f64::max)
            / scale
    };
    let (soft, stiff) = (difference(2e6, false), difference(2e7, false));
    assert!(
        soft < 1e-6 && stiff < soft / 5.0,
        "no friction: {soft:.2e}, {stiff:.2e}"
    );
    let (soft, stiff) = (difference(2e6, true), difference(2e7, true));
    assert!(
        soft < 2e-4 && stiff < soft,
        "friction: {soft:.2e}, {stiff:.2e}"
    );
}

#[test]
fn a_diverging_simulation_stops_with_time_and_state() {
    // Negative damping cannot be entered; a torque of 1e12 N·m drives the state past
    // any physical bound instead.
    let p = presets::load("worm-gear").unwrap();
    let mut sim = Simulation::with_default_step(&p).unwrap();
    let err = sim
        .run_open_loop(
            &mut rtid::input::Step {
                torque_nm: 1e12,
                at_s: 0.0,
            },
            1.0,
            &mut NullRecorder,
        )
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("simulation diverged at t = "), "{err}");
    assert!(err.contains("motor_velocity_rad_per_s"), "{err}");
}

#[test]
fn an_unbalanced_vertical_table_swings_conserving_energy() {
    // A 20 kg mass at 0.1 m on the table, no damping or friction: the whole drive
    // swings like a pendulum; gravity's work enters the energy balance exactly.
    let mut p = conservative("roller-gear-cam", true);
    p.unbalance_mass = 20.0;
    p.unbalance_radius = 0.1;
    p.unbalance_phase = 0.3; // released 0.3 rad from hanging straight down
    let drift = energy_drift(&p, [0.0; NSTATE], 1.0, None);
    assert!(drift < 1e-6, "drift {drift:.3e}");
    // Small swings: the table swings at √(m·g·e / J) with J the inertia seen at
    // the table (Jt + Jm/Rw²); the drive's compliance lowers that by (ω/ω_drive)²
    // ≈ 1.4e-4, inside the tolerance.
    p.unbalance_phase = 0.01;
    let mut sim = Simulation::with_default_step(&p).unwrap();
    let mut trace = Trace::every(10);
    sim.run_open_loop(&mut NoTorque, 40.0, &mut trace).unwrap();
    let t: Vec<f64> = trace.samples.iter().map(|s| s.t).collect();
    let x: Vec<f64> = trace.samples.iter().map(|s| s.y[THETA_T]).collect();
    let j = p.jt + p.jm / (p.rw * p.rw);
    let expected = (20.0 * 9.80665 * 0.1 / j).sqrt() / std::f64::consts::TAU;
    let measured = crossing_frequency(&t, &x);
    assert!(
        ((measured - expected) / expected).abs() < 1e-3,
        "{measured} vs {expected} Hz"
    );
}
