//! States to start a run from: the drive at rest with its table (carriage) at a given
//! position, the meshes centred in their backlash or twisted by a static torque the
//! drive transmits, or the whole drive moving rigidly. The one place that knows how
//! each topology fills the state slots ([`idx`](super::idx)), so that every
//! experiment runs on every topology.

use super::drive::{idx::*, NSTATE};
use super::params::{Params, Topology};

/// What the drive transmits at rest.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Preload {
    /// Nothing: every mesh centred in its backlash, no twist (the meshes are free).
    #[default]
    None,
    /// A static torque (N·m at the table; N on a linear axis) carried from the motor
    /// to the table, which an external torque of the opposite sign holds: each mesh
    /// twisted by its share of it over its stiffness, its backlash taken up on the
    /// flank of the torque's sign (the positive flank for 0), the axial bearing
    /// deflected by torque/r. A rigid direct drive has nothing to twist.
    Torque(f64),
}

/// The drive at rest with the table at `table` (rad, or m on a linear axis): motor at
/// table/(Rg·Rw), driving shaft at table/Rw, plus the static twist of `preload`.
/// Slots a topology does not integrate hold what the kernel mirrors into them.
pub fn rest_state(p: &Params, table: f64, preload: Preload) -> [f64; NSTATE] {
    let mut y = [0.0; NSTATE];
    y[THETA_M] = table / p.ratio();
    y[THETA_W] = if p.topology == Topology::SpurGear {
        table / p.rw
    } else {
        y[THETA_M]
    };
    y[THETA_T] = table;
    if let Preload::Torque(torque) = preload {
        let twist = static_twist(p, torque);
        y[THETA_M] += twist[THETA_M];
        y[THETA_W] += twist[THETA_W];
        y[X_W] += twist[X_W];
        if p.topology != Topology::SpurGear {
            y[THETA_W] = y[THETA_M];
        }
    }
    y
}

/// The drive moving rigidly at `velocity` (table rad/s, or m/s) through the position
/// `table`, meshes centred: every body at the table's velocity over its ratio.
pub fn moving_state(p: &Params, table: f64, velocity: f64) -> [f64; NSTATE] {
    let mut y = rest_state(p, table, Preload::None);
    y[OMEGA_M] = velocity / p.ratio();
    y[OMEGA_W] = if p.topology == Topology::SpurGear {
        velocity / p.rw
    } else {
        y[OMEGA_M]
    };
    y[OMEGA_T] = velocity;
    y
}

/// The deflections of the motor, shaft and axial slots that carry `torque` to a
/// table at 0 (docs/model.md §2 at rest: Tw = Kw·dz(δw), Tg = Tw·Rw, Kb·xw = −Tw/r). The
/// gear fluctuation e(θw) is left out (W·N·θw is below 1e-7 rad for the presets).
fn static_twist(p: &Params, torque: f64) -> [f64; NSTATE] {
    let mut y = [0.0; NSTATE];
    let side = if torque < 0.0 { -1.0 } else { 1.0 };
    let drive_twist = torque / p.kw + side * p.theta_bw;
    match p.topology {
        Topology::SpurGear | Topology::Direct => {
            let xw = -torque / (p.r * p.kb);
            let shaft = (drive_twist - xw / p.r) / p.rw;
            y[X_W] = xw;
            if p.topology == Topology::SpurGear {
                let tg = torque * p.rw;
                let dg = tg / p.kg.unwrap_or(f64::INFINITY) + side * p.theta_bg.unwrap_or(0.0);
                y[THETA_W] = shaft;
                y[THETA_M] = (dg + shaft) / p.rg.unwrap_or(1.0);
            } else {
                y[THETA_M] = shaft;
            }
        }
        Topology::TwoMass => y[THETA_M] = drive_twist,
        Topology::DirectDrive => {}
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{presets, Drive};

    #[test]
    fn at_rest_every_topology_has_its_table_where_asked_and_no_twist() {
        for name in ["worm-gear", "roller-gear-cam", "direct-drive", "two-mass"] {
            let p = presets::load(name).unwrap();
            let d = Drive::new(&p).unwrap();
            let y = rest_state(&p, 0.3, Preload::None);
            assert_eq!(y[THETA_T], 0.3, "{name}");
            assert!((y[THETA_M] * p.ratio() - 0.3).abs() < 1e-15, "{name}");
            assert_eq!(d.mesh_torques(&y), [0.0, 0.0], "{name}");
            let mut mirrored = y;
            d.mirror(&mut mirrored);
            assert_eq!(mirrored, y, "{name}: the slots are already consistent");
        }
    }

    #[test]
    fn a_preloaded_drive_transmits_the_torque_to_the_table() {
        for name in ["worm-gear", "roller-gear-cam", "two-mass"] {
            let mut p = presets::load(name).unwrap();
            // The static twist leaves out the gear fluctuation e(θw) (its torque
            // Kw·e is 1.4 % of 2 N·m on the worm preset).
            p.w = 0.0;
            let d = Drive::new(&p).unwrap();
            for torque in [2.0, -0.7] {
                let y = rest_state(&p, 0.0, Preload::Torque(torque));
                let [tg, tw] = d.mesh_torques(&y);
                assert!((tw - torque).abs() < 1e-9 * torque.abs(), "{name}: {tw}");
                if p.topology == Topology::SpurGear {
                    assert!((tg - torque * p.rw).abs() < 1e-9, "{name}: {tg}");
                }
            }
        }
    }

    #[test]
    fn moving_state_moves_every_body_at_its_ratio() {
        let p = presets::load("worm-gear").unwrap();
        let y = moving_state(&p, 0.1, 0.5);
        assert_eq!(y[OMEGA_T], 0.5);
        assert!((y[OMEGA_M] * p.ratio() - 0.5).abs() < 1e-15);
        assert!((y[OMEGA_W] * p.rw - 0.5).abs() < 1e-15);
    }
}
