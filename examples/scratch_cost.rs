use rtid::identify::setup;
use rtid::objectives::{Fidelity, Objective, Stage};
use rtid::{preset, read_experiment, ExperimentSpec};
fn cpu() -> f64 {
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut ru) };
    ru.ru_utime.tv_sec as f64 + ru.ru_utime.tv_usec as f64 * 1e-6
}
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let p = preset("worm-gear").unwrap();
    for file in &args[1..] {
        let exp = read_experiment(file.as_ref()).unwrap();
        let spec = ExperimentSpec::new(file.clone(), exp);
        let joint = setup::build(std::slice::from_ref(&spec), Stage::Search, Fidelity::Linear).unwrap();
        let pts: Vec<_> = (0..4).map(|k| { let mut q = p.clone(); q.fm *= 1.0 + 0.01 * k as f64; q }).collect();
        let c0 = cpu();
        for q in &pts { joint.residuals(q).unwrap(); }
        let c1 = cpu();
        joint.residuals_batch(&pts);
        let c2 = cpu();
        println!("{file}: alone {:.3} s CPU per point, in lanes {:.3} s per point", (c1 - c0) / 4.0, (c2 - c1) / 4.0);
    }
}
