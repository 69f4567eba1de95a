//! Identification: `cargo bench --bench identify`; figures in docs/performance.md.
//!
//! `identify/cost/<fidelity>`: one evaluation of the resonance objective of the
//! worm-gear fixture (two resonances; linear: the exact response, nonlinear: the
//! virtual test located on the measured frequencies, ~25 simulations).
//! `identify/fit/worm-gear`: the README's main job — Kw and Kg from the worm-gear
//! fixture from +40 % starts, defaults (4 starts, lsq, linear search + nonlinear
//! check). `identify/fit/worm-gear-nonlinear`: the same with `--model nonlinear`
//! (issue 4's goal: < 3 s on 2 cores).

#[path = "../tests/support/mod.rs"]
mod support;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rtid::identify::{identify, Config, FidelityChoice, Monitor};
use rtid::objectives::{Fidelity, ObjectiveKind, Source};

fn bench(c: &mut Criterion) {
    let support::Fixture { spec, truth } = support::worm_frequency_response();
    let source = Source {
        file: &spec.source,
        experiment: &spec.experiment,
    };
    let resonance = ObjectiveKind::named("resonance").unwrap();
    let mut group = c.benchmark_group("identify");
    group.sample_size(10);
    group.throughput(Throughput::Elements(1));
    for fidelity in [Fidelity::Linear, Fidelity::Nonlinear] {
        let obj = resonance.build(&source, fidelity).unwrap();
        group.bench_function(format!("cost/{}", fidelity.name()), |b| {
            b.iter(|| obj.residuals(&truth).unwrap())
        });
    }
    let start = support::off(&truth, &[("Kw", 1.4), ("Kg", 1.4)]);
    group.bench_function("fit/worm-gear", |b| {
        b.iter(|| {
            let config = Config::new(vec![spec.clone()], start.clone(), &["Kw", "Kg"]);
            identify(&config, &Monitor::default()).unwrap()
        })
    });
    group.bench_function("fit/worm-gear-nonlinear", |b| {
        b.iter(|| {
            let mut config = Config::new(vec![spec.clone()], start.clone(), &["Kw", "Kg"]);
            config.fidelity = FidelityChoice::Nonlinear;
            identify(&config, &Monitor::default()).unwrap()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
