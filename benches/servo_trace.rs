//! Servo traces: `cargo bench --bench servo_trace`; figures in docs/performance.md.
//!
//! On the EMPS estimation record (24 841 samples, fixtures/real/emps):
//! `servo_trace/idim` — the IDIM-LS friction law (filters, decimation, least squares);
//! `servo_trace/replay` — one closed-loop replay of the whole record on the published
//! model, the unit of cost of the output-error identification (`servo-trace`
//! objective: 14 replays from the IDIM estimate with Levenberg–Marquardt);
//! `servo_trace/replay_4_sets/{lanes,lone}` — four parameter sets (a Jacobian's
//! columns) replayed in the kernel's lanes, and one after another;
//! `servo_trace/replay_2_sets/lanes` — two of them, as each core runs a Jacobian's
//! four columns on two cores;
//! `servo_trace/replay_drive_functions` — the same with the drive's functions on:
//! velocity and torque feed-forward, the symmetrising lag and four setpoint filters;
//! `servo_trace/identify` — the whole EMPS identification as `rtid identify` runs it:
//! the IDIM-LS start, then the output-error search of Jt, Ct, ft, Tload
//! (Levenberg–Marquardt, its points in lanes) and the uncertainty at the result.

use std::path::PathBuf;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rtid::estimation::inverse_dynamics::IdimSettings;
use rtid::experiments::servo_trace::{replay, replay_batch, ServoTrace};
use rtid::identify::{identify, Config, ExperimentSpec, Monitor};
use rtid::io::experiment_file::{self, Data};
use rtid::model::{Params, SetpointFilter};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fixtures/real/emps")
}

fn emps() -> (ServoTrace, Params) {
    let root = root();
    let e = experiment_file::read(&root.join("emps_estimation.json")).unwrap();
    let Data::ServoTrace(file) = &e.data else {
        panic!("not a servo trace")
    };
    let text = std::fs::read_to_string(root.join("axis.json")).unwrap();
    (
        ServoTrace::from_file(file),
        serde_json::from_str(&text).unwrap(),
    )
}

fn bench(c: &mut Criterion) {
    let (trace, params) = emps();
    let mut group = c.benchmark_group("servo_trace");
    group.sample_size(20);
    group.throughput(Throughput::Elements(trace.len() as u64));
    group.bench_function("idim", |b| {
        b.iter(|| trace.fit_friction(&IdimSettings::default()).unwrap())
    });
    group.bench_function("replay", |b| b.iter(|| replay(&params, &trace).unwrap()));
    // Four parameter sets (a Jacobian's columns) in lanes, and the same one by one.
    let sets = columns(&params);
    group.bench_function("replay_4_sets/lanes", |b| {
        b.iter(|| replay_batch(&sets, &trace))
    });
    group.bench_function("replay_4_sets/lone", |b| {
        b.iter(|| sets.iter().map(|p| replay(p, &trace)).collect::<Vec<_>>())
    });
    // Two sets in lanes: a Jacobian of four columns split over two cores.
    group.bench_function("replay_2_sets/lanes", |b| {
        b.iter(|| replay_batch(&sets[..2], &trace))
    });
    let functions = with_drive_functions(&params);
    group.bench_function("replay_drive_functions", |b| {
        b.iter(|| replay(&functions, &trace).unwrap())
    });
    group.finish();
}

/// `params` with each of Jt, Ct, ft, Tload 3 % higher: the points of a
/// forward-difference Jacobian.
fn columns(params: &Params) -> Vec<Params> {
    ["Jt", "Ct", "ft", "Tload"]
        .iter()
        .map(|name| {
            let mut p = params.clone();
            let v = p.get(name).unwrap().unwrap();
            p.set(name, 1.03 * v).unwrap();
            p
        })
        .collect()
}

/// `params` with feed-forward, the symmetrising lag and four setpoint filters on.
fn with_drive_functions(params: &Params) -> Params {
    let mut p = params.clone();
    let c = &mut p.controller;
    (c.kvff, c.kaff, c.symmetrising_s) = (1.0, p.jt / c.drive_gain, 1e-3);
    let notch = |centre_hz| SetpointFilter::Notch {
        centre_hz,
        width_hz: 20.0,
        depth_db: Some(-20.0),
    };
    c.filters = vec![
        SetpointFilter::LowPass {
            frequency_hz: 200.0,
            damping: 0.7,
        },
        notch(80.0),
        notch(120.0),
        notch(160.0),
    ];
    p.validate().unwrap();
    p
}

/// The whole identification: seconds per run, so the fewest samples criterion allows.
fn bench_identify(c: &mut Criterion) {
    let (_, params) = emps();
    let e = experiment_file::read(&root().join("emps_estimation.json")).unwrap();
    let config = Config::new(
        vec![ExperimentSpec::new("emps_estimation.json", e)],
        params,
        &[],
    );
    let mut group = c.benchmark_group("servo_trace");
    group.sample_size(10);
    group.bench_function("identify", |b| {
        b.iter(|| identify(&config, &Monitor::default()).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench, bench_identify);
criterion_main!(benches);
