//! Identification (issue 4): parameters recovered from rtid's own virtual
//! experiments (fixtures/), multi-start, identifiability warnings, the interrupt path.
//! The true values come from the fixtures (`support`), the presets that made them.

use rtid::estimation::peaks::of_linear_response as linear_peaks;
use rtid::identify::{
    identify, Bound, Config, ExperimentSpec, FidelityChoice, Identified, Method, Monitor, Warning,
};
use rtid::io::experiment_file::{Data, Experiment, Kind, Manifest};
use rtid::model::{presets, Params};
use rtid::objectives::ObjectiveKind;

use crate::support::{self, off, values, Fixture};

fn config(experiments: Vec<ExperimentSpec>, base: Params, fit: &[&str]) -> Config {
    Config::new(experiments, base, fit)
}

fn run(c: &Config) -> Identified {
    identify(c, &Monitor::default()).unwrap()
}

fn objective(name: &str) -> ObjectiveKind {
    ObjectiveKind::named(name).unwrap()
}

/// Whether a warning of the result matches.
fn warns(r: &Identified, matches: impl Fn(&Warning) -> bool) -> bool {
    r.result.warnings.iter().any(|w| matches(&w.0))
}

fn assert_within(r: &Identified, truth: &[(&str, f64)], tol: f64) {
    for (name, want) in truth {
        let got = r.result.parameters[*name];
        assert!(
            ((got - want) / want).abs() < tol,
            "{name}: identified {got:.6e}, true {want:.6e} (tolerance {} %); result: {:#?}",
            tol * 100.0,
            r.result.parameters
        );
    }
}

#[test]
fn kw_and_kg_from_the_worm_frequency_response_within_1_percent_from_50_percent_off() {
    let Fixture { spec, truth } = support::worm_frequency_response();
    for (kw, kg) in [(1.5, 0.5), (0.5, 1.5), (1.5, 1.5)] {
        let base = off(&truth, &[("Kw", kw), ("Kg", kg)]);
        let r = run(&config(vec![spec.clone()], base, &["Kw", "Kg"]));
        assert_within(&r, &values(&truth, &["Kw", "Kg"]), 0.01);
        assert!(!r.result.interrupted);
    }
}

#[test]
fn kw_and_kg_from_nonlinear_simulations_within_0_2_percent_from_40_percent_off() {
    // Issue 4's speed reference case (+40 % starts). The linear fit alone ends at
    // −0.36 % / −0.18 % on this nonlinear data (the bias of backlash and friction), so
    // 0.2 % needs the nonlinear stage; it must converge in a few evaluations of the
    // nonlinear test (docs/identification.md, `--model nonlinear`). The case is the
    // resonance search, on the fixture's gain: with its phase the search fits the
    // complex curve, which the nonlinear test biases more (Kw −1.0 %), and the
    // corrections then stop at their limit of six with the last step at 2.2e-4 (the
    // result still within 0.2 %).
    let Fixture { spec, truth } = support::gain_only(support::worm_frequency_response());
    let base = off(&truth, &[("Kw", 1.4), ("Kg", 1.4)]);
    let mut c = config(vec![spec], base, &["Kw", "Kg"]);
    c.fidelity = FidelityChoice::Nonlinear;
    let r = run(&c);
    assert_within(&r, &values(&truth, &["Kw", "Kg"]), 0.002);
    let stage = &r.result.starts[0];
    assert!(
        stage.termination.converged() && stage.iterations <= 6,
        "{stage:?}"
    );
    assert_eq!(r.result.residuals[0].objective, "gain_curve");
}

#[test]
fn by_default_kw_and_kg_within_1_percent_on_friction_affected_data() {
    // Issue 12's independent case: friction flattens the second resonance, so the
    // linear fit meets the one resonance and its height exactly along a whole curve
    // of (Kw, Kg) and lands 26 % off; `auto` sees its gain curve miss the measured one
    // and goes on to the nonlinear fit, saying so.
    let Fixture { spec, truth } = support::worm_frequency_response_with_friction();
    let base = {
        let mut p = presets::load("worm-gear").unwrap();
        p.set("theta_bw", 0.0).unwrap();
        p.set("theta_bg", 0.0).unwrap();
        p
    };
    let r = run(&config(vec![spec.clone()], base.clone(), &["Kw", "Kg"]));
    assert_within(&r, &values(&truth, &["Kw", "Kg"]), 0.01);
    assert!(
        warns(&r, |w| matches!(w, Warning::Escalated { .. })),
        "{:?}",
        r.result.warnings
    );
    assert_eq!(r.result.fidelity, "linear, then nonlinear");
    // The linear fit alone is far off: without the escalation the test above fails.
    let mut c = config(vec![spec], base, &["Kw", "Kg"]);
    c.fidelity = FidelityChoice::Linear;
    let linear = run(&c);
    let kw = linear.result.parameters["Kw"];
    assert!((kw / 3.6e5 - 1.0).abs() > 0.05, "linear Kw {kw:.4e}");
}

#[test]
fn kw_and_kb_of_the_roller_from_two_resonances() {
    let Fixture { spec, truth } = support::roller_frequency_response();
    let base = off(&truth, &[("Kw", 0.5), ("Kb", 1.5)]);
    let r = run(&config(vec![spec], base, &["Kw", "Kb"]));
    assert_within(&r, &values(&truth, &["Kw", "Kb"]), 0.01);
    assert!(
        !warns(&r, |w| matches!(w, Warning::Correlated { .. })),
        "Kw and Kb of the roller move its two modes differently: {:?}",
        r.result.warnings
    );
}

#[test]
fn with_1_percent_noise_kw_and_kg_within_5_percent() {
    let Fixture { spec, truth } = support::worm_frequency_response_noisy();
    let base = off(&truth, &[("Kw", 1.5), ("Kg", 0.5)]);
    let r = run(&config(vec![spec], base, &["Kw", "Kg"]));
    assert_within(&r, &values(&truth, &["Kw", "Kg"]), 0.05);
}

/// A resonance experiment made from the exact linear peaks of the preset (frequency
/// and height), as a measurement in the linear limit would give them.
fn linear_resonance_experiment(p: &Params) -> ExperimentSpec {
    let peaks = linear_peaks(p, 10.0, 600.0, 2).unwrap();
    let mut m = Manifest::new(Kind::Resonance);
    m.peaks_hz = Some(peaks.iter().map(|k| k.frequency_hz).collect());
    m.peak_gain_db = Some(peaks.iter().map(|k| k.gain_db).collect());
    let data = Data::Resonance {
        peaks_hz: m.peaks_hz.clone().unwrap(),
        peak_gain_db: m.peak_gain_db.clone(),
    };
    ExperimentSpec::new(
        "linear-peaks",
        Experiment {
            manifest: m,
            data,
            path: "linear-peaks.json".into(),
            data_path: None,
        },
    )
}

#[test]
fn ciw_and_cig_from_the_peak_amplitudes_within_5_percent() {
    let truth = presets::load("worm-gear").unwrap();
    let exp = linear_resonance_experiment(&truth);
    for (a, b) in [(1.5, 0.5), (0.5, 1.5)] {
        let base = off(&truth, &[("Ciw", a), ("Cig", b)]);
        let c = config(vec![exp.clone()], base, &["Ciw", "Cig"])
            .with_objectives(&[objective("peak_amplitude")]);
        let r = run(&c);
        assert_within(&r, &values(&truth, &["Ciw", "Cig"]), 0.05);
    }
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (20–40 s): --features slow-tests"
)]
fn motor_friction_and_viscous_damping_from_the_torque_curve_within_5_percent() {
    // The motor's Coulomb friction and viscous damping (the table's are divided by
    // Rg·Rw = 1/90 at the motor and hardly show; see docs/validation.md), started
    // 50 % off, clean and with 1 % noise. Nelder–Mead: the quantised encoders make the
    // torque residual rough on the scale of finite differences.
    for (fixture, start) in [
        (support::worm_torque_curve(), (1.5, 0.5)),
        (support::worm_torque_curve_noisy(), (0.5, 1.5)),
    ] {
        let Fixture { spec, truth } = fixture;
        let base = off(&truth, &[("fm", start.0), ("Cm", start.1)]);
        let mut c = config(vec![spec], base, &["fm", "Cm"]);
        c.search.starts = Some(1);
        c.search.method = Some(Method::NelderMead);
        c.search.max_iters = 60;
        let r = run(&c);
        assert_within(&r, &values(&truth, &["fm", "Cm"]), 0.05);
        // The standard errors of such a fit are lower bounds, and the result says so.
        assert!(
            warns(&r, |w| *w == Warning::RoughCost),
            "{:?}",
            r.result.warnings
        );
    }
}

#[test]
fn the_table_friction_hardly_shows_in_the_motor_torque() {
    // Why the torque curve identifies fm, not ft: ft reaches the motor divided by
    // Rg·Rw = 1/90. Half as much again of it changes the motor torque by < 1 % of its
    // RMS (measured 0.65 %: more than 1/90 of fm's effect, because in full-closed
    // loop the table's stick also shapes the servo's response), an eighth of what the
    // same change of fm does (5.3 %).
    use rtid::experiments::torque_curve::{simulate_torque, TorqueTest};
    let test = TorqueTest::default();
    let times: Vec<f64> = (0..3000).map(|i| i as f64 * 2e-3).collect();
    let p = presets::load("worm-gear").unwrap();
    let base = simulate_torque(&p, &test, &times).unwrap();
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let change = |name: &str, factor: f64| {
        let mut q = p.clone();
        let v = q.get(name).unwrap().unwrap();
        q.set(name, v * factor).unwrap();
        let t = simulate_torque(&q, &test, &times).unwrap();
        let d: Vec<f64> = t.iter().zip(&base).map(|(a, b)| a - b).collect();
        rms(&d) / rms(&base)
    };
    let (ft, fm) = (change("ft", 1.5), change("fm", 1.5));
    assert!(
        ft < 0.01,
        "ft ×1.5 changes the motor torque by {:.2} % of its RMS",
        100.0 * ft
    );
    eprintln!("ft: {:.3} %, fm: {:.3} %", 100.0 * ft, 100.0 * fm);
    assert!(
        fm > 0.03 && ft < 0.25 * fm,
        "fm ×1.5 changes the motor torque by {:.2} % of its RMS, ft ×1.5 by {:.2} %",
        100.0 * fm,
        100.0 * ft
    );
}

#[test]
fn the_kw_kb_pair_of_the_worm_is_flagged_and_kw_kg_is_not() {
    let Fixture { spec, truth } = support::worm_frequency_response();
    let r = run(&config(vec![spec.clone()], truth.clone(), &["Kw", "Kb"]));
    assert!(
        warns(&r, |w| match w {
            Warning::Correlated { a, b, .. } => a == "Kw" && b == "Kb",
            Warning::Singular { .. } => true,
            _ => false,
        }),
        "Kb·r² acts in series with Kw: {:?}",
        r.result.warnings
    );
    let r = run(&config(vec![spec], truth, &["Kw", "Kg"]));
    assert!(
        !warns(&r, |w| matches!(
            w,
            Warning::Correlated { .. } | Warning::Singular { .. }
        )),
        "{:?}",
        r.result.warnings
    );
}

#[test]
fn multistart_escapes_the_local_minimum_a_single_start_falls_into() {
    // The whole linear gain curve against Kw alone over two decades: started 3.4×
    // too soft (Kw = 9e4), the model's resonances sit below the measured ones and the
    // gain-curve residual has a local minimum there.
    // The gain alone: with its phase the fixture's curve is complex, and one start
    // from 9e4 no longer stalls (the phase tells the modes apart).
    let Fixture { mut spec, truth } = support::worm_frequency_response();
    if let rtid::io::experiment_file::Data::FrequencyResponse { phase_rad, .. } =
        &mut spec.experiment.data
    {
        *phase_rad = None;
    }
    let kw_true = truth.kw;
    let mut base = truth.clone();
    base.kw = 9e4;
    let mut c = config(vec![spec], base, &["Kw"]).with_objectives(&[objective("gain_curve")]);
    c.fidelity = FidelityChoice::Linear;
    c.bounds = vec![("Kw".into(), Bound { lo: 3e4, hi: 3e6 })];
    c.search.starts = Some(1);
    let single = run(&c);
    let kw = single.result.parameters["Kw"];
    assert!(
        ((kw - kw_true) / kw_true).abs() > 0.2,
        "one start from 9e4 should stall in the local minimum, got Kw = {kw:.4e}"
    );
    c.search.starts = Some(8);
    let multi = run(&c);
    assert_within(&multi, &values(&truth, &["Kw"]), 0.02);
    assert!(multi.result.cost < single.result.cost);
}

#[test]
fn an_interrupted_search_still_writes_a_valid_result() {
    let Fixture { spec, truth } = support::worm_torque_curve();
    let mut c = config(vec![spec], off(&truth, &[("fm", 1.4)]), &["fm", "Cm"]);
    c.search.max_evaluations = Some(5);
    c.search.starts = Some(2);
    let r = identify(&c, &Monitor::default()).expect("an interrupted search has a result");
    assert!(r.result.interrupted, "{:#?}", r.result.starts);
    assert!(warns(&r, |w| matches!(w, Warning::Interrupted { .. })));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("result.json");
    r.result.write(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    for name in ["fm", "Cm"] {
        let x = v["parameters"][name].as_f64();
        let (lo, hi) = (v["bounds"][name][0].as_f64(), v["bounds"][name][1].as_f64());
        assert!(
            matches!((x, lo, hi), (Some(x), Some(lo), Some(hi)) if x >= lo && x <= hi),
            "{name} = {x:?} outside [{lo:?}, {hi:?}]:\n{text}"
        );
    }
    assert!(v["cost"].as_f64().is_some_and(f64::is_finite), "{text}");
    assert_eq!(v["termination"]["code"], "interrupted", "{text}");
}

/// README's identification without `--fit` (Kw, Kg, Ciw and Cig from 40–60 % off,
/// the linear search's starts then the nonlinear corrections) interrupted after n
/// evaluations — 14 moments through the search's starts, 3 in the corrections' sub-searches —
/// then resumed from the checkpoint: the parameters and cost of the run never
/// interrupted, bit for bit. Issue 37: a start interrupted with its cost still null
/// continued from its last point. Issue 50: the search's result is its best
/// evaluation, which may be a difference step's point rather than a start's result;
/// a resume inside the starts lost it and ended at Ciw 0.32 against 0.15.
#[test]
fn a_resumed_identification_is_the_uninterrupted_one_from_every_moment() {
    let Fixture { spec, truth } = support::worm_frequency_response();
    let base = off(&truth, &[("Kw", 1.4), ("Kg", 1.4), ("Cig", 1.6)]);
    let mut c = config(vec![spec], base, &["Kw", "Kg", "Ciw", "Cig"]);
    let whole = run(&c);
    let total = whole.result.evaluations;
    assert!(total > 1000, "{total} evaluations");
    let dir = tempfile::tempdir().unwrap();
    let checkpoint = dir.path().join("fit.ck.json");
    c.checkpoint = Some(checkpoint.clone());
    // The corrections' last evaluations: their linear sub-searches (the nonlinear
    // test's and the uncertainty's, last of all, are counted but not stopped).
    let search: Vec<usize> = (1..=14).map(|k| k * (total - 400) / 15).collect();
    for n in search
        .into_iter()
        .chain([total - 350, total - 300, total - 250])
    {
        let _ = std::fs::remove_file(&checkpoint);
        c.resume = false;
        c.search.max_evaluations = Some(n);
        let first = run(&c);
        assert!(first.result.interrupted, "stopped after {n} of {total}");
        c.resume = true;
        c.search.max_evaluations = None;
        let again = run(&c);
        assert_eq!(
            (&again.result.parameters, again.result.cost),
            (&whole.result.parameters, whole.result.cost),
            "resumed after {n} of {total} evaluations"
        );
    }
}

#[test]
fn the_paper_worm_resonances_are_out_of_reach_of_kw_and_kg() {
    let Fixture { spec, truth } = support::paper_worm();
    let r = run(&config(vec![spec], truth, &["Kw", "Kg"]));
    assert!(
        warns(&r, |w| matches!(w, Warning::ResonanceMiss { .. })),
        "{:?}",
        r.result.warnings
    );
}

#[test]
fn methods_agree_on_an_easy_problem() {
    let Fixture { spec, truth } = support::worm_frequency_response();
    for method in [Method::NelderMead, Method::Pso] {
        let base = off(&truth, &[("Kw", 1.3), ("Kg", 0.8)]);
        let mut c = config(vec![spec.clone()], base, &["Kw", "Kg"]);
        c.search.method = Some(method);
        c.search.starts = Some(4);
        c.search.max_iters = if method == Method::Pso { 60 } else { 300 };
        let r = run(&c);
        assert_within(&r, &values(&truth, &["Kw", "Kg"]), 0.02);
    }
}

/// The torque-curve objective of the worm fixture and the uncertainty at the truth
/// for `names` (standard machinery: the Jacobian step of a simulated objective).
fn torque_curve_uncertainty(
    names: &[&str],
    step: f64,
) -> rtid::identify::intervals::uncertainty::Assessed {
    use rtid::identify::{intervals::uncertainty::at_optimum, setup, ParamSpace};
    use rtid::objectives::{Fidelity, Stage};
    let Fixture { spec, truth } = support::worm_torque_curve();
    let joint = setup::build(&[spec], Stage::Search, Fidelity::Linear).unwrap();
    let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    let space = ParamSpace::new(truth.clone(), &names, &[]).unwrap();
    let values: Vec<f64> = names
        .iter()
        .map(|n| truth.get(n).unwrap().unwrap())
        .collect();
    at_optimum(&space, &joint, &values, step).unwrap()
}

#[test]
fn the_torque_curve_cannot_separate_motor_from_shaft_friction_but_coulomb_from_viscous() {
    // fm and fw·Rg multiply the sign of the same velocity at the motor: the warning
    // must fire. fm and Cm (Coulomb against viscous) it separates: no warning. The
    // Jacobian step is ±0.1 in ln p: the quantised encoders make the simulated motor
    // torque jitter, and at smaller steps that jitter, not the friction, fills the
    // columns (at 2e-3, identify's step for such fits until then, every correlation
    // of the six friction parameters comes out under 0.2; identify now uses 0.1;
    // docs/identification.md).
    let u = torque_curve_uncertainty(&["fm", "fw"], 0.1);
    eprintln!("fm–fw: {:+.4}", u.uncertainty.correlation[0][1]);
    assert!(
        u.warnings.iter().any(|w| match w {
            Warning::Correlated { a, b, .. } => a == "fm" && b == "fw",
            Warning::Singular { .. } => true,
            _ => false,
        }),
        "fm and fw reach the motor as one Coulomb sum: {:?}",
        u.warnings
    );
    let u = torque_curve_uncertainty(&["fm", "Cm"], 0.1);
    eprintln!("fm–Cm: {:+.4}", u.uncertainty.correlation[0][1]);
    assert!(
        !u.warnings
            .iter()
            .any(|w| matches!(w, Warning::Correlated { .. } | Warning::Singular { .. })),
        "{:?}",
        u.warnings
    );
}

#[test]
#[ignore = "measurement for docs/identification.md: 13 torque-curve simulations"]
fn measure_the_six_friction_correlations_of_the_torque_curve() {
    for step in [2e-3, 2e-2, 0.1, 0.3] {
        let a = torque_curve_uncertainty(&["fm", "fw", "ft", "Cm", "Cw", "Ct"], step);
        let u = &a.uncertainty;
        eprintln!("step {step}: conditioning {:.2e}", u.conditioning);
        for (name, row) in u.names.iter().zip(&u.correlation) {
            let cells: Vec<String> = row.iter().map(|c| format!("{c:+.4}")).collect();
            eprintln!("{name}: {}", cells.join(" "));
        }
        for w in &a.warnings {
            eprintln!("warning: {w}");
        }
    }
}

fn unbalance_config(specs: Vec<ExperimentSpec>, base: Params, fit: &[&str]) -> Config {
    let mut c = config(specs, base, fit);
    c.search.starts = Some(1);
    c.search.method = Some(Method::NelderMead);
    c.search.max_iters = 20;
    c
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (20–40 s): --features slow-tests"
)]
fn table_friction_from_the_unbalance_step_within_5_percent_from_50_percent_off() {
    // The step of the unbalance test stands where m·g·e·sin(θt + ψ) overcomes
    // ft + Ct·ω: the table friction the torque curve cannot see.
    let Fixture { spec, truth } = support::worm_unbalance();
    for start in [1.5, 0.5] {
        let base = off(&truth, &[("ft", start)]);
        let r = run(&unbalance_config(vec![spec.clone()], base, &["ft"]));
        eprintln!(
            "{} from ×{start}: ft = {:.5} ({} evaluations, {:.2} s)",
            spec.source, r.result.parameters["ft"], r.result.evaluations, r.result.wall_time_s
        );
        assert_within(&r, &values(&truth, &["ft"]), 0.05);
    }
}

#[test]
fn the_unbalance_experiment_fits_ft_by_default() {
    let Fixture { spec, truth } = support::worm_unbalance();
    let mut c = unbalance_config(vec![spec], off(&truth, &[("ft", 0.5)]), &[]);
    c.search.max_iters = 1;
    let r = run(&c);
    assert_eq!(
        r.result.parameters.keys().collect::<Vec<_>>(),
        vec!["ft"],
        "{:?}",
        r.result.parameters
    );
    assert_eq!(r.result.residuals[0].objective, "unbalance_step");
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (20–40 s): --features slow-tests"
)]
fn motor_and_table_friction_together_from_the_torque_curve_and_the_unbalance_step() {
    // The answer: fm from the torque curve (the unbalance step hardly moves
    // with it), ft from the unbalance step (the torque curve hardly moves with it);
    // on the noisy fixtures (1 % torque noise, 2″ table-angle noise), fm 50 % low and
    // ft 50 % high at the start.
    let (torque, unbalance) = (
        support::worm_torque_curve_noisy(),
        support::worm_unbalance_noisy(),
    );
    let truth = torque.truth;
    let base = off(&truth, &[("fm", 0.5), ("ft", 1.5)]);
    let mut c = unbalance_config(vec![torque.spec, unbalance.spec], base, &["fm", "ft"]);
    c.search.max_iters = 40;
    let r = run(&c);
    eprintln!(
        "noisy: fm = {:.5}, ft = {:.5} ({} evaluations, {:.2} s); warnings {:?}",
        r.result.parameters["fm"],
        r.result.parameters["ft"],
        r.result.evaluations,
        r.result.wall_time_s,
        r.result.warnings
    );
    assert_within(&r, &values(&truth, &["fm", "ft"]), 0.05);
}
