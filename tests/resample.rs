//! The residual block bootstrap (issue 14) on the fixtures: on a torque curve's
//! rough cost, whose standard error misses the truth, its interval holds it and
//! replaces the warning that the standard errors are lower bounds; objectives of a
//! few residuals are refused. (Its agreement with σ²(JᵀJ)⁻¹ on a smooth cost with
//! white errors is tested in src/identify/intervals/resample.rs.)

mod support;

use rtid::identify::intervals::resample::{self, Request};
use rtid::identify::result::resampling::Resampling;
use rtid::identify::{identify, Config, FidelityChoice, Identified, Monitor};
use support::{off, Fixture};

/// The fit of `config`, then its bootstrap with `replicates` replicates.
fn fit_and_resample(config: &Config, replicates: usize) -> (Identified, Resampling) {
    let fit = identify(config, &Monitor::default()).unwrap();
    let request = Request {
        result: &fit.result,
        params: &fit.params,
        objective: fit.objective.as_ref(),
        settings: fit.settings,
        replicates,
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
        replicates: 20,
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
    resample::attach(&mut fit.result, r);
    assert!(!fit.result.warns("rough_cost"));
}
