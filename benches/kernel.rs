//! Integration steps per second of one trajectory, per preset (every topology: the
//! worm's spur gear, the cam's direct, the direct drive, the two-mass drive), open and
//! closed loop; and the same with a Stribeck law on every body (`-stribeck`): what the
//! law costs. `cargo bench --bench kernel`; figures in docs/performance.md.

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use rtid::input::{Move, Sine};
use rtid::model::{presets, Params};
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;

/// Simulated time per iteration, s (20 000 steps at dt = 1e-5 s).
const DURATION: f64 = 0.2;

fn kernel(c: &mut Criterion) {
    let mut group = c.benchmark_group("kernel");
    for name in ["worm-gear", "roller-gear-cam", "direct-drive", "two-mass"] {
        let plain = presets::load(name).unwrap();
        bench_preset(&mut group, name, "", &plain);
        bench_preset(&mut group, name, "-stribeck", &with_stribeck(plain));
    }
    group.finish();
}

/// The preset with a Stribeck rise of half its Coulomb level on every body that has
/// friction (Stribeck speed 0.5 rad/s, δ = 2).
fn with_stribeck(mut p: Params) -> Params {
    for (level, rise, speed) in [
        ("fm", "fsm", "vsm"),
        ("fw", "fsw", "vsw"),
        ("ft", "fst", "vst"),
    ] {
        let applies = p.get(rise).is_ok_and(|r| r.is_some());
        if let (true, Ok(Some(f))) = (applies, p.get(level)) {
            if f > 0.0 {
                p.set(rise, 0.5 * f).unwrap();
                p.set(speed, 0.5).unwrap();
            }
        }
    }
    p.validate().unwrap();
    p
}

/// The open- and closed-loop benches of one parameter set (`law`: the name's suffix).
fn bench_preset(group: &mut BenchmarkGroup<WallTime>, name: &str, law: &str, p: &Params) {
    let dt = rtid::sim::default_step(p).unwrap();
    let steps = (DURATION / dt).round() as u64;
    group.throughput(Throughput::Elements(steps));
    // Open loop: the frequency-response test's ±5 N·m sine near the resonances
    // (with backlash, the worm's meshes open and close: contact events included).
    group.bench_function(format!("{name}/open{law}"), |b| {
        b.iter(|| {
            let mut sim = Simulation::new(p, dt).unwrap();
            let mut input = Sine::new(230.0, 5.0, 0.0);
            sim.run_open_loop(&mut input, DURATION, &mut NullRecorder)
                .unwrap();
            sim.state()
        })
    });
    // Closed loop: the servo moving the table 10°.
    group.bench_function(format!("{name}/closed{law}"), |b| {
        b.iter(|| {
            let mut sim = Simulation::new(p, dt).unwrap();
            let mut controller = sim.controller(p).unwrap();
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

criterion_group!(benches, kernel);
criterion_main!(benches);
