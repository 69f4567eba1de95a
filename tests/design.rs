//! Experiment design (issue 14): the Fisher information of each candidate test,
//! simulated on the model, ranks the tests as the physics says it should.

use std::collections::BTreeMap;

use rtid::experiments::fluctuation::FluctuationTest;
use rtid::experiments::frequency_response::FrequencyTest;
use rtid::experiments::torque_curve::TorqueTest;
use rtid::identify::design::{self, Candidate, Criterion, Request, Test};
use rtid::model::presets;

fn frequency_response(label: &str, amplitude_nm: f64, preload_nm: f64) -> Candidate {
    Candidate {
        label: label.into(),
        settings: BTreeMap::from([
            ("amplitude_nm".to_string(), amplitude_nm),
            ("preload_nm".to_string(), preload_nm),
        ]),
        test: Test::FrequencyResponse(FrequencyTest {
            frequencies_hz: (0..=55).map(|i| 150.0 + 2.0 * i as f64).collect(),
            amplitude_nm,
            preload_nm,
            ..FrequencyTest::default()
        }),
    }
}

/// The worm preset's candidates ranked for `fit` (D-optimal, σ = 1).
fn rank(fit: &[&str], candidates: &[Candidate]) -> Vec<design::Assessed> {
    let p = presets::load("worm-gear").unwrap();
    let fit: Vec<String> = fit.iter().map(|s| s.to_string()).collect();
    let request = Request {
        params: &p,
        fit: &fit,
        noise: 1.0,
        criterion: Criterion::D,
        on_done: &|| {},
    };
    design::rank(&request, candidates).unwrap()
}

#[test]
fn for_kw_and_kg_a_preloaded_frequency_response_beats_an_unloaded_one() {
    let ranked = rank(
        &["Kw", "Kg"],
        &[
            frequency_response("unloaded ±5 N·m", 5.0, 0.0),
            frequency_response("preloaded ±20 N·m", 20.0, 2000.0),
        ],
    );
    for a in &ranked {
        eprintln!(
            "{} {:?} {:?} {:?}",
            a.label, a.score, a.predicted_se, a.correlations
        );
    }
    assert_eq!(ranked[0].label, "preloaded ±20 N·m");
}

#[test]
fn for_table_friction_the_unbalance_test_beats_the_torque_curve() {
    let unbalance = Candidate {
        label: "unbalance".into(),
        settings: BTreeMap::new(),
        test: Test::Unbalance(FluctuationTest {
            speed: 6f64.to_radians(),
            unbalance: Some((10.0, 0.1)),
            ..FluctuationTest::default()
        }),
    };
    let torque = Candidate {
        label: "torque curve".into(),
        settings: BTreeMap::new(),
        test: Test::TorqueCurve(TorqueTest::default()),
    };
    let ranked = rank(&["ft"], &[torque, unbalance]);
    // The table's friction reaches the motor divided by the ratio (1/90): the torque
    // curve hardly sees it (predicted 24 % against the unbalance test's 3.6 %).
    assert_eq!(ranked[0].label, "unbalance", "{ranked:?}");
    assert!(
        ranked[1].score.unwrap() > 3.0 * ranked[0].score.unwrap(),
        "{ranked:?}"
    );
}
