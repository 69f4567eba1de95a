//! Integration steps per second of one trajectory, per preset (every topology: the
//! worm's spur gear, the cam's direct, the direct drive, the two-mass drive), open and
//! closed loop. `cargo bench --bench kernel`; figures in docs/performance.md.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rtid::input::{Move, Sine};
use rtid::model::presets;
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;

/// Simulated time per iteration, s (20 000 steps at dt = 1e-5 s).
const DURATION: f64 = 0.2;

fn kernel(c: &mut Criterion) {
    let mut group = c.benchmark_group("kernel");
    for name in ["worm-gear", "roller-gear-cam", "direct-drive", "two-mass"] {
        let p = presets::load(name).unwrap();
        let dt = rtid::sim::default_step(&p).unwrap();
        let steps = (DURATION / dt).round() as u64;
        group.throughput(Throughput::Elements(steps));
        // Open loop: the frequency-response test's ±5 N·m sine near the resonances
        // (with backlash, the worm's meshes open and close: contact events included).
        group.bench_function(format!("{name}/open"), |b| {
            b.iter(|| {
                let mut sim = Simulation::new(&p, dt).unwrap();
                let mut input = Sine::new(230.0, 5.0, 0.0);
                sim.run_open_loop(&mut input, DURATION, &mut NullRecorder)
                    .unwrap();
                sim.state()
            })
        });
        // Closed loop: the servo moving the table 10°.
        group.bench_function(format!("{name}/closed"), |b| {
            b.iter(|| {
                let mut sim = Simulation::new(&p, dt).unwrap();
                let mut controller = sim.controller(&p).unwrap();
                let step = Move {
                    from: 0.0,
                    to: 10f64.to_radians(),
                    speed: None,
                };
                sim.run_closed_loop(&mut controller, &step, DURATION, &mut NullRecorder)
                    .unwrap();
                sim.state()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, kernel);
criterion_main!(benches);
