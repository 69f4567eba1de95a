//! `rtid tune` and `rtid::tuning` (docs/tuning.md): the tuned presets meet their
//! targets, the margins agree with an independent computation
//! (fixtures/tuning/generate.py, numpy), the command line writes a tuned parameter
//! file that loads and never writes over its input.

use rtid::io::params_file;
use rtid::model::{presets, SetpointFilter};
use rtid::tuning::search::Grid;
use rtid::tuning::{tune, Margins, Targets, VelocityLoop, VelocityPi};

use crate::cli_support::{err, ok, root, rtid};

fn expected() -> serde_json::Value {
    let path = root().join("fixtures/tuning/expected.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_tuned_presets_meet_their_targets() {
    for name in ["worm-gear", "two-mass"] {
        let p = presets::load(name).unwrap();
        for (pm, gm) in [(50.0, 6.0), (60.0, 10.0)] {
            let targets = Targets {
                phase_margin_deg: pm,
                gain_margin_db: gm,
            };
            let t = tune(&p, targets).unwrap();
            let m = t.after.velocity_loop;
            let got = m.phase_margin_deg.unwrap();
            assert!((got - pm).abs() <= 3.0, "{name} {pm}°: {m:?}");
            assert!(m.gain_margin_db.unwrap() >= gm, "{name} {gm} dB: {m:?}");
            // One notch per resonance below 0.8·Nyquist; the tuned file loads.
            assert_eq!(t.after.filters.len(), t.resonances.len(), "{name}");
            assert!(!t.resonances.is_empty(), "{name}");
            t.params.validate().unwrap();
        }
    }
}

/// rtid's margins of a setting recorded in expected.json.
fn margins_of(name: &str, setting: &serde_json::Value) -> Margins {
    let p = presets::load(name).unwrap();
    let filters: Vec<SetpointFilter> = serde_json::from_value(setting["filters"].clone()).unwrap();
    let lp = VelocityLoop::new(&p, &filters).unwrap();
    let pi = VelocityPi {
        kvp: setting["Kvp"].as_f64().unwrap(),
        kvi: setting["Kvi"].as_f64().unwrap(),
    };
    Grid::new(&lp).margins(pi)
}

#[test]
fn the_margins_agree_with_an_independent_numpy_computation() {
    let e = expected();
    for name in ["worm-gear", "two-mass"] {
        for which in ["before", "after"] {
            let case = &e[name][which];
            let m = margins_of(name, &case["setting"]);
            let want = &case["margins"];
            let close = |got: Option<f64>, field: &str, tol: f64| {
                let w = want[field].as_f64().unwrap();
                let g = got.unwrap();
                assert!((g - w).abs() <= tol, "{name} {which} {field}: {g} vs {w}");
            };
            close(m.phase_margin_deg, "phase_margin_deg", 0.1);
            close(m.gain_margin_db, "gain_margin_db", 0.01);
            for (got, field) in [
                (m.crossover_hz, "crossover_hz"),
                (m.phase_margin_hz, "phase_margin_hz"),
                (m.gain_margin_hz, "gain_margin_hz"),
            ] {
                let w = want[field].as_f64().unwrap();
                close(got, field, 1e-4 * w);
            }
        }
    }
}

#[test]
fn the_recorded_tuning_is_what_rtid_tunes_today() {
    // expected.json's "after" settings came from `rtid tune --json`: the library
    // still tunes the same (a change of rule regenerates the fixture).
    let e = expected();
    for name in ["worm-gear", "two-mass"] {
        let t = tune(&presets::load(name).unwrap(), Targets::default()).unwrap();
        let s = &e[name]["after"]["setting"];
        for (got, field) in [(t.after.kvp, "Kvp"), (t.after.kvi, "Kvi")] {
            let w = s[field].as_f64().unwrap();
            assert!((got / w - 1.0).abs() < 1e-9, "{name} {field}: {got} vs {w}");
        }
    }
}

#[test]
fn the_command_writes_a_tuned_parameter_file_and_never_over_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = rtid(
        &["tune", "--preset", "two-mass", "--json", "-o", "tuned.json"],
        dir.path(),
    );
    let v: serde_json::Value = serde_json::from_str(&ok(&out)).unwrap();
    let p = params_file::read(&dir.path().join("tuned.json")).unwrap();
    assert_eq!(p.controller.kvp, v["after"]["Kvp"].as_f64().unwrap());
    assert_eq!(p.controller.kpp, v["after"]["Kpp"].as_f64().unwrap());
    assert_eq!(p.controller.filters.len(), 1);

    // Tuning the tuned file again finds the same gains (its notch is the same).
    let again = rtid(&["tune", "--params", "tuned.json", "--json"], dir.path());
    let w: serde_json::Value = serde_json::from_str(&ok(&again)).unwrap();
    let (a, b) = (&v["after"]["Kvp"], &w["after"]["Kvp"]);
    assert!((a.as_f64().unwrap() / b.as_f64().unwrap() - 1.0).abs() < 1e-9);
    let pm = w["before"]["velocity_loop"]["phase_margin_deg"]
        .as_f64()
        .unwrap();
    assert!((pm - 50.0).abs() < 1e-6, "{pm}");

    let over = rtid(
        &["tune", "--params", "tuned.json", "-o", "./tuned.json"],
        dir.path(),
    );
    assert!(err(&over).contains("input"), "{}", err(&over));

    let table = ok(&rtid(&["tune", "--preset", "worm-gear"], dir.path()));
    assert!(
        table.contains("phase margin") && table.contains("50.0°"),
        "{table}"
    );
}

#[test]
fn the_command_plots_the_open_loop_before_and_after_with_the_margins() {
    let dir = tempfile::tempdir().unwrap();
    let out = rtid(
        &[
            "tune", "--preset", "two-mass", "--json", "--plot", "loop.svg",
        ],
        dir.path(),
    );
    let v: serde_json::Value = serde_json::from_str(&ok(&out)).unwrap();
    let svg = std::fs::read_to_string(dir.path().join("loop.svg")).unwrap();
    assert!(svg.starts_with("<svg"));
    for s in [
        "L, before tuning",
        "L, after tuning",
        "before: phase margin",
        "after: phase margin",
        "after: gain margin",
        "frequency, Hz",
    ] {
        assert!(svg.contains(s), "{s}");
    }
    let pm = v["after"]["velocity_loop"]["phase_margin_deg"]
        .as_f64()
        .unwrap();
    assert!(svg.contains(&format!("phase margin {pm:.1}°")), "{pm}");

    // Never over an input or the parameter file written.
    std::fs::write(dir.path().join("p.json"), "{}").unwrap();
    let over = rtid(
        &["tune", "--params", "p.json", "--plot", "./p.json"],
        dir.path(),
    );
    assert!(err(&over).contains("input"), "{}", err(&over));
    let over = rtid(
        &[
            "tune", "--preset", "two-mass", "-o", "t.json", "--plot", "t.json",
        ],
        dir.path(),
    );
    err(&over);
    assert!(!dir.path().join("t.json").exists());
}

#[test]
fn an_unreachable_target_names_the_best() {
    let dir = tempfile::tempdir().unwrap();
    let out = rtid(
        &["tune", "--preset", "worm-gear", "--phase-margin-deg", "170"],
        dir.path(),
    );
    let e = err(&out);
    assert!(e.contains("170° ") && e.contains("the best is"), "{e}");
}

/// A 1° step command in the semi-closed loop for 1 s: the motor's (× Rg·Rw) time
/// after which it stays within 20″ of the target, s; its overshoot, fraction; and its
/// range over the last 0.3 s, arc-sec.
fn step_response(p: &rtid::Params) -> (f64, f64, f64) {
    use rtid::model::idx::THETA_M;
    const ARCSEC: f64 = std::f64::consts::PI / 180.0 / 3600.0;
    let mut sim = rtid::Simulation::with_default_step(p).unwrap();
    let mut controller = sim.controller(p).unwrap();
    let target = 1f64.to_radians();
    let step = rtid::Move {
        from: 0.0,
        to: target,
        speed: None,
    };
    let mut trace = rtid::recorder::Trace::every(1);
    sim.run_closed_loop(&mut controller, &step, 1.0, &mut trace)
        .unwrap();
    let motor: Vec<(f64, f64)> = trace
        .samples
        .iter()
        .map(|s| (s.t, s.y[THETA_M] * p.ratio()))
        .collect();
    let settled = motor
        .iter()
        .rev()
        .find(|(_, x)| (x - target).abs() > 20.0 * ARCSEC)
        .map_or(0.0, |(t, _)| *t);
    let peak = motor.iter().map(|m| m.1).fold(f64::MIN, f64::max);
    let tail: Vec<f64> = motor.iter().filter(|m| m.0 >= 0.7).map(|m| m.1).collect();
    let range = tail.iter().cloned().fold(f64::MIN, f64::max)
        - tail.iter().cloned().fold(f64::MAX, f64::min);
    (settled, peak / target - 1.0, range / ARCSEC)
}

#[test]
fn the_tuned_drives_settle_a_step_faster_on_the_nonlinear_model() {
    // docs/tuning.md: worm gear 186 → 38 ms, two-mass 564 → 133 ms to within 20″
    // (motor × Rg·Rw); overshoot 0 → 6.8 % (the step drives the worm gear's output
    // into its torque limit) and 0 → 0.9 %.
    for name in ["worm-gear", "two-mass"] {
        let p = presets::load(name).unwrap();
        let tuned = tune(&p, Targets::default()).unwrap().params;
        let (t0, over0, _) = step_response(&p);
        let (t1, over1, rest) = step_response(&tuned);
        assert!(
            t1 < t0 / 3.0,
            "{name}: settles in {t1} s, the preset in {t0} s"
        );
        assert!(over1 < 0.08 && over0 < 0.001, "{name}: {over0} → {over1}");
        // At rest: no limit cycle at the motor (two table-encoder counts).
        assert!(rest < 0.72, "{name}: moves {rest}″ at rest");
    }
}

/// `tune FIT.json --preset …` tunes the identified model: the base set with the fit's
/// values, as `--set` of each would.
#[test]
fn the_command_tunes_the_model_of_an_identification() {
    let dir = tempfile::tempdir().unwrap();
    let fit_path = root().join("fixtures/predict/worm-gear/fit.json");
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&fit_path).unwrap()).unwrap();
    let mut args = vec!["tune".to_string(), "--preset".into(), "worm-gear".into()];
    for (name, value) in fit["parameters"].as_object().unwrap() {
        args.extend(["--set".into(), format!("{name}={value}")]);
    }
    args.push("--json".into());
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let by_set = ok(&rtid(&refs, dir.path()));
    let by_fit = ok(&rtid(
        &[
            "tune",
            fit_path.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--json",
        ],
        dir.path(),
    ));
    assert_eq!(by_fit, by_set);
    let e = err(&rtid(
        &["tune", "missing.json", "--preset", "worm-gear"],
        dir.path(),
    ));
    assert!(e.contains("missing.json"), "{e}");
}

/// The command's own check on the nonlinear model: the tuned worm gear settles a 1°
/// step faster, follows a constant speed closer (v/Kpp), and says so in its JSON.
#[test]
fn the_command_checks_both_settings_on_the_nonlinear_model() {
    let dir = tempfile::tempdir().unwrap();
    let out = ok(&rtid(
        &["tune", "--preset", "worm-gear", "--json"],
        dir.path(),
    ));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (b, a) = (&v["verification"]["before"], &v["verification"]["after"]);
    let f = |x: &serde_json::Value, k: &str| x[k].as_f64().unwrap();
    assert!(
        f(a, "step_settling_s") < f(b, "step_settling_s") / 3.0,
        "{v}"
    );
    let kpp = |x: &serde_json::Value| x["Kpp"].as_f64().unwrap();
    for (r, setting) in [(b, &v["before"]), (a, &v["after"])] {
        // 10°/s over Kpp, in arc-seconds.
        let expected = 36000.0 / kpp(setting);
        let got = f(r, "following_error");
        assert!(
            (got / expected - 1.0).abs() < 0.05,
            "{got} against {expected}″"
        );
    }
}
