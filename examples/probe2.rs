use rtid::input::Sine;
use rtid::model::{idx::*, presets, Params, Topology};
use rtid::recorder::Trace;
use rtid::sim::Simulation;
fn main() {
    for (fric, kg) in [(true, 2e6), (false, 2e6), (false, 2e7), (true, 2e7)] {
        let mut spur = presets::load("worm-gear").unwrap();
        spur.rg = Some(1.0);
        spur.kg = Some(kg);
        spur.cig = Some(20.0);
        spur.theta_bg = Some(0.0);
        if !fric {
            spur.fm = 0.0;
            spur.fw = 0.0;
            spur.ft = 0.0;
        }
        spur.theta_bw = 0.0;
        let mut direct = spur.clone();
        direct.topology = Topology::Direct;
        direct.kg = None;
        direct.rg = None;
        direct.cig = None;
        direct.theta_bg = None;
        let dt = rtid::sim::default_step(&spur).unwrap();
        let run = |p: &Params| {
            let mut sim = Simulation::new(p, dt).unwrap();
            let mut tr = Trace::every(20);
            sim.run_open_loop(&mut Sine::new(40.0, 3.0, 0.5), 0.25, &mut tr)
                .unwrap();
            tr.samples
        };
        let a = run(&spur);
        let b = run(&direct);
        let scale = a.iter().map(|s| s.y[THETA_T].abs()).fold(0.0, f64::max);
        let (mut worst, mut at) = (0.0, 0.0);
        for (x, y) in a.iter().zip(&b) {
            let d = (x.y[THETA_T] - y.y[THETA_T]).abs();
            if d > worst {
                worst = d;
                at = x.t;
            }
        }
        println!(
            "fric={fric} kg={kg} dt={dt}: worst {:.3e} rel at t={at}",
            worst / scale
        );
    }
}
