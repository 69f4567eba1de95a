//! From an identification to the machine's compensation and its predicted effect: the
//! worm-gear preset's backlash and frictions identified from its shipped experiments
//! (fixtures/predict/worm-gear/fit.json), `rtid compensate --fit` on the identified
//! model, `rtid predict` with the fit's uncertainty, and the virtual test on the
//! preset itself (the "real" drive here) with that compensation.

use std::path::{Path, PathBuf};

use crate::cli_support::{err, ok, root, rtid};

fn fit_file() -> PathBuf {
    root().join("fixtures/predict/worm-gear/fit.json")
}

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_str(&ok(out)).unwrap()
}

/// `compensate --fit` into `dir`/compensation.json.
fn compensate(dir: &Path) -> serde_json::Value {
    let fit = fit_file();
    let out = rtid(
        &[
            "compensate",
            "--fit",
            fit.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "-o",
            "compensation.json",
            "--json",
        ],
        dir,
    );
    json(&out)
}

/// `predict` of the shipped fit with the compensation of `dir`, 2 runs, `draws`
/// draws, then `extra`.
fn predict(dir: &Path, draws: &str, extra: &[&str]) -> std::process::Output {
    let fit = fit_file();
    let mut args = vec![
        "predict",
        fit.to_str().unwrap(),
        "--preset",
        "worm-gear",
        "--compensation",
        "compensation.json",
        "--draws",
        draws,
        "--runs",
        "2",
    ];
    args.extend_from_slice(extra);
    rtid(&args, dir)
}

/// One predicted value: (at the fit, lower, upper).
fn predicted(p: &serde_json::Value, case: &str, name: &str) -> (f64, f64, f64) {
    let case = p["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["case"] == case)
        .unwrap();
    let v = case["values"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["name"] == name)
        .unwrap();
    let f = |k: &str| v[k].as_f64().unwrap();
    (f("nominal"), f("lower"), f("upper"))
}

/// The ISO 230-2 axis values of the preset's own positioning test, 2 runs, with the
/// compensation of `dir`, arc-seconds.
fn preset_with_compensation(dir: &Path) -> serde_json::Value {
    let out = rtid(
        &[
            "experiment",
            "positioning",
            "--preset",
            "worm-gear",
            "--runs",
            "2",
            "--compensation",
            "compensation.json",
            "--out",
            "real",
            "--json",
        ],
        dir,
    );
    json(&out)["axis"].clone()
}

#[test]
fn the_fit_compensates_the_preset_and_the_prediction_holds_what_its_test_shows() {
    let dir = tempfile::tempdir().unwrap();
    let c = compensate(dir.path());
    // The identified model's own reversal: the preset's B̄ −35″ (docs/compensation.md).
    let backlash = c["backlash"].as_f64().unwrap();
    assert!((-36.0..-34.0).contains(&backlash), "{backlash}");
    // The machine here is the preset itself: its held values are exact, so they are
    // held at 0 % (drawn within the preset's ranges, the draws' upper end of B̄ after
    // lay below the fit's value and the interval missed the preset's 0.25″: noted in
    // docs/validation.md as open).
    let exact = ["Cb", "Jt", "Jw", "Kw", "Mw", "W", "theta_bg"].map(|n| format!("{n}=0%"));
    let mut extra = vec!["--json"];
    for e in &exact {
        extra.extend(["--uncertain", e.as_str()]);
    }
    let out = predict(dir.path(), "12", &extra);
    let p = json(&out);
    assert_eq!(p["completed"], 12);
    assert_eq!(p["drawn"], serde_json::json!(["theta_bw", "fm", "fw"]));
    let real = preset_with_compensation(dir.path());
    let (b_before, _, _) = predicted(&p, "before", "B_mean");
    let (a_before, _, _) = predicted(&p, "before", "A");
    for name in ["B_mean", "A"] {
        let (at_fit, lo, hi) = predicted(&p, "after", name);
        let shown = real[name].as_f64().unwrap();
        assert!(
            lo <= shown && shown <= hi,
            "{name}: the preset shows {shown}″, predicted {at_fit} [{lo} … {hi}]"
        );
    }
    let b = real["B_mean"].as_f64().unwrap();
    assert!(b.abs() < 2.0 && b_before < -34.0, "B̄ {b_before} → {b}″");
    // The value at the fit is the virtual test on the identified model with it.
    let fit = fit_file();
    let identified = json(&rtid(
        &[
            "experiment",
            "positioning",
            "--preset",
            "worm-gear",
            "--fit",
            fit.to_str().unwrap(),
            "--runs",
            "2",
            "--compensation",
            "compensation.json",
            "--out",
            "identified",
            "--json",
        ],
        dir.path(),
    ));
    for name in ["B_mean", "A"] {
        let (at_fit, _, _) = predicted(&p, "after", name);
        let shown = identified["axis"][name].as_f64().unwrap();
        assert!(
            (at_fit - shown).abs() < 1e-9,
            "{name}: {at_fit} against {shown}"
        );
    }
    let a = real["A"].as_f64().unwrap();
    assert!(a < 0.5 * a_before, "A {a_before} → {a}″");
}

#[test]
fn the_model_s_friction_compensation_is_its_lumped_law() {
    let dir = tempfile::tempdir().unwrap();
    let out = rtid(
        &[
            "compensate",
            "--preset",
            "worm-gear",
            "--friction",
            "--json",
        ],
        dir.path(),
    );
    let f = json(&out)["friction"].clone();
    // fm + Rg·fw + Rg·Rw·ft and Cm + Rg²·Cw + (Rg·Rw)²·Ct of the preset.
    let p = rtid::preset("worm-gear").unwrap();
    let (rg, rw) = (p.rg.unwrap(), p.rw);
    let coulomb = p.fm + rg * p.fw + rg * rw * p.ft;
    let viscous = p.cm + rg * rg * p.cw + (rg * rw).powi(2) * p.ct;
    let got = (
        f["coulomb"].as_f64().unwrap(),
        f["viscous"].as_f64().unwrap(),
    );
    assert!(
        (got.0 / coulomb - 1.0).abs() < 1e-6,
        "{got:?} against {coulomb}"
    );
    assert!(
        (got.1 / viscous - 1.0).abs() < 1e-6,
        "{got:?} against {viscous}"
    );
}

#[test]
fn a_parameter_the_data_did_not_determine_is_refused_until_held() {
    let dir = tempfile::tempdir().unwrap();
    let mut fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fit_file()).unwrap()).unwrap();
    fit["uncertainty"]["standard_errors"][1][1] = serde_json::Value::Null;
    std::fs::write(dir.path().join("fit.json"), fit.to_string()).unwrap();
    let args = [
        "predict",
        "fit.json",
        "--preset",
        "worm-gear",
        "--draws",
        "10",
        "--runs",
        "2",
    ];
    let e = err(&rtid(&args, dir.path()));
    assert!(
        e.contains("`fm` has no standard error") && e.contains("--hold fm"),
        "{e}"
    );
    let mut held = args.to_vec();
    held.extend(["--hold", "fm", "--json"]);
    let p = json(&rtid(&held, dir.path()));
    assert_eq!(p["held"], serde_json::json!(["fm"]));
    // The fitted parameters drawn, then the preset's held ranges (`rtid params`).
    let preset = ["Cb", "Jt", "Jw", "Kw", "Mw", "W", "theta_bg"];
    let mut want = vec!["theta_bw", "fw"];
    want.extend(preset);
    assert_eq!(p["drawn"], serde_json::json!(want));
    // Only "before": nothing to predict the effect of.
    assert_eq!(p["cases"].as_array().unwrap().len(), 1);
}

#[test]
fn bad_predict_options_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let fit = fit_file();
    let f = fit.to_str().unwrap();
    let cases: [(&[&str], &str); 5] = [
        (&["--draws", "3"], "--draws 3"),
        (&["--hold", "Kw"], "--hold Kw: not a parameter of the fit"),
        (&["--tests", "fluctuation"], "--tests fluctuation"),
        (&["--level", "1.5"], "level 1.5"),
        (&["--from", "bootstrap"], "no bootstrap replicates"),
    ];
    for (extra, want) in cases {
        let mut args = vec!["predict", f, "--preset", "worm-gear"];
        args.extend_from_slice(extra);
        let e = err(&rtid(&args, dir.path()));
        assert!(e.contains(want), "{extra:?}: {e}");
    }
    let cargo = root().join("Cargo.toml");
    let e = err(&rtid(
        &["predict", cargo.to_str().unwrap(), "--preset", "worm-gear"],
        dir.path(),
    ));
    assert!(e.contains("not an identification result"), "{e}");
}

/// The shipped fit is what rtid's identification of the shipped experiments gives.
#[cfg(feature = "slow-tests")]
#[test]
fn the_shipped_fit_is_rtid_s_identification() {
    let dir = tempfile::tempdir().unwrap();
    let exp = root().join("fixtures/worm-gear");
    let (tc, ub) = (exp.join("torque_curve.json"), exp.join("unbalance.json"));
    let out = rtid(
        &[
            "identify",
            tc.to_str().unwrap(),
            ub.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--fit",
            "theta_bw,fm,fw",
            "--intervals",
            "standard-errors",
            "--out",
            "fit.json",
            "--quiet",
        ],
        dir.path(),
    );
    ok(&out);
    let read = |p: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    let (got, shipped) = (read(&dir.path().join("fit.json")), read(&fit_file()));
    for name in ["theta_bw", "fm", "fw"] {
        let (g, s) = (
            got["parameters"][name].as_f64().unwrap(),
            shipped["parameters"][name].as_f64().unwrap(),
        );
        assert!((g / s - 1.0).abs() < 1e-9, "{name}: {g} against {s}");
    }
    assert_eq!(got["uncertainty"], shipped["uncertainty"]);
}

#[test]
fn the_report_puts_the_prediction_beside_the_records() {
    let dir = tempfile::tempdir().unwrap();
    compensate(dir.path());
    let out = predict(dir.path(), "10", &["-o", "prediction.json", "--quiet"]);
    ok(&out);
    preset_with_compensation(dir.path());
    let out = rtid(
        &[
            "report",
            "prediction.json",
            "real/positioning.json",
            "--out",
            "report.html",
            "--json",
        ],
        dir.path(),
    );
    let kinds: Vec<String> = json(&out)["sections"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["kind"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(kinds, ["prediction", "positioning", "prediction"]);
    let page = std::fs::read_to_string(dir.path().join("report.html")).unwrap();
    assert!(page.contains("Before, after and predicted"));
    assert!(page.contains("after predicted (prediction.json)"));
    assert!(page.contains("measured (real/positioning.json)"));
}

/// Issue 51's chain on the worm gear's fixtures: identify → tune → compensate for the
/// tuned gains → predict `--tune` with that compensation. The predicted A after is at
/// most A before (the preset's gains, uncompensated), and within 1.1 times what the
/// preset's gains give with a compensation built for them; `--tests servo` predicts
/// the tune's own check.
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (about a minute): --features slow-tests"
)]
fn identify_tune_and_predict_a_tuning_in_a_chain() {
    let dir = tempfile::tempdir().unwrap();
    let frf = root().join("fixtures/worm-gear/frequency_response.json");
    ok(&rtid(
        &[
            "identify",
            frf.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--fit",
            "Kw,Kg,Cig",
            "--out",
            "fit.json",
            "--quiet",
        ],
        dir.path(),
    ));
    let base = ["--preset", "worm-gear"];
    let run = |args: &[&str]| {
        let mut all = args.to_vec();
        all.extend_from_slice(&base);
        ok(&rtid(&all, dir.path()))
    };
    // One run per ensemble: the ensembles' judgement is the presets' test's (tuning.rs).
    let checked: serde_json::Value = serde_json::from_str(&run(&[
        "tune",
        "fit.json",
        "--ensemble",
        "1",
        "-o",
        "tuned.json",
        "--json",
    ]))
    .unwrap();
    run(&[
        "compensate",
        "--fit",
        "fit.json",
        "--tune",
        "tuned.json",
        "-o",
        "c-tuned.json",
        "--quiet",
    ]);
    run(&[
        "compensate",
        "--fit",
        "fit.json",
        "-o",
        "c-today.json",
        "--quiet",
    ]);
    let predict = |extra: &[&str]| {
        let mut args = vec!["predict", "fit.json", "--draws", "10", "--json"];
        args.extend_from_slice(extra);
        serde_json::from_str::<serde_json::Value>(&run(&args)).unwrap()
    };
    // Two runs each way (the default five take 2.5 times as long): what the chain
    // checks is how the tuning and its compensation carry into the prediction.
    let positioning = ["--tests", "positioning", "--runs", "2"];
    let tuned = predict(
        &[
            &positioning[..],
            &["--tune", "tuned.json", "--compensation", "c-tuned.json"],
        ]
        .concat(),
    );
    let today = predict(&[&positioning[..], &["--compensation", "c-today.json"]].concat());
    let (before, _, _) = predicted(&tuned, "before", "A");
    let (after, _, _) = predicted(&tuned, "after", "A");
    let (today_after, _, _) = predicted(&today, "after", "A");
    assert!(after <= before, "A {before} → {after}″");
    assert!(
        after <= 1.1 * today_after,
        "A {after}″ against today's {today_after}″"
    );

    // `--tests servo` predicts `rtid tune`'s own check: its value at the fit is the
    // check of the tuned identified model, the interval around it; the following
    // error v/Kpp falls by the ratio of the position gains.
    let servo = predict(&["--tune", "tuned.json", "--tests", "servo"]);
    for name in [
        "following_error",
        "reversal_spike",
        "step_overshoot_percent",
    ] {
        let (at_fit, lo, hi) = predicted(&servo, "after", name);
        let want = checked["check"]["after"]["members"][0]["servo"][name]
            .as_f64()
            .unwrap();
        assert!(
            (at_fit - want).abs() < 1e-9,
            "{name}: {at_fit} against {want}"
        );
        assert!(lo <= hi, "{name}: [{lo} … {hi}]");
    }
    let (before, _, _) = predicted(&servo, "before", "following_error");
    let (after, _, _) = predicted(&servo, "after", "following_error");
    let kpp = |w: &str| checked[w]["Kpp"].as_f64().unwrap();
    let ratio = kpp("before") / kpp("after");
    assert!(
        (after / before / ratio - 1.0).abs() < 0.05,
        "{before} → {after}″"
    );
}

/// `identify --uncertain`: on a smooth cost the fit is repeated at each end of the
/// held parameter's range, its shifts half the difference of what separate fits
/// with the held value set give; the preset's own ranges are carried beside it
/// unless held exactly (0 %). `predict` draws the fit's held parameters beside the
/// fitted ones and the preset's other ranges independently, and refuses a range
/// the fit's replicates draw already.
#[test]
fn held_ranges_go_from_the_identification_into_the_prediction() {
    let dir = tempfile::tempdir().unwrap();
    let frf = root().join("fixtures/worm-gear/frequency_response.json");
    let identify = |extra: &[&str]| {
        let mut args = vec![
            "identify",
            frf.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--fit",
            "Kw,Kg",
            "--model",
            "linear",
            "--json",
            "--quiet",
        ];
        args.extend_from_slice(extra);
        json(&rtid(&args, dir.path()))
    };
    let by_default = identify(&[]);
    let names: Vec<&str> = (by_default["held"].as_array().unwrap().iter())
        .map(|h| h["name"].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"Jt") && names.contains(&"Jw") && !names.contains(&"Kw"),
        "the preset's ranges of the held parameters, not of the fitted: {names:?}"
    );
    let fit = identify(&["--uncertain", "Jt=10%"]);
    let held = (fit["held"].as_array().unwrap().iter())
        .find(|h| h["name"] == "Jt")
        .unwrap();
    assert_eq!(
        held["half_width"], 0.1,
        "--uncertain replaces the preset's 25 %"
    );
    let at = |name: &str| fit["parameters"][name].as_f64().unwrap().to_string();
    let (kw, kg) = (format!("Kw={}", at("Kw")), format!("Kg={}", at("Kg")));
    let ends: Vec<serde_json::Value> = ["Jt=0.1188", "Jt=0.0972"]
        .iter()
        .map(|jt| identify(&["--set", jt, "--set", &kw, "--set", &kg, "--starts", "1"]))
        .collect();
    for name in ["Kw", "Kg"] {
        let end = |k: usize| ends[k]["parameters"][name].as_f64().unwrap();
        let want = (end(0) - end(1)) / 2.0;
        let shift = held["shifts"][name].as_f64().unwrap();
        assert!(
            (shift - want).abs() < 1e-6 * want.abs(),
            "{name}: {shift} against {want}"
        );
    }
    // The worm's resonances move as √(K/J): Jt + 10 % asks for Kw about 20 % higher.
    let kw_shift =
        held["shifts"]["Kw"].as_f64().unwrap() / fit["parameters"]["Kw"].as_f64().unwrap();
    assert!((0.15..0.3).contains(&kw_shift), "{kw_shift}");

    let e = err(&rtid(
        &[
            "identify",
            frf.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--fit",
            "Kw",
            "--uncertain",
            "Kw=10%",
        ],
        dir.path(),
    ));
    assert!(
        e.contains("--uncertain Kw") && e.contains("Kw is fitted"),
        "{e}"
    );
    let mut shipped: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fit_file()).unwrap()).unwrap();
    shipped["held"] = serde_json::json!([{"name": "theta_bg", "value": 3e-4,
        "half_width": 0.5, "shifts": {"theta_bw": -1e-5}}]);
    std::fs::write(dir.path().join("held.json"), shipped.to_string()).unwrap();
    let predict = |fit: &str, extra: &[&str]| {
        let mut args = vec![
            "predict",
            fit,
            "--preset",
            "worm-gear",
            "--draws",
            "10",
            "--runs",
            "2",
        ];
        args.extend_from_slice(extra);
        rtid(&args, dir.path())
    };
    let p = json(&predict(
        "held.json",
        &["--uncertain", "theta_bg=20%", "--json"],
    ));
    // The fit's draws, its held theta_bg, then the preset's other held ranges.
    assert_eq!(
        p["drawn"],
        serde_json::json!(["theta_bw", "fm", "fw", "theta_bg", "Cb", "Jt", "Jw", "Kw", "Mw", "W"])
    );
    let values: Vec<f64> = (0..10)
        .map(|k| shipped["parameters"]["fm"].as_f64().unwrap() * (k as f64))
        .collect();
    shipped["resampling"] = serde_json::json!({"method": "residual block bootstrap",
        "level": 0.95, "asked": 10, "fitted": 10, "block_lengths": [1, 1], "intervals": {},
        "values": {"fm": values, "fw": values, "theta_bw": values, "theta_bg": values}});
    shipped["held"] = serde_json::json!([]);
    std::fs::write(dir.path().join("replicates.json"), shipped.to_string()).unwrap();
    let e = err(&predict(
        "replicates.json",
        &["--uncertain", "theta_bg=20%"],
    ));
    assert!(
        e.contains("--uncertain theta_bg") && e.contains("draw it already"),
        "{e}"
    );
}

/// The coverage docs/validation.md reports (`scripts/coverage.py`): six machines
/// around the worm gear (backlash and frictions moved; on three, Kw, θbg and Jt),
/// identified from their noisy torque curve and unbalance test, compensated and
/// predicted as docs/compensation.md does, with rtid's defaults (no interval
/// flags: the bootstrap on the rough cost, the preset's held ranges drawn). At least
/// 85 % of the 72 predicted ISO 230-2 values before and after hold the machine's own
/// (measured on 2026-11-29: 71 of 72, the intervals joined with their reflection
/// about the value at the fit; 61 of 72 before that).
#[test]
#[ignore = "coverage tier (about 12 min on 2 cores): cargo test --profile test-release -- --ignored coverage_of"]
fn coverage_of_the_predictions_on_six_machines_that_are_not_the_preset() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new("python3")
        .arg(root().join("scripts/coverage.py"))
        .args(["--rtid", env!("CARGO_BIN_EXE_rtid"), "--out"])
        .arg(dir.path())
        .output()
        .expect("python3 runs scripts/coverage.py");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("coverage.json")).unwrap())
            .unwrap();
    let rows: Vec<&serde_json::Value> = run["machines"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|m| m["rows"].as_array().unwrap())
        .filter(|r| r["case"] == "before" || r["case"] == "after")
        .collect();
    assert_eq!(rows.len(), 72);
    let inside = rows.iter().filter(|r| r["inside"] == true).count();
    assert!(inside >= 62, "{inside} of 72 inside their 95 % intervals");
}
