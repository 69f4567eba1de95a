//! One peak finder for every caller: for the same parameters, a sweep's resonance
//! output and an identification's resonance objective report the same resonances.

use rtid::objectives::resonance::ResonanceMatch;
use rtid::objectives::Fidelity;
use rtid::sweep::{Evaluator, Output, TestLength};

use crate::support;

#[test]
fn a_sweep_and_an_identification_report_the_same_resonance() {
    let support::Fixture { spec, truth } = support::worm_frequency_response();
    for p in [
        truth.clone(),
        support::off(&truth, &[("Kw", 1.3), ("Kg", 0.8)]),
    ] {
        let sweep = Evaluator {
            outputs: vec![Output::Resonances],
            tests: TestLength::Short,
            topology: p.topology,
        }
        .evaluate(&p)
        .unwrap();
        // The objective's model resonances, paired with the fixture's two measured ones.
        let test =
            rtid::experiments::frequency_response::measured::frequency_test(&spec.experiment);
        let objective = ResonanceMatch::new(vec![187.0, 234.0], Fidelity::Linear, test);
        let identified = objective.model_hz(&p).unwrap();
        for (k, model) in identified.iter().enumerate() {
            let (a, b) = (model.unwrap(), sweep[k].unwrap());
            assert!(
                ((a - b) / b).abs() < 1e-6,
                "resonance {}: identification {a} Hz, sweep {b} Hz",
                k + 1
            );
        }
    }
}
