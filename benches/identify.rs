//! Identification: `cargo bench --bench identify`; figures in docs/performance.md.
//!
//! `identify/cost/<fidelity>`: one evaluation of the resonance objective of the
//! worm-gear fixture (two resonances; linear: the exact response, nonlinear: the
//! virtual test located on the measured frequencies, ~25 simulations).
//! `identify/fit/worm-gear`: the README's main job — Kw and Kg from the worm-gear
//! fixture from +40 % starts, defaults (4 starts, lsq, linear search + nonlinear
//! check). `identify/fit/worm-gear-nonlinear`: the same with `--model nonlinear`
//! (issue 4's goal: < 3 s on 2 cores).
//!
//! `identify/complex/…`: the complex residual against the gain alone on the same
//! data (fixtures/frf/worm_frf: the worm's linear response with 2 % complex noise,
//! 5–2000 Hz, 1996 lines), `gain_curve` with the linear model — `cost/*` one
//! evaluation, `fit/*` Kw, Kg, Ciw, Cig from +40 % starts (`--model linear`).
//!
//! `identify/torque-curve/…` on the worm's clean torque curve (fixtures/worm-gear,
//! 6001 samples): `cost` one evaluation (the closed-loop torque test), `fit` fm and
//! Cm from 0.2 and 0.01 (Nelder–Mead, one start), `profile` the profiles of both
//! at that fit (a bowl fitted to the rough cost around it).

#[path = "../tests/support/mod.rs"]
mod support;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rtid::identify::{identify, Config, ExperimentSpec, FidelityChoice, Monitor};
use rtid::objectives::{Fidelity, ObjectiveKind, Source};

fn bench(c: &mut Criterion) {
    // The resonance fit, as measured since issue 4: the fixture's gain alone (with its
    // phase the default is the complex curve, measured in `complex` below).
    let support::Fixture { spec, truth } = support::gain_only(support::worm_frequency_response());
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
    complex(c);
    torque_curve(c);
}

/// The torque-curve fit and its profiles (module docs).
fn torque_curve(c: &mut Criterion) {
    let support::Fixture { spec, truth } = support::worm_torque_curve();
    let start = support::off(&truth, &[("fm", 0.2 / 0.14), ("Cm", 0.01 / 8e-3)]);
    let config = Config::new(vec![spec.clone()], start, &["fm", "Cm"]);
    let source = Source {
        file: &spec.source,
        experiment: &spec.experiment,
    };
    let objective = ObjectiveKind::named("torque_curve")
        .unwrap()
        .build(&source, Fidelity::Nonlinear)
        .unwrap();
    let mut group = c.benchmark_group("identify/torque-curve");
    group.sample_size(10);
    group.throughput(Throughput::Elements(1));
    group.bench_function("cost", |b| b.iter(|| objective.residuals(&truth).unwrap()));
    group.bench_function("fit", |b| {
        b.iter(|| identify(&config, &Monitor::default()).unwrap())
    });
    let fit = identify(&config, &Monitor::default()).unwrap();
    group.bench_function("profile", |b| {
        b.iter(|| support::profiles(&fit, &["fm", "Cm"]))
    });
    group.finish();
}

/// The complex residual against the gain alone (module docs).
fn complex(c: &mut Criterion) {
    let with_phase = support::experiment("frf/worm_frf.json");
    let mut gain_only = with_phase.clone();
    gain_only.experiment.data.drop_phase();
    let truth = rtid::model::presets::load("worm-gear").unwrap();
    let curve = ObjectiveKind::named("gain_curve").unwrap();
    let names = ["Kw", "Kg", "Ciw", "Cig"];
    let factors: Vec<(&str, f64)> = names.iter().map(|n| (*n, 1.4)).collect();
    let start = support::off(&truth, &factors);
    let mut group = c.benchmark_group("identify/complex");
    group.sample_size(10);
    group.throughput(Throughput::Elements(1));
    for (label, spec) in [("phase", &with_phase), ("gain", &gain_only)] {
        let source = Source {
            file: &spec.source,
            experiment: &spec.experiment,
        };
        let obj = curve.build(&source, Fidelity::Linear).unwrap();
        group.bench_function(format!("cost/{label}"), |b| {
            b.iter(|| obj.residuals(&truth).unwrap())
        });
        let mut spec: ExperimentSpec = spec.clone();
        spec.objectives = Some(vec![curve]);
        group.bench_function(format!("fit/{label}"), |b| {
            b.iter(|| {
                let mut config = Config::new(vec![spec.clone()], start.clone(), &names);
                config.fidelity = FidelityChoice::Linear;
                identify(&config, &Monitor::default()).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
