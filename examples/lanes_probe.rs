use rtid::model::{presets, Drive, Kernel, States, NSTATE};
fn run<const L: usize>(d: &Drive, steps: usize) -> f64 {
    let mut k = Kernel::<L>::default();
    let mut y: States<L> = [[0.0; L]; NSTATE];
    let h = 1e-5;
    let freqs: [f64; L] = std::array::from_fn(|l| 100.0 + 37.0 * l as f64);
    let t0 = std::time::Instant::now();
    for n in 0..steps {
        let t = n as f64 * h;
        let m: [[f64; L]; 3] = std::array::from_fn(|s| std::array::from_fn(|l| 5.0 * (std::f64::consts::TAU * freqs[l] * (t + 0.5 * h * s as f64)).sin()));
        k.step(d, &mut y, &m, &[0.0; L], h);
    }
    let el = t0.elapsed().as_secs_f64();
    std::hint::black_box(y);
    (steps * L) as f64 / el / 1e6
}
fn main() {
    for name in ["worm-gear", "roller-gear-cam"] {
        let d = Drive::new(&presets::load(name).unwrap()).unwrap();
        println!("{name}: L=1 {:.1}  L=4 {:.1}  L=8 {:.1} M lane-steps/s (incl. sin inputs)", run::<1>(&d, 200_000), run::<4>(&d, 50_000), run::<8>(&d, 25_000));
    }
}
