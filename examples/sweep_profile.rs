//! The fixed-work frequency-response workload of `benches/experiments.rs` as a plain
//! binary, for instruction counts (valgrind) where criterion is awkward:
//!
//!     cargo build --release --example sweep_profile
//!     valgrind --tool=callgrind target/release/examples/sweep_profile 0.3 1
//!
//! Arguments: simulated seconds per frequency (default 0.3; `full`: the whole
//! default test with steady-state detection and refinement, as the bench
//! `experiments/sweep/worm-gear`), threads (default 1). Otherwise 60 frequencies
//! (10–600 Hz), worm-gear preset, dt = 1e-5 s, never settling.

use rtid::experiments::frequency_response::{sweep, FrequencyTest};
use rtid::model::presets;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let first = args.next().unwrap_or_else(|| "0.3".into());
    let threads: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(1);
    let p = presets::load("worm-gear")?;
    let test = if first == "full" {
        FrequencyTest::default()
    } else {
        FrequencyTest {
            tolerance_db: 0.0,
            max_duration_s: first.parse()?,
            refine_step_hz: 0.0,
            dt: Some(1e-5),
            ..Default::default()
        }
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let started = std::time::Instant::now();
    let points = pool.install(|| sweep(&p, &test, &|| {}))?;
    let wall = started.elapsed().as_secs_f64();
    let dt = rtid::sim::default_step(&p)?;
    let lane_steps: f64 = points.iter().map(|q| q.simulated_s / dt).sum();
    println!(
        "{} frequencies, {lane_steps:.0} lane-steps in {wall:.3} s on {threads} thread(s) = {:.2} M lane-steps/s",
        points.len(),
        lane_steps / wall / 1e6
    );
    Ok(())
}
