//! Virtual experiments: `cargo bench --bench experiments`; figures in
//! docs/performance.md.
//!
//! `experiments/fixed_work`: the comparison workload of issue 3 — 60 frequencies
//! (10–600 Hz) × 0.3 s simulated at dt = 1e-5 s on the worm-gear preset (1.8 M
//! steps), one independent simulation per frequency, on one thread and on all.
//! `experiments/sweep`: the full frequency-response test with steady-state detection
//! and refinement around the peaks.

use criterion::{criterion_group, criterion_main, Criterion};
use rtid::experiments::frequency_response::{sweep, FrequencyTest};
use rtid::model::presets;

fn experiments(c: &mut Criterion) {
    let p = presets::load("worm-gear").unwrap();
    let fixed = FrequencyTest {
        tolerance_db: 0.0, // never "settled": every frequency runs its full 0.3 s
        max_duration_s: 0.3,
        refine_step_hz: 0.0,
        dt: Some(1e-5),
        ..Default::default()
    };
    let mut group = c.benchmark_group("experiments");
    group.sample_size(10);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        group.bench_function(format!("fixed_work/{threads}_threads"), |b| {
            b.iter(|| pool.install(|| sweep(&p, &fixed, &|| {}).unwrap()))
        });
    }
    let full = FrequencyTest::default();
    group.bench_function("sweep/worm-gear", |b| {
        b.iter(|| sweep(&p, &full, &|| {}).unwrap())
    });
    group.finish();
}

criterion_group!(benches, experiments);
criterion_main!(benches);
