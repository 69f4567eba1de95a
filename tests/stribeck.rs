//! The Stribeck law in the kernel (docs/model.md §2): a body at rest holds up to its
//! static level fc + rise, a sliding one meets fc + rise·exp(−(|ω|/vs)^δ) evaluated at
//! each stage (so the integration stays fourth order while the body slides), and the
//! steady speed under a constant torque is where the torque meets the curve.

use rtid::input::{NoTorque, Sine};
use rtid::model::{idx::*, presets, Params};
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;

/// The direct drive with a Stribeck law on its one body: Coulomb 0.8 N·m, static 1.3,
/// Stribeck speed 0.4 rad/s, no viscous damping.
fn rigid_stribeck(shape: f64) -> Params {
    let mut p = presets::load("direct-drive").unwrap();
    (p.ft, p.fst, p.vst, p.stribeck_shape, p.ct) = (0.8, 0.5, 0.4, shape, 0.0);
    p.validate().unwrap();
    p
}

fn level(p: &Params, w: f64) -> f64 {
    p.ft + p.fst * (-(w.abs() / p.vst).powf(p.stribeck_shape)).exp()
}

/// The table speed after `duration` s under the constant motor torque `torque`.
fn speed_after(p: &Params, dt: f64, torque: f64, duration: f64) -> f64 {
    let mut sim = Simulation::new(p, dt).unwrap();
    sim.run_open_loop(
        &mut Sine::new(1.0, 0.0, torque),
        duration,
        &mut NullRecorder,
    )
    .unwrap();
    sim.state()[OMEGA_T]
}

#[test]
fn a_body_holds_up_to_its_static_level_and_breaks_away_above_it() {
    let p = rigid_stribeck(2.0);
    // Above the Coulomb level but below the static one: it never starts.
    assert_eq!(speed_after(&p, 1e-4, 1.25, 0.5), 0.0);
    assert_eq!(speed_after(&p, 1e-4, -1.25, 0.5), 0.0);
    // Above the static level it breaks away, in the torque's direction.
    assert!(speed_after(&p, 1e-4, 1.35, 0.5) > 0.0);
    assert!(speed_after(&p, 1e-4, -1.35, 0.5) < 0.0);
}

const DTS: [f64; 3] = [0.04, 0.02, 0.01];

#[test]
fn the_sliding_friction_follows_the_curve_to_fourth_order() {
    // From rest under 1.4 N·m: Jt·ω' = 1.4 − f(ω), f falling from 1.3 to 0.8 — the
    // body accelerates ever faster as the friction falls away. A scalar RK4 of the
    // same equation at a tiny step is the reference; halving the kernel's step must
    // cut its error about 16-fold (a level held over each step would give 2-fold).
    // (With a δ that is not a whole number, ω^δ is not smooth at rest and the error
    // of a run from a break-away falls as dt^(1+δ): measured ratios 5.6 for δ = 1.5
    // and 3.4 for δ = 0.7, 2^2.5 and 2^1.7 — the law's, not the integrator's.)
    for shape in [2.0, 1.0] {
        let p = rigid_stribeck(shape);
        let (torque, duration) = (1.4f64, 0.2f64);
        let reference = {
            let (mut w, h) = (0.0f64, 1e-6);
            let f = |w: f64| (torque - level(&p, w)) / p.jt;
            for _ in 0..(duration / h).round() as usize {
                let k1 = f(w);
                let k2 = f(w + 0.5 * h * k1);
                let k3 = f(w + 0.5 * h * k2);
                let k4 = f(w + h * k3);
                w += h / 6.0 * (k1 + 2.0 * (k2 + k3) + k4);
            }
            w
        };
        let errors: Vec<f64> = [DTS[0], DTS[1], DTS[2]]
            .iter()
            .map(|&dt| (speed_after(&p, dt, torque, duration) - reference).abs())
            .collect();
        let (first, second) = (errors[0] / errors[1], errors[1] / errors[2]);
        assert!(
            first > 10.0 && second > 10.0,
            "δ = {shape}: errors {errors:?} (ratios {first:.1}, {second:.1}) — not fourth order"
        );
    }
}

#[test]
fn the_steady_speed_is_where_the_torque_meets_the_curve() {
    // With viscous damping the body settles where T = Ct·ω + f(ω) (time constant
    // Jt/Ct = 1 s: after 40 s the transient is e^-40 of its start).
    let mut p = rigid_stribeck(2.0);
    p.ct = 0.5;
    let torque = 1.6;
    let w = speed_after(&p, 1e-4, torque, 40.0);
    let residual = torque - p.ct * w - level(&p, w);
    assert!(
        w > 1.0 && residual.abs() < 1e-9,
        "ω = {w}, residual {residual:e}"
    );
}

#[test]
fn every_topology_runs_the_law_on_each_of_its_bodies() {
    // A Stribeck rise on the motor (and shaft) slows the free run of each drive under
    // the same torque, and a rise of 0 gives the Coulomb drive bit for bit.
    for name in ["worm-gear", "roller-gear-cam", "two-mass", "direct-drive"] {
        let plain = presets::load(name).unwrap();
        let run = |p: &Params| {
            let mut sim = Simulation::with_default_step(p).unwrap();
            let torque = 3.0 * (p.fm + p.ft);
            sim.run_open_loop(&mut Sine::new(1.0, 0.0, torque), 0.05, &mut NullRecorder)
                .unwrap();
            sim.run_open_loop(&mut NoTorque, 0.01, &mut NullRecorder)
                .unwrap();
            sim.state()
        };
        let mut zero_rise = plain.clone();
        (zero_rise.vst, zero_rise.stribeck_shape) = (0.3, 1.0);
        if name != "direct-drive" {
            zero_rise.vsm = 0.3;
        }
        assert_eq!(run(&plain), run(&zero_rise), "{name}");
        let mut rising = plain.clone();
        let body = if name == "direct-drive" { "fst" } else { "fsm" };
        let level = if name == "direct-drive" {
            plain.ft
        } else {
            plain.fm
        };
        rising.set(body, level).unwrap();
        rising.set(&body.replace('f', "v"), 5.0).unwrap();
        if name == "worm-gear" {
            (rising.fsw, rising.vsw) = (plain.fw, 5.0);
        }
        rising.validate().unwrap();
        let (a, b) = (run(&plain), run(&rising));
        assert!(
            b[OMEGA_M].abs() < a[OMEGA_M].abs(),
            "{name}: {} with the rise, {} without",
            b[OMEGA_M],
            a[OMEGA_M]
        );
    }
}

#[test]
fn a_rise_without_a_speed_is_refused_naming_both() {
    let mut p = presets::load("worm-gear").unwrap();
    p.fst = 0.1;
    let e = p.validate().unwrap_err().to_string();
    assert!(e.contains("vst") && e.contains("fst"), "{e}");
    let mut q = presets::load("roller-gear-cam").unwrap();
    assert!(
        q.set("fsw", 0.1).is_err(),
        "fsw applies to the spur gear only"
    );
}

#[test]
fn a_stribeck_rise_on_the_table_widens_the_worms_reversal_value() {
    // The sweep output `reversal` (ISO 230-2 mean reversal B̄ of the positioning test)
    // against the table's Stribeck rise: a higher static level holds the table longer
    // at each reversal, so the lost motion grows (measured 35.5 → 37.6 arc-sec from
    // fst = 0 to 0.3 N·m at vst = 0.02 rad/s).
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args([
            "sweep",
            "--preset",
            "worm-gear",
            "--set",
            "vst=0.02",
            "--vary",
            "fst=0..0.3:3",
            "--outputs",
            "reversal",
            "--out",
            "rev.csv",
            "--quiet",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(dir.path().join("rev.csv")).unwrap();
    let reversal: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("index"))
        .map(|l| l.split(',').nth(2).unwrap().parse::<f64>().unwrap().abs())
        .collect();
    assert_eq!(reversal.len(), 3);
    assert!(
        reversal[0] < reversal[1] && reversal[1] < reversal[2] && reversal[2] - reversal[0] > 1.0,
        "{reversal:?} arc-sec"
    );
}
