//! A friction law written outside the model's list plugs into the kernel through
//! [`FrictionLaw`] alone: a viscous law with a dead band, run by
//! [`Kernel::step_with_law`] on a rigid and a meshed drive; and the drive's own laws
//! run through the same entry give bit for bit what [`Kernel::step`] gives.

use super::lanes::LaneLaw;
use super::{Coulomb, DriveFriction, FrictionLaw};
use crate::model::drive::idx::*;
use crate::model::{presets, Drive, Kernel, LaneDrive, Params, NSTATE};

/// Viscous friction that starts only beyond a speed `band`: c·(|ω| − band) above it,
/// nothing below; nothing to break away from.
#[derive(Clone, Copy)]
struct DeadBandViscous {
    c: f64,
    band: f64,
}

impl FrictionLaw for DeadBandViscous {
    const CONSTANT_LEVEL: bool = false;

    fn breakaway(&self, _body: usize) -> f64 {
        0.0
    }

    fn sliding(&self, _body: usize, speed: f64) -> f64 {
        self.c * (speed - self.band).max(0.0)
    }
}

/// The direct drive without its own friction and damping.
fn frictionless_table() -> Params {
    let mut p = presets::load("direct-drive").unwrap();
    (p.ct, p.ft) = (0.0, 0.0);
    p
}

/// The table's speed after `seconds` of a constant motor torque under `law`.
fn speed_after<F: FrictionLaw>(p: &Params, law: &F, torque: f64, seconds: f64) -> f64 {
    let d = Drive::new(p).unwrap();
    let (lane, law) = (LaneDrive::splat(&d), LaneLaw::splat(*law));
    let mut kernel = Kernel::<1>::default();
    let mut y = [[0.0; 1]; NSTATE];
    let h = 1e-4;
    for _ in 0..(seconds / h).round() as usize {
        kernel.step_with_law(&lane, &law, &mut y, &[[torque]; 3], &[d.tload()], h);
    }
    y[OMEGA_T][0]
}

#[test]
fn a_dead_band_law_settles_where_its_level_balances_the_torque() {
    let p = frictionless_table();
    let law = DeadBandViscous { c: 2.0, band: 0.5 };
    // Jt/c = 0.25 s: after 5 s the transient is e⁻²⁰ of the start.
    let w = speed_after(&p, &law, 3.0, 5.0);
    let expected = 0.5 + 3.0 / 2.0;
    assert!(
        (w - expected).abs() < 1e-6 * expected,
        "{w} against {expected}"
    );
    let w = speed_after(&p, &law, -3.0, 5.0);
    assert!((w + expected).abs() < 1e-6 * expected, "{w}");
}

#[test]
fn inside_its_band_the_law_leaves_the_body_free() {
    let p = frictionless_table();
    let law = DeadBandViscous { c: 2.0, band: 10.0 };
    // 0.1 N·m on 0.5 kg·m² for 1 s: 0.2 rad/s, below the band, no friction.
    let w = speed_after(&p, &law, 0.1, 1.0);
    assert!((w - 0.2).abs() < 1e-9, "{w}");
}

/// A trajectory of the worm-gear drive (meshes with backlash, contact events, stick)
/// under a sine of the motor torque, through `step` or `step_with_law`.
fn worm_run(p: &Params, own: bool) -> Vec<[f64; NSTATE]> {
    let d = Drive::new(p).unwrap();
    let lane = LaneDrive::splat(&d);
    let mut kernel = Kernel::<1>::default();
    let mut y = [[0.0; 1]; NSTATE];
    let h = 1e-5;
    (0..20_000)
        .map(|i| {
            let t = i as f64 * h;
            let m = [0.0, 0.5, 1.0]
                .map(|s| [5.0 * (2.0 * 3.0 * std::f64::consts::PI * 37.0 * (t + s * h)).sin()]);
            if own {
                kernel.step(&lane, &mut y, &m, &[d.tload()], h);
            } else {
                let load = &[d.tload()];
                match *d.friction_law() {
                    DriveFriction::Coulomb(law) => {
                        kernel.step_with_law(&lane, &LaneLaw::splat(law), &mut y, &m, load, h)
                    }
                    DriveFriction::Stribeck(law) => {
                        kernel.step_with_law(&lane, &LaneLaw::splat(law), &mut y, &m, load, h)
                    }
                }
            }
            y.map(|s| s[0])
        })
        .collect()
}

#[test]
fn the_drives_own_laws_through_the_generic_entry_are_bit_identical() {
    let coulomb = presets::load("worm-gear").unwrap();
    let mut stribeck = coulomb.clone();
    (stribeck.fsm, stribeck.vsm, stribeck.fst, stribeck.vst) = (0.1, 0.5, 5.0, 0.01);
    for p in [coulomb, stribeck] {
        assert_eq!(worm_run(&p, true), worm_run(&p, false));
    }
    let d = Drive::new(&presets::load("worm-gear").unwrap()).unwrap();
    assert!(
        matches!(d.friction_law(), DriveFriction::Coulomb(c) if *c == Coulomb::new(d.friction()))
    );
}
