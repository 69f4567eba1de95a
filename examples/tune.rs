use rtid::input::Move;
use rtid::model::{idx::*, presets, LoopMode};
use rtid::recorder::Trace;
use rtid::sim::Simulation;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    for name in ["worm-gear", "roller-gear-cam"] {
        for mode in [LoopMode::SemiClosed, LoopMode::FullClosed] {
            let mut p = presets::load(name).unwrap();
            p.controller.loop_mode = mode;
            for a in &args[1..] {
                let (k, v) = a.split_once('=').unwrap();
                p.set(k, v.parse().unwrap()).unwrap();
            }
            let mut sim = Simulation::with_default_step(&p).unwrap();
            let mut c = sim.controller(&p).unwrap();
            let target = 30f64.to_radians();
            let mut tr = Trace::every(10);
            let r = sim.run_closed_loop(
                &mut c,
                &Move {
                    from: 0.0,
                    to: target,
                    speed: None,
                },
                2.0,
                &mut tr,
            );
            if let Err(e) = r {
                println!("{name} {mode:?}: {e}");
                continue;
            }
            let s = &tr.samples;
            let err = |x: &rtid::recorder::Sample| (x.y[THETA_T] - target).to_degrees() * 3600.0;
            let last: Vec<_> = s.iter().filter(|x| x.t > 1.5).collect();
            let pp = last.iter().map(|x| err(x)).fold(f64::MIN, f64::max)
                - last.iter().map(|x| err(x)).fold(f64::MAX, f64::min);
            let tq_pp = last.iter().map(|x| x.motor_torque).fold(f64::MIN, f64::max)
                - last.iter().map(|x| x.motor_torque).fold(f64::MAX, f64::min);
            let settle = s
                .iter()
                .rev()
                .find(|x| err(x).abs() > 20.0)
                .map(|x| x.t)
                .unwrap_or(0.0);
            let over = s.iter().map(|x| err(x)).fold(f64::MIN, f64::max);
            println!("{name:16} {mode:?}: settle(20\") {settle:.3}s overshoot {over:.1}\" final err {:.2}\" pp last0.5s {pp:.3}\" torque pp {tq_pp:.3}", err(s.last().unwrap()));
        }
    }
}
