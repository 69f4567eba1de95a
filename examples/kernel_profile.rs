//! A plain binary around the kernel for instruction-level profiling, where a
//! criterion bench is awkward (valgrind, perf):
//!
//!     cargo build --release --example kernel_profile
//!     valgrind --tool=callgrind target/release/examples/kernel_profile worm-gear 0.2
//!     target/release/examples/kernel_profile worm-gear 2 lanes=8
//!     target/release/examples/kernel_profile worm-gear 2 closed
//!
//! Arguments: preset name, simulated seconds (default 2), then NAME=VALUE overrides
//! of parameters, `lanes=L` (1, 2, 4 or 8) and `closed`. Runs the frequency-response
//! test's ±5 N·m open-loop sine at dt = 1e-5 s: at 230 Hz through `Simulation` for one
//! lane; for `L` lanes, `L` trajectories at 230, 240, … Hz advanced together by a
//! `Kernel<L>` (no divergence check, no recorder). With `closed`, the kernel bench's
//! closed-loop run instead: the servo moving the table (or carriage) by 10° (0.1745
//! rad or m) through `Simulation::run_closed_loop`, one lane.

use rtid::input::{Move, Sine, TorqueInput};
use rtid::model::{presets, Drive, Kernel, LaneDrive, NSTATE};
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;

const DT: f64 = 1e-5;

/// Lane-steps per second of `L` sines through a `Kernel<L>`, and the events.
fn lanes<const L: usize>(d: &Drive, seconds: f64) -> (f64, f64, u64) {
    let lanes = LaneDrive::<L>::splat(d);
    let mut kernel = Kernel::<L>::default();
    let mut y = [[0.0; L]; NSTATE];
    let mut inputs: [Sine; L] =
        std::array::from_fn(|l| Sine::new(230.0 + 10.0 * l as f64, 5.0, 0.0));
    let n = (seconds / DT).round() as u64;
    let started = std::time::Instant::now();
    for k in 0..n {
        let t = k as f64 * DT;
        let mut motor = [[0.0; L]; 3];
        for (l, input) in inputs.iter_mut().enumerate() {
            let m = input.step_torques(t, DT);
            for s in 0..3 {
                motor[s][l] = m[s];
            }
        }
        kernel.step(&lanes, &mut y, &motor, &[d.tload(); L], DT);
    }
    let wall = started.elapsed().as_secs_f64();
    std::hint::black_box(y);
    ((n * L as u64) as f64, wall, kernel.events())
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or_else(|| "worm-gear".into());
    let seconds: f64 = args.next().map(|s| s.parse()).transpose()?.unwrap_or(2.0);
    let mut p = presets::load(&name)?;
    let mut width = 1;
    let mut closed = false;
    for a in args {
        if a == "closed" {
            closed = true;
            continue;
        }
        let (k, v) = a
            .split_once('=')
            .ok_or_else(|| anyhow::anyhow!("{a}: NAME=VALUE"))?;
        if k == "lanes" {
            width = v.parse()?;
        } else {
            p.set(k, v.parse()?)?;
        }
    }
    let (steps, wall, events) = if closed {
        let mut sim = Simulation::new(&p, DT)?;
        let mut controller = sim.controller(&p)?;
        let step = Move {
            from: 0.0,
            to: 10f64.to_radians(),
            speed: None,
        };
        let started = std::time::Instant::now();
        sim.run_closed_loop(&mut controller, &step, seconds, &mut NullRecorder)?;
        let wall = started.elapsed().as_secs_f64();
        (sim.time() / sim.dt(), wall, sim.contact_events())
    } else if width == 1 {
        let mut sim = Simulation::new(&p, DT)?;
        let started = std::time::Instant::now();
        sim.run_open_loop(&mut Sine::new(230.0, 5.0, 0.0), seconds, &mut NullRecorder)?;
        let wall = started.elapsed().as_secs_f64();
        (sim.time() / sim.dt(), wall, sim.contact_events())
    } else {
        let d = Drive::new(&p)?;
        match width {
            2 => lanes::<2>(&d, seconds),
            4 => lanes::<4>(&d, seconds),
            8 => lanes::<8>(&d, seconds),
            _ => anyhow::bail!("lanes must be 1, 2, 4 or 8"),
        }
    };
    println!(
        "{name}, {width} lane(s): {steps:.0} lane-steps in {wall:.3} s = {:.2} M lane-steps/s, {events} split at contact events",
        steps / wall / 1e6,
    );
    Ok(())
}
