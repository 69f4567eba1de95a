use rtid::model::{modes::LinearModel, presets};
fn main() {
    for name in ["worm-gear", "roller-gear-cam"] {
        let p = presets::load(name).unwrap();
        let lm = LinearModel::new(&p).unwrap();
        let a = lm.state_matrix();
        let mut ev: Vec<_> = a
            .complex_eigenvalues()
            .iter()
            .cloned()
            .filter(|z| z.im > 1.0)
            .collect();
        ev.sort_by(|x, y| x.im.partial_cmp(&y.im).unwrap());
        for z in ev {
            println!(
                "{name}: f = {:.1} Hz, zeta = {:.3e}",
                z.norm() / std::f64::consts::TAU,
                -z.re / z.norm()
            );
        }
    }
}
