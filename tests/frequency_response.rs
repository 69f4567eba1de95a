//! The virtual frequency-response test (docs/experiments.md (frequency response)).

use rtid::estimation::peaks::maxima as peaks;
use rtid::experiments::frequency_response::{linear, sweep, FrequencyTest};
use rtid::model::{presets, Params};

/// The preset made linear: no backlash, no Coulomb friction, no fluctuation.
fn linear_limit(name: &str) -> Params {
    let mut p = presets::load(name).unwrap();
    (p.fm, p.fw, p.ft, p.theta_bw, p.w) = (0.0, 0.0, 0.0, 0.0, 0.0);
    if p.theta_bg.is_some() {
        p.theta_bg = Some(0.0);
    }
    p
}

#[test]
fn in_the_linear_limit_simulated_peaks_match_the_frequency_domain_ones() {
    for name in ["worm-gear", "roller-gear-cam"] {
        let p = linear_limit(name);
        let test = FrequencyTest::default();
        let points = sweep(&p, &test, &|| {}).unwrap();
        assert!(
            points.iter().all(|q| q.settled),
            "{name}: every point settles"
        );
        assert!(points.iter().all(|q| q.contact_loss == [0.0, 0.0]));
        let simulated = peaks(
            &points
                .iter()
                .map(|q| (q.frequency_hz, q.gain_db))
                .collect::<Vec<_>>(),
            2,
        );
        // The same peaks of the exact linear response on a 0.01 Hz grid.
        let grid: Vec<f64> = (1000..60000).map(|i| i as f64 * 0.01).collect();
        let gains = linear(&p, &grid).unwrap();
        let curve: Vec<(f64, f64)> = grid.iter().zip(&gains).map(|(&f, g)| (f, g.0)).collect();
        let exact = peaks(&curve, simulated.len());
        eprintln!("{name}: simulated {simulated:?}\n   linear {exact:?}");
        assert_eq!(simulated.len(), exact.len(), "{name}");
        for (s, e) in simulated.iter().zip(&exact) {
            assert!(
                (s.frequency_hz - e.frequency_hz).abs() < 0.5,
                "{name}: {s:?} vs {e:?}"
            );
        }
    }
}
