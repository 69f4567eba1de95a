//! The residual block bootstrap (issue 14) on the fixtures: on a torque curve's
//! rough cost, whose standard error misses the truth, its interval holds it and
//! replaces the warning that the standard errors are lower bounds; objectives of a
//! few residuals are refused. (Its agreement with σ²(JᵀJ)⁻¹ on a smooth cost with
//! white errors is tested in src/identify/intervals/resample.rs.)

use rtid::identify::intervals::resample::{self, Request};
use rtid::identify::result::interval::FitInterval;
use rtid::identify::result::resampling::Resampling;
use rtid::identify::{identify, Config, ExperimentSpec, FidelityChoice, Identified, Monitor};

use crate::cli_support::{ok, rtid};
use crate::support::{self, off, Fixture};

/// The fit of `config`, then its bootstrap with `replicates` replicates.
fn fit_and_resample(config: &Config, replicates: usize) -> (Identified, Resampling) {
    let fit = identify(config, &Monitor::default()).unwrap();
    let request = Request {
        result: &fit.result,
        params: &fit.params,
        objective: fit.objective.as_ref(),
        settings: fit.settings,
        replay: fit.replay.as_ref(),
        replicates,
        held: &[],
        stop: &|| false,
        on_replicate: &|| {},
    };
    let resampling = resample::resample(&request).unwrap();
    assert_eq!(resampling.fitted, replicates, "{:?}", resampling.notes);
    (fit, resampling)
}

#[test]
fn a_frequency_responses_two_resonances_are_too_few_to_resample() {
    // Its resonances: the gain alone (with phase the default is the whole curve).
    let Fixture { spec, truth } = support::gain_only(support::worm_frequency_response_noisy());
    let start = off(&truth, &[("Kw", 1.3), ("Kg", 1.2)]);
    let mut c = Config::new(vec![spec], start, &["Kw", "Kg"]);
    c.fidelity = FidelityChoice::Linear;
    let fit = identify(&c, &Monitor::default()).unwrap();
    let request = Request {
        result: &fit.result,
        params: &fit.params,
        objective: fit.objective.as_ref(),
        settings: fit.settings,
        replay: fit.replay.as_ref(),
        replicates: 20,
        held: &[],
        stop: &|| false,
        on_replicate: &|| {},
    };
    let e = resample::resample(&request).unwrap_err().to_string();
    assert!(e.contains("[resonance] has 2 residual(s)"), "{e}");
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (3 min): cargo test --release --features slow-tests"
)]
fn on_a_torque_curves_rough_cost_the_bootstrap_interval_holds_the_truth() {
    // Nelder–Mead from fm 0.2, Cm 0.01 stops at fm 0.13827 (truth 0.14), 4.6
    // standard errors off: the encoders' quantisation gives the cost local minima,
    // and the search stops in one. The replicates stop short the same way (their
    // mean is below the fit), and the interval, moved against that bias, holds
    // the truth.
    let Fixture { spec, truth } = support::worm_torque_curve_noisy();
    let mut start = truth.clone();
    start.set("fm", 0.2).unwrap();
    start.set("Cm", 0.01).unwrap();
    let c = Config::new(vec![spec], start, &["fm", "Cm"]);
    let (mut fit, r) = fit_and_resample(&c, 20);
    let fm = truth.get("fm").unwrap().unwrap();
    let (v, se) = (
        fit.result.parameters["fm"],
        fit.result.standard_error("fm").unwrap(),
    );
    assert!(
        (fm - v).abs() > 1.96 * se,
        "the standard error already holds fm"
    );
    assert!(fit.result.warns("rough_cost"));
    for (name, i) in &r.intervals {
        let want = truth.get(name).unwrap().unwrap();
        assert!(
            i.lower < want && want < i.upper,
            "{name}: {want} outside {i:?}"
        );
    }
    assert_profile_within_bootstrap(&fit, &r, &truth);
    resample::attach(&mut fit.result, r);
    assert!(!fit.result.warns("rough_cost"));
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (1 min): cargo test --release --features slow-tests"
)]
fn on_the_clean_torque_curve_the_profile_holds_the_truth_within_the_bootstrap() {
    let Fixture { spec, truth } = support::worm_torque_curve();
    let mut start = truth.clone();
    start.set("fm", 0.2).unwrap();
    start.set("Cm", 0.01).unwrap();
    let c = Config::new(vec![spec], start, &["fm", "Cm"]);
    let (fit, r) = fit_and_resample(&c, 10);
    assert_profile_within_bootstrap(&fit, &r, &truth);
}

/// How much wider than the bootstrap's the profile interval may be
/// (docs/identification.md): a width from B replicates is itself uncertain by
/// 1/√(2(B − 1)) — 24 % at the clean test's 10, 16 % at 20 — and on a noise-free
/// record the roughness is both the residuals the statistic reads and the scatter
/// that moves the minimum, counted twice (up to √2).
const WIDER: f64 = 2.0;

/// The profile of each fitted parameter (a bowl fitted to the rough cost) holds the
/// truth and is at most [`WIDER`] times the bootstrap's interval. It is mostly
/// narrower: the bootstrap repeats the search, which stops anywhere in the
/// roughness's local minima; the bowl's minimum averages them out.
fn assert_profile_within_bootstrap(fit: &Identified, r: &Resampling, truth: &rtid::model::Params) {
    let names: Vec<&str> = fit.result.parameters.keys().map(String::as_str).collect();
    let (profiles, _) = support::profiles(fit, &names);
    for (name, p) in &profiles {
        let (lo, hi) = (p.lower.unwrap(), p.upper.unwrap());
        let want = truth.get(name).unwrap().unwrap();
        assert!(lo < want && want < hi, "{name}: {want} outside {lo}…{hi}");
        let b = &r.intervals[name];
        assert!(
            hi - lo <= WIDER * (b.upper - b.lower),
            "{name}: profile {lo}…{hi} against the bootstrap's {}…{}",
            b.lower,
            b.upper
        );
    }
}

/// A worm-gear friction map (1 % noise) made by `rtid experiment` in `dir`, with
/// `sets` (NAME=VALUE) on the preset.
fn worm_friction_map(dir: &std::path::Path, sets: &[&str]) -> std::path::PathBuf {
    let mut args = vec!["experiment", "friction-map", "--preset", "worm-gear"];
    args.extend([
        "--noise-percent",
        "1",
        "--seed",
        "2",
        "--out",
        "map",
        "--quiet",
    ]);
    for s in sets {
        args.extend(["--set", s]);
    }
    ok(&rtid(&args, dir));
    dir.join("map/friction_map.json")
}

#[test]
fn a_fit_by_plan_is_resampled_stage_by_stage() {
    // The frequency response determines Kw and Kg, the friction map fm and Cm: the
    // fit runs a stage for each, and each replicate runs the same stages on its data
    // (not one joint search of all four, which is another estimator).
    let dir = tempfile::tempdir().unwrap();
    let map = worm_friction_map(dir.path(), &[]);
    let frf = support::worm_frequency_response();
    let exp = rtid::io::experiment_file::read(&map).unwrap();
    let specs = vec![frf.spec, ExperimentSpec::new("map", exp)];
    let start = off(&frf.truth, &[("Kw", 1.3), ("fm", 1.4)]);
    let c = Config::new(specs, start, &["Kw", "Kg", "fm", "Cm"]);
    let (fit, r) = fit_and_resample(&c, 6);
    let replay = fit
        .replay
        .as_ref()
        .expect("a fit by plan carries its stages");
    let stages: Vec<(usize, Vec<&str>)> = (replay.stages.iter())
        .map(|s| (s.part, s.names.iter().map(String::as_str).collect()))
        .collect();
    assert_eq!(stages, [(0, vec!["Kg", "Kw"]), (1, vec!["Cm", "fm"])]);
    let plan = fit.result.plan.as_ref().unwrap();
    assert_eq!(plan.stages.len(), 2);
    assert!(fit.objective.part(1).is_some() && fit.objective.part(2).is_none());
    // Each replicate's fm comes from the map alone, as the fit's did.
    let fm = fit.result.parameters["fm"];
    for v in &r.values["fm"] {
        assert!(
            (v / fm - 1.0).abs() < 0.02,
            "replicate fm {v} against the fit's {fm}"
        );
    }
    // The stiffnesses' intervals hold the preset. The map's runs average 10⁵
    // samples each, which leaves fm and Cm uncertain by 1e-5 of their values, below
    // the virtual map's own systematic (its runs' mean torque against the law: Cm
    // 7.9994e-3 for 8e-3): theirs are checked at 0.1 %.
    for (name, i) in &r.intervals {
        let want = frf.truth.get(name).unwrap().unwrap();
        let margin = if name.starts_with('K') {
            0.0
        } else {
            1e-3 * want
        };
        assert!(
            i.lower - margin < want && want < i.upper + margin,
            "{name}: {want} outside {i:?}"
        );
        assert!(i.at_bound.is_none(), "{name}");
    }
}

#[test]
#[ignore = "coverage tier (about 3 min on 2 cores): cargo test --profile test-release -- --ignored not_the_preset"]
fn on_a_machine_that_is_not_the_preset_every_interval_holds_or_is_not_determined() {
    // Issue 57's machine: Kw −15 %, Kg +20 %, Cig ×2, θbw ×1.5, fm ×1.3; its
    // frequency response and torque curve with 1 % noise, fitted by rtid's
    // defaults. The torque curve's cost in θbw is a plateau below the machine's
    // value: the fit stops at −71 % and 4 of 12 replicates run to the lower bound,
    // so θbw is said not determined; every other interval holds the machine's value
    // (before the replicates replayed the plan, Cig's excluded it).
    let dir = tempfile::tempdir().unwrap();
    let sets = [
        "Kw=263500",
        "Kg=1020",
        "Cig=0.1",
        "theta_bw=1.2e-4",
        "fm=0.182",
    ];
    let mut made = vec![
        "params",
        "--preset",
        "worm-gear",
        "--out",
        "machine.json",
        "--quiet",
    ];
    for s in &sets {
        made.extend(["--set", s]);
    }
    ok(&rtid(&made, dir.path()));
    for test in ["frequency-response", "torque-curve"] {
        let args = [
            "experiment",
            test,
            "--params",
            "machine.json",
            "--noise-percent",
            "1",
        ];
        let args = [&args[..], &["--seed", "3", "--out", "rec", "--quiet"]].concat();
        ok(&rtid(&args, dir.path()));
    }
    let fitted = ok(&rtid(
        &[
            "identify",
            "rec/frequency_response.json",
            "rec/torque_curve.json",
            "--preset",
            "worm-gear",
            "--fit",
            "Kw,Kg,Cig,fm,theta_bw",
            "--json",
            "--quiet",
        ],
        dir.path(),
    ));
    let result: rtid::identify::IdentifyResult = serde_json::from_str(&fitted).unwrap();
    let machine = rtid::io::params_file::read(&dir.path().join("machine.json")).unwrap();
    let mut undetermined = Vec::new();
    for name in result.parameters.keys() {
        let want = machine.get(name).unwrap().unwrap();
        match result.interval(name) {
            Some(FitInterval::Bounds { lower, upper, .. }) => {
                assert!(
                    lower <= want && want <= upper,
                    "{name}: {want} outside {lower}…{upper}"
                )
            }
            Some(FitInterval::NotDetermined(_)) => undetermined.push(name.as_str()),
            other => panic!("{name}: {other:?}"),
        }
    }
    assert_eq!(undetermined, ["theta_bw"]);
    assert!(result.warns("bootstrap_at_bound"));
}
