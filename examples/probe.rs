use rtid::input::NoTorque;
use rtid::model::{idx::*, presets, Drive, Params, NSTATE};
use rtid::recorder::Recorder;
use rtid::sim::Simulation;
fn drift(p: &Params, y0: [f64; NSTATE], dt: f64) -> f64 {
    let mut sim = Simulation::new(p, dt).unwrap();
    sim.set_state(y0);
    let d = Drive::new(p).unwrap();
    let e0 = d.energy(&sim.state());
    struct W<'a>(&'a Drive, f64, f64, usize, [bool; 2]);
    impl Recorder for W<'_> {
        fn record(&mut self, _t: f64, y: &[f64; NSTATE], _u: f64) {
            self.2 = self.2.max((self.0.energy(y) - self.1).abs());
            let c = self.0.mesh_deflections(y).map(|v| v != 0.0);
            if c != self.4 {
                self.3 += 1;
                self.4 = c;
            }
        }
    }
    let mut w = W(&d, e0, 0.0, 0, [true, true]);
    sim.run_open_loop(&mut NoTorque, 1.0, &mut w).unwrap();
    println!("   contact changes {}", w.3);
    w.2 / e0
}
fn main() {
    for (bg, bw, wf) in [
        (0.0, 0.0, 1.5e-5),
        (3e-4, 0.0, 0.0),
        (0.0, 8e-5, 0.0),
        (3e-4, 8e-5, 1.5e-5),
    ] {
        let mut p = presets::load("worm-gear").unwrap();
        for n in ["Cm", "Cw", "Cb", "Ct", "Ciw", "Cig", "fm", "fw", "ft"] {
            p.set(n, 0.0).unwrap();
        }
        p.theta_bg = Some(bg);
        p.theta_bw = bw;
        p.w = wf;
        let mut y = [0.0; NSTATE];
        let kbr2 = p.kb * p.r * p.r;
        let twist = 2e-4;
        let torque = twist / (1.0 / p.kw + 1.0 / kbr2);
        y[X_W] = -torque / p.r / p.kb;
        y[THETA_T] = -twist - bw;
        for dt in [1e-5, 5e-6, 2.5e-6] {
            println!(
                "bg={bg} bw={bw} W={wf} dt={dt}: drift {:.3e}",
                drift(&p, y, dt)
            );
        }
    }
}
