use rtid::input::Sine;
use rtid::model::presets;
use rtid::recorder::NullRecorder;
use rtid::sim::Simulation;
fn main() {
    let mut args = std::env::args().skip(1);
    let name = args.next().unwrap_or("worm-gear".into());
    let mut p = presets::load(&name).unwrap();
    for a in args {
        let (k, v) = a.split_once('=').unwrap();
        p.set(k, v.parse().unwrap()).unwrap();
    }
    let mut sim = Simulation::new(&p, 1e-5).unwrap();
    let t = std::time::Instant::now();
    sim.run_open_loop(&mut Sine::new(230.0, 5.0, 0.0), 2.0, &mut NullRecorder)
        .unwrap();
    let el = t.elapsed().as_secs_f64();
    println!(
        "{:.2} M steps/s events {}",
        2e5 / el / 1e6,
        sim.contact_events()
    );
}
