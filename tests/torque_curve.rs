//! The virtual friction-torque test (paper §4.2, docs/experiments.md (friction torque curve)) on both presets: the
//! torque it records is the physics of the drive as seen by the motor.

use std::f64::consts::TAU;
use std::process::Command;

use rtid::experiments::torque_curve::{self, evaluate, run, simulate_torque, TorqueTest};
use rtid::io::experiment_file;
use rtid::model::{presets, Params};

const PRESETS: [&str; 2] = ["worm-gear", "roller-gear-cam"];

/// One recorded period: enough for two velocity reversals, and quick.
fn one_period() -> TorqueTest {
    TorqueTest {
        periods: 1.0,
        ..Default::default()
    }
}

/// Motor-side inertia J_eff = Jm + Jw·Rg² + Jt·(Rg·Rw)² (the roller: Rg = 1, Jw = 0).
fn j_eff(p: &Params) -> f64 {
    let rg = p.rg.unwrap_or(1.0);
    p.jm + p.jw * rg * rg + p.jt * p.ratio() * p.ratio()
}

/// Coulomb friction referred to the motor: fm + fw·Rg + ft·Rg·Rw (roller: fm + ft·Rw).
fn motor_friction(p: &Params) -> f64 {
    p.fm + p.fw * p.rg.unwrap_or(1.0) + p.ft * p.ratio()
}

#[test]
fn without_friction_the_torque_is_the_inertia_torque_of_the_commanded_motion() {
    let test = one_period();
    for name in PRESETS {
        let mut p = presets::load(name).unwrap();
        (p.fm, p.fw, p.ft) = (0.0, 0.0, 0.0);
        (p.cm, p.cw, p.ct) = (0.0, 0.0, 0.0);
        // Backlash off too: with free play the flanks change at every reversal of the
        // acceleration, a shock of up to 35 % of the peak that is not inertia torque.
        p.theta_bw = 0.0;
        p.theta_bg = p.theta_bg.map(|_| 0.0);
        let curve = run(&p, &test, |_, _| {}).unwrap();
        // θt = A·sin(ωt) ⇒ T = J_eff·θ̈m = −J_eff·A·ω²·sin(ωt)/(Rg·Rw); the recorded
        // time restarts after a whole period, so the phase is the command's. The servo
        // has no feed-forward: its P position loop makes the table follow the command
        // through Kpp/(s + Kpp), i.e. gain 1/√(1 + (ω/Kpp)²) and lag atan(ω/Kpp) =
        // 0.070 rad here — 7 % of the peak as a pointwise difference.
        let w = TAU / test.period;
        let peak = j_eff(&p) * test.amplitude * w * w / p.ratio();
        let x = w / p.controller.kpp;
        let (gain, lag) = (1.0 / (1.0 + x * x).sqrt(), x.atan());
        // The fundamental (least squares over the one recorded period) is that lagged
        // inertia torque: amplitude within 1 %, phase within 0.01 rad.
        let n = curve.time.len() - 1;
        let (mut a, mut b) = (0.0, 0.0);
        for (&t, &tau) in curve.time.iter().zip(&curve.motor_torque).take(n) {
            a += 2.0 * tau * (w * t).sin() / n as f64;
            b += 2.0 * tau * (w * t).cos() / n as f64;
        }
        let (amplitude, phase) = (a.hypot(b), b.atan2(-a));
        // Pointwise, what is left is the velocity loop acting on the quantised motor
        // encoder: one count per control period is a velocity step of
        // 2π/(counts·Tc), i.e. a torque step of Kvp times that (0.007 N·m for the worm,
        // 0.022 for the roller); allowed on top of 3 % of the peak.
        let c = &p.controller;
        let ripple = c.kvp * TAU / (c.motor_encoder_counts * c.tc);
        let worst = curve
            .time
            .iter()
            .zip(&curve.motor_torque)
            .map(|(&t, &tau)| (tau + peak * gain * (w * t - lag).sin()).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: inertia peak {peak:.4} N·m; fundamental {:.4} of it, lag {phase:.4} rad \
             (expected {gain:.4}, {lag:.4}); worst deviation from the lagged command \
             {worst:.4} N·m (encoder ripple {ripple:.4})",
            amplitude / peak
        );
        assert!(
            (amplitude - gain * peak).abs() < 0.01 * peak,
            "{name}: {amplitude}"
        );
        assert!((phase - lag).abs() < 0.01, "{name}: phase {phase} vs {lag}");
        assert!(
            worst < 0.03 * peak + ripple,
            "{name}: {worst} vs peak {peak}"
        );
    }
}

#[test]
fn the_jump_at_each_velocity_reversal_is_twice_the_motor_side_coulomb_friction() {
    let test = TorqueTest::default();
    for name in PRESETS {
        let p = presets::load(name).unwrap();
        let report = evaluate(&run(&p, &test, |_, _| {}).unwrap(), &test).unwrap();
        // Across a reversal every body's Coulomb torque flips sign; at the motor they
        // add up to F = fm + fw·Rg + ft·Rg·Rw, so the torque jumps by 2F. The estimate
        // (lines fitted beside the stick transition, extrapolated to the reversal)
        // keeps ~2 % of the viscous and servo-lag curvature: 5 % tolerance.
        let expected = motor_friction(&p);
        let got = report.friction_nm.expect("reversals found");
        eprintln!(
            "{name}: RMS {:.4} N·m, peak {:.4} N·m, friction {got:.4} N·m (expected {expected:.4}), {} reversals",
            report.rms_nm,
            report.peak_nm,
            report.reversals.len()
        );
        assert_eq!(report.reversals.len(), 4);
        assert!(
            (got - expected).abs() < 0.05 * expected,
            "{name}: {got} vs {expected}"
        );
        for r in &report.reversals {
            assert!(
                (r.jump_nm.abs() - 2.0 * expected).abs() < 0.1 * expected,
                "{r:?}"
            );
        }
    }
}

#[test]
fn more_table_friction_raises_the_rms_torque_and_the_friction_estimate() {
    let test = one_period();
    for name in PRESETS {
        let p = presets::load(name).unwrap();
        let mut q = p.clone();
        q.ft += 2.0;
        let a = evaluate(&run(&p, &test, |_, _| {}).unwrap(), &test).unwrap();
        let b = evaluate(&run(&q, &test, |_, _| {}).unwrap(), &test).unwrap();
        let rise = b.friction_nm.unwrap() - a.friction_nm.unwrap();
        let expected = 2.0 * p.ratio();
        eprintln!(
            "{name}: ft + 2 N·m: RMS {:.4} → {:.4} N·m, friction +{rise:.4} (expected +{expected:.4})",
            a.rms_nm, b.rms_nm
        );
        assert!(b.rms_nm > a.rms_nm, "{name}: {} → {}", a.rms_nm, b.rms_nm);
        assert!((rise - expected).abs() < 0.15 * expected, "{name}: {rise}");
    }
}

#[test]
fn simulate_torque_reproduces_the_recorded_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = presets::load("roller-gear-cam").unwrap();
    let test = one_period();
    let path = dir.path().join("torque_curve.json");
    let mut manifest = torque_curve::manifest(&p, &test);
    manifest.data = Some("torque_curve.csv".into());
    let curve = run(&p, &test, |_, _| {}).unwrap();
    experiment_file::write(&path, &manifest, &torque_curve::to_data(&curve, p.axis)).unwrap();
    let exp = experiment_file::read(&path).unwrap();
    let file = torque_curve::from_data(&exp.data).unwrap();
    // The conditions as the identification will see them: from the manifest.
    let conditions = TorqueTest::from_conditions(&exp.manifest.conditions);
    let sim = simulate_torque(&p, &conditions, &file.time).unwrap();
    let worst = sim
        .iter()
        .zip(&file.motor_torque)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert_eq!(sim.len(), file.time.len());
    assert!(worst < 1e-12, "worst difference {worst} N·m");
    // Between samples: linear interpolation of the neighbours.
    let mid = simulate_torque(&p, &conditions, &[0.0105]).unwrap()[0];
    let (a, b) = (file.motor_torque[10], file.motor_torque[11]);
    assert!((mid - 0.5 * (a + b)).abs() < 1e-9, "{mid} vs {a}, {b}");
}

#[test]
fn the_cli_writes_and_evaluates_and_a_malformed_file_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let rtid = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_rtid"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap()
    };
    let out = rtid(&[
        "experiment",
        "torque-curve",
        "--preset",
        "roller-gear-cam",
        "--periods",
        "1",
        "--out",
        "run",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["kind"], "torque_curve");
    assert!(v["friction_nm"].as_f64().unwrap() > 0.1);
    for f in ["torque_curve.json", "torque_curve.csv", "torque_curve.svg"] {
        assert!(dir.path().join("run").join(f).is_file(), "{f}");
    }
    // Time that does not increase, on line 4 of the CSV.
    std::fs::write(
        dir.path().join("bad.json"),
        r#"{"kind": "torque_curve", "data": "bad.csv"}"#,
    )
    .unwrap();
    std::fs::write(
        dir.path().join("bad.csv"),
        "time_s,motor_torque_nm\n0.0,1.0\n0.001,1.1\n0.001,1.2\n",
    )
    .unwrap();
    let out = rtid(&["evaluate", "bad.json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("bad.csv") && err.contains("line 4"), "{err}");
}
