//! A plain binary around the kernel for instruction-level profiling, where a
//! criterion bench is awkward (valgrind, perf):
//!
//!     cargo build --release --example kernel_profile
//!     valgrind --tool=callgrind target/release/examples/kernel_profile worm-gear 0.2
//!
//! Arguments: preset name, simulated seconds (default 2), then NAME=VALUE overrides.
//! Runs the frequency-response test's ±5 N·m, 230 Hz open-loop sine at dt = 1e-5 s.

use rtid::input::Sine;
use rtid::model::presets;
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "worm-gear".into());
    let seconds: f64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(2.0);
    let mut p = presets::load(&name)?;
    for a in args {
        let (k, v) = a
            .split_once('=')
            .ok_or_else(|| anyhow::anyhow!("{a}: NAME=VALUE"))?;
        p.set(k, v.parse()?)?;
    }
    let mut sim = Simulation::new(&p, 1e-5)?;
    let started = std::time::Instant::now();
    sim.run_open_loop(&mut Sine::new(230.0, 5.0, 0.0), seconds, &mut NullRecorder)?;
    let wall = started.elapsed().as_secs_f64();
    let steps = sim.time() / sim.dt();
    println!(
        "{name}: {steps:.0} steps in {wall:.3} s = {:.2} M steps/s, {} split at contact events",
        steps / wall / 1e6,
        sim.contact_events()
    );
    Ok(())
}
