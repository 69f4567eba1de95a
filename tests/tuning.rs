//! `rtid tune` and `rtid::tuning` (docs/tuning.md): the margins of the velocity loop
//! (fixtures/tuning/generate.py, numpy) and of the cascade as it runs
//! (fixtures/tuning/cascade.py, scipy and python-control) agree with independent
//! computations; the tuned presets keep the targets on the cascade and are never
//! worse than today's settings without a warning (the slow tier weighs each preset on
//! the nonlinear model); the command line writes a tuned parameter file that loads
//! and never writes over its input.

use rtid::io::params_file;
use rtid::model::params::{ControllerParams, LoopMode};
use rtid::model::{presets, SetpointFilter};
use rtid::tuning::sampled::{Closure, DiscretePlant, SampledLoop};
use rtid::tuning::search::Grid;
use rtid::tuning::{
    rule, tune, Criterion, LoopMargins, Margins, Options, Setting, Targets, TuneWarning, Tuned,
    VelocityLoop, VelocityPi, Verdict,
};

use crate::cli_support::{err, ok, root, rtid};

fn expected() -> serde_json::Value {
    let path = root().join("fixtures/tuning/expected.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
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

fn cascade_json(file: &str) -> serde_json::Value {
    let path = root().join("fixtures/tuning").join(file);
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The controller of a setting recorded in cascade-settings.json on `name`'s preset.
fn recorded(name: &str, s: &serde_json::Value) -> (rtid::Params, ControllerParams) {
    let p = presets::load(name).unwrap();
    let c = ControllerParams {
        kvp: s["Kvp"].as_f64().unwrap(),
        kvi: s["Kvi"].as_f64().unwrap(),
        kpp: s["Kpp"].as_f64().unwrap(),
        filters: serde_json::from_value(s["filters"].clone()).unwrap(),
        loop_mode: serde_json::from_value(s["loop"].clone()).unwrap(),
        ..p.controller.clone()
    };
    (p, c)
}

/// The cascade as it runs, opened at the torque setpoint, exact on the sampled loop:
/// rtid's state space of the controller sample by sample against scipy's ZOH and
/// python-control's loop of transfer functions, for the four presets before and after
/// `rtid tune`, the rule alone, and the worm gear full-closed.
#[test]
fn the_cascade_margins_agree_with_an_independent_python_control_computation() {
    let settings = cascade_json("cascade-settings.json");
    let expected = cascade_json("cascade-expected.json");
    let mut compared = 0;
    for (name, cases) in settings.as_object().unwrap() {
        for (case, s) in cases.as_object().unwrap() {
            let (p, c) = recorded(name, s);
            let m = Setting::of(&p, &c).unwrap().cascade;
            let want = &expected[name][case];
            agrees_with_python_control(&format!("{name} {case}"), &m, want);
            compared += 1;
        }
    }
    assert_eq!(compared, 15);
}

/// rtid's margins `m` of a cascade against python-control's `want` (cascade.py's
/// fields): the phase margin within 0.05°, the gain margins both ways within 0.02 dB,
/// the frequencies within 0.1 %, stability and a conditional window exactly.
fn agrees_with_python_control(at: &str, m: &LoopMargins, want: &serde_json::Value) {
    let close = |got: Option<f64>, field: &str, tol: f64| match want[field].as_f64() {
        Some(w) => {
            let g = got.unwrap_or_else(|| panic!("{at} {field}: none, want {w}"));
            assert!((g - w).abs() <= tol, "{at} {field}: {g} vs {w}");
        }
        None => assert!(got.is_none(), "{at} {field}: {got:?}, want none"),
    };
    close(m.margins.phase_margin_deg, "phase_margin_deg", 0.05);
    close(m.margins.gain_margin_db, "gain_margin_db", 0.02);
    close(
        m.stability.gain_reduction_margin_db,
        "gain_reduction_margin_db",
        0.02,
    );
    for field in ["crossover_hz", "phase_margin_hz", "gain_margin_hz"] {
        let got = match field {
            "crossover_hz" => m.margins.crossover_hz,
            "phase_margin_hz" => m.margins.phase_margin_hz,
            _ => m.margins.gain_margin_hz,
        };
        close(got, field, 1e-3 * want[field].as_f64().unwrap_or(0.0));
    }
    assert_eq!(
        m.stability.stable,
        want["stable"].as_bool().unwrap(),
        "{at}"
    );
    let conditional = m.stability.conditional_window_db.is_some();
    assert_eq!(conditional, want["conditional"].as_bool().unwrap(), "{at}");
}

/// Tuning over a range (issue 58): the settings `tune --preset two-mass --vary
/// Jt=0.5..2` and `tune --preset direct-drive --vary Jt=1..3` propose
/// (range-settings.json; the two-mass's are today's, kept) keep a phase margin of 49°
/// and gain margins of 5.7 dB both ways at the range's ends and middle by an
/// independent computation (fixtures/tuning/range.py: python-control on the preset
/// with Jt scaled), and rtid's margins there are python-control's (0.05°, 0.02 dB,
/// 0.1 % of the frequencies).
#[test]
fn the_settings_tuned_over_a_range_keep_the_targets_at_its_ends_and_middle() {
    let settings = cascade_json("range-settings.json");
    let expected = cascade_json("range-expected.json");
    let mut compared = 0;
    for (name, case) in settings.as_object().unwrap() {
        let preset = case["preset"].as_str().unwrap();
        let (base, c) = recorded(preset, &case["setting"]);
        let (param, _) = case["vary"].as_object().unwrap().iter().next().unwrap();
        let value = base.get(param).unwrap().unwrap();
        for want in expected[name].as_array().unwrap() {
            let ratio = want["ratio"].as_f64().unwrap();
            let at = format!("{name} {param} ×{ratio}");
            // The independent computation keeps the targets…
            assert!(
                want["stable"].as_bool().unwrap() && !want["conditional"].as_bool().unwrap(),
                "{at}"
            );
            assert!(
                want["phase_margin_deg"].as_f64().unwrap() >= 49.0,
                "{at}: {want}"
            );
            for field in ["gain_margin_db", "gain_reduction_margin_db"] {
                assert!(
                    want[field].as_f64().map_or(true, |g| g >= 5.7),
                    "{at}: {want}"
                );
            }
            // … and rtid's margins there are its own.
            let mut p = base.clone();
            p.set(param, value * ratio).unwrap();
            let m = Setting::of(&p, &c).unwrap().cascade;
            agrees_with_python_control(&at, &m, want);
            compared += 1;
        }
    }
    assert_eq!(compared, 6);
}

/// MD32810, the closed speed loop's equivalent time constant, from the tuned loop
/// (issue 58): for every setting `tune` proposed (cascade-settings.json,
/// range-settings.json), 1/(2π·f₋₃dB) of the exact closed speed loop lies within
/// 0.5 to 2 times 1/(2π·f_c), f_c the velocity loop's crossover.
#[test]
fn the_equivalent_time_constant_follows_the_tuned_speed_loop() {
    let settings = cascade_json("cascade-settings.json");
    let ranged = cascade_json("range-settings.json");
    let mut cases: Vec<(String, &serde_json::Value)> = Vec::new();
    for (name, all) in settings.as_object().unwrap() {
        cases.push((name.clone(), &all["after"]));
    }
    for case in ranged.as_object().unwrap().values() {
        cases.push((case["preset"].as_str().unwrap().into(), &case["setting"]));
    }
    for (name, s) in cases {
        let (p, c) = recorded(&name, s);
        let setting = Setting::of(&p, &c).unwrap();
        let fc = setting.velocity_loop.crossover_hz.unwrap();
        let t = setting.closed_loop.equivalent_time_s.unwrap();
        let ratio = t * std::f64::consts::TAU * fc;
        assert!(
            (0.5..=2.0).contains(&ratio),
            "{name}: T = {t} s, f_c = {fc} Hz: {ratio}"
        );
    }
}

/// The rule of rtid's first tuning (the highest velocity crossover with 50°, Kpp =
/// ω_c/4) leaves every preset's cascade short of 50° — the numbers an independent
/// python-control computation gave for issue 51: 35.7° (worm gear), 47.2° (two-mass),
/// 36.8° (direct drive), 35.1° (roller-gear cam), the roller-gear cam's conditionally
/// stable (unstable from +10.4 dB, stable again at +16.5 dB) — and the rule is still
/// what cascade-settings.json records.
#[test]
fn the_rule_alone_leaves_the_cascade_short_of_its_targets() {
    let settings = cascade_json("cascade-settings.json");
    for (name, pm) in [
        ("worm-gear", 35.7),
        ("two-mass", 47.2),
        ("direct-drive", 36.8),
        ("roller-gear-cam", 35.1),
    ] {
        let p = presets::load(name).unwrap();
        let c = rule(&p, Targets::default()).unwrap();
        let (_, want) = recorded(name, &settings[name]["rule"]);
        assert!((c.kvp / want.kvp - 1.0).abs() < 1e-9, "{name}");
        assert!((c.kpp / want.kpp - 1.0).abs() < 1e-9, "{name}");
        let m = Setting::of(&p, &c).unwrap().cascade;
        let got = m.margins.phase_margin_deg.unwrap();
        assert!((got - pm).abs() < 0.5, "{name}: {got}° against {pm}°");
        assert!(!m.meets(50.0, 6.0), "{name}");
        let window = m.stability.conditional_window_db;
        if name == "roller-gear-cam" {
            // Unstable from +10.4 dB, stable again below +16.5 dB, and unstable once
            // more above +17.9 dB (python-control's poles: 1.00002 at +10.5 dB,
            // 0.99990 at +16.5, 0.99977 at +17.7, 1.0084 at +18; issue 51 read
            // +17.7 dB as unstable).
            let [from, to] = window.unwrap();
            assert!(
                (from - 10.4).abs() < 0.05 && to > from && to < 16.5,
                "{window:?}"
            );
            let plant = DiscretePlant::new(&p).unwrap();
            let l = SampledLoop::new(&plant, &c, Closure::Cascade);
            let radius = |db: f64| l.spectral_radius(10f64.powf(db / 20.0)).unwrap();
            assert!(radius(10.5) > 1.0 && radius(16.5) < 1.0 && radius(18.0) > 1.0);
        } else {
            assert!(window.is_none(), "{name}: {window:?}");
        }
    }
}

/// The library's search on a preset (default options) in its own loop or `mode`.
fn tuned(name: &str, mode: Option<LoopMode>) -> (rtid::Params, Tuned) {
    let mut p = presets::load(name).unwrap();
    if let Some(m) = mode {
        p.controller.loop_mode = m;
    }
    let t = tune(&p, &Options::default(), &|_, _| {}).unwrap();
    (p, t)
}

/// Every preset: the proposed cascade keeps the targets as it runs (stable, 50°,
/// 6 dB both ways, no conditional window) with the margins an independent
/// computation gives (within 1° and 0.3 dB); a proposal beats today's on the
/// objective beyond the spread of its ensemble, and every criterion its ensemble
/// makes worse than today's carries a warning naming it; the worm gear's reported A
/// is what the documented chain gives (below).
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (about two minutes): --features slow-tests"
)]
fn the_tuned_presets_keep_the_targets_on_the_cascade_and_name_what_is_worse() {
    let expected = cascade_json("cascade-expected.json");
    for name in ["worm-gear", "two-mass", "direct-drive", "roller-gear-cam"] {
        let (p, t) = tuned(name, None);
        assert!(
            t.after.cascade.meets(50.0, 6.0),
            "{name}: {:?}",
            t.after.cascade
        );
        // The margins `tune` reports are python-control's for the same setting
        // (cascade-settings.json records `tune`'s choice: regenerate both with
        // fixtures/tuning/cascade.py when the search changes).
        let want = &expected[name]["after"];
        let m = &t.after.cascade;
        let close = |got: Option<f64>, field: &str, tol: f64| {
            let w = want[field].as_f64().unwrap();
            assert!(
                (got.unwrap() - w).abs() <= tol,
                "{name} {field}: {got:?} vs {w}"
            );
        };
        close(m.margins.phase_margin_deg, "phase_margin_deg", 1.0);
        close(m.margins.gain_margin_db, "gain_margin_db", 0.3);
        close(
            m.stability.gain_reduction_margin_db,
            "gain_reduction_margin_db",
            0.3,
        );
        let j = &t.check.judgement;
        assert_eq!(j.members, 8, "{name}");
        for c in j.worse() {
            assert!(
                t.warnings
                    .iter()
                    .any(|w| matches!(w, TuneWarning::Worse(w) if w.criterion == c.criterion)),
                "{name}: {c:?} not warned"
            );
        }
        if t.proposes {
            assert_eq!(j.score.verdict, Verdict::Better, "{name}: {j:?}");
            assert!(t.search.check_score < 1.0 - rtid::tuning::judge::SCORE_TOLERANCE);
        } else {
            assert!(t
                .warnings
                .iter()
                .any(|w| matches!(w, TuneWarning::NothingBetter { .. })));
        }
        if name == "worm-gear" {
            worm_gear_reports_what_the_documented_chain_gives(&p, &t);
        }
    }
}

/// The worm gear, semi-closed (issue 58): where the axis comes to rest in stick
/// decides A after compensation (0.1″ changes of the compensation move it by 1″), so
/// `tune` reports each setting's ensemble. The documented chain — the standard cycle,
/// the compensation built from it, the compensated cycle with the compensation's
/// backlash changed by −1e-12°, +1e-11°, …, −1e-6° (seven runs, the opposite signs
/// of the ensemble's own) — gives means within 0.5″ of what `tune` reports, before
/// and after; and `tune` claims A better (or worse) only where those seven runs agree
/// (paired, beyond the half-width of their 95 % interval). No limit cycle.
fn worm_gear_reports_what_the_documented_chain_gives(p: &rtid::Params, t: &Tuned) {
    use rayon::prelude::*;
    use rtid::experiments::positioning::{self, compensate, iso230, PositioningTest};
    let chain = |q: &rtid::Params| -> Vec<f64> {
        let test = PositioningTest::default();
        let first = positioning::run(q, &test, |_, _| {}).unwrap();
        let built = compensate::compute(&first, q.axis, None)
            .unwrap()
            .compensation;
        (0..7)
            .into_par_iter()
            .map(|k| {
                let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
                let offset = sign * 10f64.powi(k - 12).to_radians();
                let mut c = built.clone();
                c.backlash = Some(c.backlash.unwrap() + offset);
                let test = PositioningTest {
                    compensation: c,
                    ..test.clone()
                };
                let readings = positioning::run(q, &test, |_, _| {}).unwrap();
                iso230::evaluate(&readings).unwrap().axis.in_arcsec().a
            })
            .collect()
    };
    let (before, after) = rayon::join(|| chain(p), || chain(&t.params));
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let reported = t.check.judgement.of(Criterion::Accuracy);
    for (which, runs, spread) in [
        ("before", &before, &reported.before),
        ("after", &after, &reported.after),
    ] {
        assert!(
            (mean(runs) - spread.mean).abs() <= 0.5,
            "{which}: tune reports A {:.2}″, the chain's seven runs {runs:?} (mean {:.2}″)",
            spread.mean,
            mean(runs)
        );
    }
    let chain_verdict = rtid::tuning::judge::compare(&before, &after, 0.0).verdict;
    if reported.verdict != Verdict::NoDifferent {
        assert_eq!(
            reported.verdict, chain_verdict,
            "tune: {reported:?}; the chain: {before:?} → {after:?}"
        );
    }
    let a = &t.check.after.members[0];
    assert!(a.servo.table_motion_at_rest < rtid::tuning::limit_cycle_threshold(p));
    assert_eq!(a.positioning.compensated_in, "controller");
}

/// The worm gear, full-closed (issue 51: the rule's gains put it into a limit cycle,
/// A 452″): the tuned settings hold the table, A ≤ 1″ and no motion at rest.
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (20–40 s): --features slow-tests"
)]
fn the_tuned_full_closed_worm_gear_holds_the_table() {
    let (p, t) = tuned("worm-gear", Some(LoopMode::FullClosed));
    assert_eq!(t.loop_mode, LoopMode::FullClosed);
    let a = t.check.judgement.of(Criterion::Accuracy).after;
    assert!(a.max <= 1.0, "A {a:?}″");
    let cycle = rtid::tuning::limit_cycle_threshold(&p);
    for m in &t.check.after.members {
        assert!(m.servo.table_motion_at_rest < cycle, "{:?}", m.servo);
    }
    assert!(t.after.cascade.meets(50.0, 6.0));
}

/// The command over a range (issue 58): the direct drive over Jt 1..3 gets the
/// setting range.py checked (today's loses the targets at Jt ×3 and is replaced), a
/// tuned parameter file that loads and carries it, the plots of the open and the
/// closed loops, MD32810 from the tuned speed loop; the two-mass drive over Jt 0.5..2
/// keeps today's (nothing beats it beyond its spread), and the command says so;
/// never over an input.
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (about 40 s): --features slow-tests"
)]
fn the_command_tunes_over_a_range_and_keeps_todays_when_nothing_beats_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = rtid(
        &[
            "tune",
            "--preset",
            "direct-drive",
            "--vary",
            "Jt=1..3",
            "--json",
            "-o",
            "tuned.json",
            "--plot",
            "loop.svg",
            "--sinumerik",
            "cnc.txt",
            "--axis-number",
            "4",
        ],
        dir.path(),
    );
    let v: serde_json::Value = serde_json::from_str(&ok(&out)).unwrap();
    assert_eq!(v["proposes"], true, "{v}");
    let p = params_file::read(&dir.path().join("tuned.json")).unwrap();
    assert_eq!(p.controller.kvp, v["after"]["Kvp"].as_f64().unwrap());
    assert_eq!(p.controller.kpp, v["after"]["Kpp"].as_f64().unwrap());
    // The setting range.py checked at the range's ends and middle; today's loses
    // the targets at Jt ×3 and is replaced.
    let recorded = &cascade_json("range-settings.json")["direct-drive"]["setting"];
    for gain in ["Kvp", "Kvi", "Kpp"] {
        let (got, want) = (
            v["after"][gain].as_f64().unwrap(),
            recorded[gain].as_f64().unwrap(),
        );
        assert!((got / want - 1.0).abs() < 1e-9, "{gain}: {got} vs {want}");
    }
    let worst = &v["after"]["over_range"];
    assert!(
        worst["phase_margin_deg"][0].as_f64().unwrap() >= 50.0,
        "{worst}"
    );
    assert!(
        v["before"]["over_range"]["phase_margin_deg"][0]
            .as_f64()
            .unwrap()
            < 50.0
    );
    let kinds: Vec<&str> = v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"today_outside_targets"), "{kinds:?}");
    for field in [
        "phase_margin_deg",
        "gain_margin_db",
        "gain_reduction_margin_db",
    ] {
        assert!(v["after"]["cascade"][field].is_number(), "{field}: {v}");
    }
    assert_eq!(v["after"]["cascade"]["stable"], true);
    assert_eq!(v["check"]["judgement"]["members"], 8);
    let svg = std::fs::read_to_string(dir.path().join("loop.svg")).unwrap();
    for s in [
        "velocity loop alone, before",
        "cascade as it runs, after",
        "cascade as it runs, after: phase margin",
        "cascade as it runs, after: gain margin",
    ] {
        assert!(svg.contains(s), "{s}");
    }
    let pm = v["after"]["cascade"]["phase_margin_deg"].as_f64().unwrap();
    assert!(svg.contains(&format!("phase margin {pm:.1}°")), "{pm}");
    let closed = std::fs::read_to_string(dir.path().join("loop-closed.svg")).unwrap();
    let s_max = v["after"]["closed_loop"]["sensitivity_peak_db"]
        .as_f64()
        .unwrap();
    assert!(closed.contains(&format!("|S|max {s_max:.1} dB")), "{s_max}");
    // MD32810 is the tuned speed loop's equivalent time constant.
    let cnc = std::fs::read_to_string(dir.path().join("cnc.txt")).unwrap();
    let md32810: f64 = cnc
        .lines()
        .find_map(|l| l.strip_prefix("$MA_EQUIV_SPEEDCTRL_TIME[0,AX4]="))
        .and_then(|l| l.split(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    let t = v["after"]["closed_loop"]["equivalent_time_s"]
        .as_f64()
        .unwrap();
    assert!((md32810 / t - 1.0).abs() < 1e-8, "{md32810} vs {t}");

    // The two-mass drive over Jt 0.5..2: today's settings keep the targets at Jt ×2
    // (51.8°) and nothing beats them beyond its ensemble's spread: the command keeps
    // them, saying so.
    let kept = ok(&rtid(
        &[
            "tune",
            "--preset",
            "two-mass",
            "--vary",
            "Jt=0.5..2",
            "-o",
            "kept.json",
        ],
        dir.path(),
    ));
    assert!(kept.contains("after (today's kept)"), "{kept}");
    assert!(kept.contains("beats today's"), "{kept}");
    assert!(
        kept.contains("worst phase margin") && kept.contains("at Jt ×2"),
        "{kept}"
    );
    let kept = params_file::read(&dir.path().join("kept.json")).unwrap();
    assert_eq!(
        kept.controller,
        presets::load("two-mass").unwrap().controller
    );

    let over = rtid(
        &["tune", "--params", "tuned.json", "-o", "./tuned.json"],
        dir.path(),
    );
    assert!(err(&over).contains("input"), "{}", err(&over));
    std::fs::write(dir.path().join("p.json"), "{}").unwrap();
    let over = rtid(
        &["tune", "--params", "p.json", "--plot", "./p.json"],
        dir.path(),
    );
    assert!(err(&over).contains("input"), "{}", err(&over));
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
    let out = rtid(
        &["tune", "--preset", "worm-gear", "--max-kpp", "nan"],
        dir.path(),
    );
    assert!(err(&out).contains("--max-kpp"), "{}", err(&out));
    let out = rtid(
        &[
            "tune",
            "--preset",
            "worm-gear",
            "--nominal",
            "--vary",
            "Jt=1..2",
        ],
        dir.path(),
    );
    assert!(
        err(&out).contains("--nominal") && err(&out).contains("--vary"),
        "{}",
        err(&out)
    );
}

/// `tune FIT.json --preset …` tunes the identified model: the base set with the fit's
/// values, as `--set` of each would (the same settings; the search's wall time aside).
#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (about a minute): --features slow-tests"
)]
fn the_command_tunes_the_model_of_an_identification() {
    let dir = tempfile::tempdir().unwrap();
    let fit_path = root().join("fixtures/predict/worm-gear/fit.json");
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&fit_path).unwrap()).unwrap();
    // One run per ensemble: what is compared is the model the two ways give.
    let mut args = vec![
        "tune".to_string(),
        "--preset".into(),
        "worm-gear".into(),
        "--ensemble".into(),
        "1".into(),
    ];
    for (name, value) in fit["parameters"].as_object().unwrap() {
        args.extend(["--set".into(), format!("{name}={value}")]);
    }
    args.push("--json".into());
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    // The ranges' quantities are the same (the preset's Jw; the fitted backlash and
    // frictions would not enter the linearised loop); where they come from differs.
    let settings = |text: String| {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["search"]["wall_s"] = serde_json::Value::Null;
        let origins = v["range"]["origins"].take();
        (v, origins)
    };
    let (by_set, _) = settings(ok(&rtid(&refs, dir.path())));
    let (by_fit, origins) = settings(ok(&rtid(
        &[
            "tune",
            fit_path.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--ensemble",
            "1",
            "--json",
        ],
        dir.path(),
    )));
    assert_eq!(by_fit, by_set);
    let theta_bw = origins
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["name"] == "theta_bw")
        .unwrap_or_else(|| panic!("{origins}"));
    // The shipped fit (a torque curve's rough cost, no bootstrap) knows its standard
    // errors to be lower bounds: its parameters are named and held, not given the
    // preset's held range in their place.
    let why = theta_bw["left_out"].as_str().unwrap_or_default();
    assert!(
        theta_bw["from"] == "the fit" && why.contains("lower bound"),
        "{theta_bw}"
    );
    assert_eq!(
        by_fit["range"]["vary"][0]["name"], "Jw",
        "{}",
        by_fit["range"]
    );
    let e = err(&rtid(
        &["tune", "missing.json", "--preset", "worm-gear"],
        dir.path(),
    ));
    assert!(e.contains("missing.json"), "{e}");
}
