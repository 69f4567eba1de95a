//! `rtid tune`'s parts: `cargo bench --bench tuning`; figures in docs/performance.md.
//!
//! `tuning/cascade_margins/worm-gear`: one setting's cascade exact on the sampled loop
//! (the drive held over Tc, the controller's state space) with its margins on 4000
//! points and its stability scanned by the closed loop's poles (`Setting::of`: the
//! velocity loop alone as well).
//! `tuning/screen_4_sets/worm-gear`: four candidates weighed on the nonlinear model in
//! the kernel's lanes — the step and the move, the short ISO 230-2 cycle, its
//! compensation built and run in the controller for a second cycle
//! (`criteria::screen`); the search screens 55 such sets on the worm gear.

use criterion::{criterion_group, criterion_main, Criterion};
use rtid::model::presets;
use rtid::tuning::{criteria, rule, Setting, Targets};

fn tuning(c: &mut Criterion) {
    let p = presets::load("worm-gear").unwrap();
    let mut group = c.benchmark_group("tuning");
    group.sample_size(10);
    group.bench_function("cascade_margins/worm-gear", |b| {
        b.iter(|| Setting::of(&p, &p.controller).unwrap())
    });
    let tuned = rule(&p, Targets::default()).unwrap();
    let sets: Vec<_> = [1.0, 0.5, 0.25, 0.125]
        .iter()
        .map(|k| {
            let mut s = p.clone();
            s.controller = tuned.clone();
            s.controller.kpp *= k;
            s
        })
        .collect();
    group.bench_function("screen_4_sets/worm-gear", |b| {
        b.iter(|| criteria::screen(&sets))
    });
    group.finish();
}

criterion_group!(benches, tuning);
criterion_main!(benches);
