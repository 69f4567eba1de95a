//! Identification: `cargo bench --bench identify`; figures in docs/performance.md.
//!
//! `identify/cost/<fidelity>`: one evaluation of the resonance objective of the
//! worm-gear fixture (two resonances; linear: the exact response, nonlinear: the
//! virtual test located on the measured frequencies, ~25 simulations).
//! `identify/fit/worm-gear`: the README's main job — Kw and Kg from the worm-gear
//! fixture from +40 % starts, defaults (4 starts, lsq, linear search + nonlinear
//! check). `identify/fit/worm-gear-nonlinear`: the same with `--model nonlinear`
//! (issue 4's goal: < 3 s on 2 cores).

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rtid::identify::setup::{frequency_test, measured_grid};
use rtid::identify::{identify, Config, FidelityChoice, Monitor};
use rtid::io::experiment_file;
use rtid::model::presets;
use rtid::objectives::{resonance::ResonanceMatch, Fidelity, Objective};

fn bench(c: &mut Criterion) {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/worm-gear/frequency_response.json");
    let exp = experiment_file::read(&path).unwrap();
    let p = presets::load("worm-gear").unwrap();
    let peaks: Vec<f64> = rtid::identify::setup::measured_peaks("fixture", &exp)
        .unwrap()
        .iter()
        .map(|k| k.frequency_hz)
        .collect();
    let mut group = c.benchmark_group("identify");
    group.sample_size(10);
    group.throughput(Throughput::Elements(1));
    for fidelity in [Fidelity::Linear, Fidelity::Nonlinear] {
        let obj = ResonanceMatch::new(peaks.clone(), fidelity, frequency_test(&exp))
            .on_grid(measured_grid(&exp).expect("a gain curve"));
        group.bench_function(format!("cost/{}", fidelity.name()), |b| {
            b.iter(|| obj.residuals(&p).unwrap())
        });
    }
    let mut start = p.clone();
    start.kw *= 1.4;
    start.kg = start.kg.map(|k| k * 1.4);
    group.bench_function("fit/worm-gear", |b| {
        b.iter(|| {
            let config = Config::new(
                vec![("fixture".into(), exp.clone())],
                start.clone(),
                &["Kw", "Kg"],
            );
            identify(&config, &Monitor::default()).unwrap()
        })
    });
    group.bench_function("fit/worm-gear-nonlinear", |b| {
        b.iter(|| {
            let mut config = Config::new(
                vec![("fixture".into(), exp.clone())],
                start.clone(),
                &["Kw", "Kg"],
            );
            config.fidelity = FidelityChoice::Nonlinear;
            identify(&config, &Monitor::default()).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
