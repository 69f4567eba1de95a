//! Sensitivity sweeps: `cargo bench --bench sweep`; figures in docs/performance.md
//! ("Sweeps").
//!
//! `sweep/point/linear`: one design point of the linear outputs (resonances +
//! peak_gain + modes) on the worm-gear preset.
//! `sweep/sobol_1000_linear/{1,2}_threads`: the whole `rtid sweep` of a 1000-point
//! Sobol design (N = 250 base rows, k = 2: Kw, Jt) on resonances + peak_gain — design,
//! parallel evaluation, a flushed CSV row per point, the sorted atomic rewrite — into
//! a temporary folder.
//! `sweep/point/nonlinear_short`: one point of reversal, repeatability, accuracy,
//! fluctuation_pp and torque_rms with the short tests.
//! `sweep/reversal/{lone,batch}_4_points`: the `reversal` output (the short
//! positioning test, closed loop) at 4 design points (Kw ±20 %), evaluated one by one
//! and as one batch in the kernel's lanes: the batch's time per point against a lone
//! point's is issue 38's measure.
//! `sweep/design/sobol_4096x3`: the Saltelli design of 4096 base rows, 3 factors
//! (20 480 points) built into its matrices.
//! `sweep/ishigami_indices`: Sobol S1/ST with 100 bootstrap resamples from
//! 4096 × (3 + 2) outputs (the analysis alone).

use criterion::{criterion_group, criterion_main, Criterion};
use rtid::model::presets;
use rtid::sweep::{
    self, designs::Design, sobol, Factor, Method, Output, RunOptions, Scale, Sweep, TestLength,
};

fn linear_sobol(samples: usize) -> Sweep {
    let p = presets::load("worm-gear").unwrap();
    let factors = vec![
        Factor::new("Kw", 1e5, 1e6, Scale::Log, 2).unwrap(),
        Factor::new("Jt", 0.08, 0.14, Scale::Lin, 2).unwrap(),
    ];
    Sweep::new(
        p,
        factors,
        Method::Sobol {
            samples,
            bootstrap: 200,
        },
        vec![Output::Resonances, Output::PeakGain],
        TestLength::Short,
        0,
    )
    .unwrap()
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("sweep");
    group.sample_size(10);
    let p = presets::load("worm-gear").unwrap();
    let linear = sweep::Evaluator {
        outputs: vec![Output::Resonances, Output::PeakGain, Output::Modes],
        tests: TestLength::Short,
        topology: p.topology,
    };
    group.bench_function("point/linear", |b| b.iter(|| linear.evaluate(&p).unwrap()));
    let s = linear_sobol(250);
    assert_eq!(s.design().unwrap().len(), 1000);
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sobol.csv");
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        group.bench_function(format!("sobol_1000_linear/{threads}_threads"), |b| {
            b.iter(|| {
                let opts = RunOptions {
                    overwrite: true,
                    ..RunOptions::default()
                };
                pool.install(|| sweep::run(&s, &out, &opts).unwrap())
            })
        });
    }
    let nonlinear = sweep::Evaluator {
        outputs: vec![
            Output::Reversal,
            Output::Repeatability,
            Output::Accuracy,
            Output::FluctuationPp,
            Output::TorqueRms,
        ],
        tests: TestLength::Short,
        topology: p.topology,
    };
    group.bench_function("point/nonlinear_short", |b| {
        b.iter(|| nonlinear.evaluate(&p).unwrap())
    });
    reversal(&mut group);
    let factors: Vec<Factor> = (0..3)
        .map(|i| {
            let pi = std::f64::consts::PI;
            Factor::new(&format!("x{i}"), -pi, pi, Scale::Lin, 2).unwrap()
        })
        .collect();
    let m = Method::Sobol {
        samples: 4096,
        bootstrap: 100,
    };
    let d = Design::new(&m, &factors, &[], 0).unwrap();
    let y: Vec<f64> = d
        .values
        .rows()
        .into_iter()
        .map(|x| x[0].sin() + 7.0 * x[1].sin().powi(2) + 0.1 * x[2].powi(4) * x[0].sin())
        .collect();
    group.bench_function("design/sobol_4096x3", |b| {
        b.iter(|| Design::new(&m, &factors, &[], 0).unwrap())
    });
    group.bench_function("ishigami_indices", |b| {
        b.iter(|| sobol::indices(&y, 3, 4096, 100, 0.95, 0).unwrap())
    });
    group.finish();
}

/// `reversal` at 4 design points, lone and batched, and at 8 batched (two batches
/// of [`rtid::sim::LANES`] = 4 lanes; one of 8 where the width is 8: the width's
/// measurement, docs/performance.md).
fn reversal(group: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>) {
    let base = presets::load("worm-gear").unwrap();
    let factors = [0.8, 0.93, 1.07, 1.2, 0.85, 0.97, 1.03, 1.15];
    let all: Vec<_> = factors
        .iter()
        .map(|f| {
            let mut p = base.clone();
            p.kw *= f;
            p
        })
        .collect();
    let points = &all[..4];
    let reversal = sweep::Evaluator {
        outputs: vec![Output::Reversal],
        tests: TestLength::Short,
        topology: base.topology,
    };
    group.bench_function("reversal/lone_4_points", |b| {
        b.iter(|| {
            let rows: Vec<_> = points.iter().map(|p| reversal.evaluate(p)).collect();
            rows
        })
    });
    group.bench_function("reversal/batch_4_points", |b| {
        b.iter(|| reversal.evaluate_batch(points))
    });
    group.bench_function("reversal/batch_8_points", |b| {
        b.iter(|| reversal.evaluate_batch(&all))
    });
}

criterion_group!(sweeps, benches);
criterion_main!(sweeps);
