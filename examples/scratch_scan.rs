use rtid::identify::setup;
use rtid::objectives::{sum_of_squares, Fidelity, Stage};
use rtid::{preset, read_experiment, ExperimentSpec};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let file = &args[1];
    let name = &args[2];
    let exp = read_experiment(file.as_ref()).unwrap();
    let spec = ExperimentSpec::new(file.clone(), exp);
    let joint = setup::build(std::slice::from_ref(&spec), Stage::Search, Fidelity::Linear).unwrap();
    let mut p = preset("worm-gear").unwrap();
    for kv in &args[4..] {
        let (k, v) = kv.split_once('=').unwrap();
        p.set(k, v.parse().unwrap()).unwrap();
    }
    let base: f64 = args[3].parse().unwrap();
    for f in [0.25, 0.5, 0.75, 0.9, 1.0, 1.1, 1.25, 1.5, 2.0] {
        let mut q = p.clone();
        q.set(name, base * f).unwrap();
        let c = sum_of_squares(&rtid::objectives::Objective::residuals(&joint, &q).unwrap());
        println!("{name} = {:.4e} ({f}): cost {c:.5}", base * f);
    }
}
