//! Gear meshes with free play (docs/model.md §2): a dead zone of half-width `b` that
//! transmits stiffness plus internal damping only while the teeth touch, and never
//! pulls while they separate.
//!
//! The laws are written as selects between values computed unconditionally (no
//! branch depends on the state), so the kernel's lane-wise forms ([`mesh_torque_lanes`])
//! vectorise; each lane, with its own stiffness, damping and gap, gets exactly the
//! scalar result.

use super::lanes::Lanes;

/// The dead-zone deflection: δ − b above the gap, δ + b below it, 0 inside.
#[inline(always)]
pub(crate) fn dead_zone(delta: f64, b: f64) -> f64 {
    // One level of select at a time: compiles to blends, not branches.
    let below = if delta < -b { delta + b } else { 0.0 };
    if delta > b {
        delta - b
    } else {
        below
    }
}

/// Torque transmitted by a mesh of stiffness `k`, internal damping `c` and backlash
/// half-width `b`, at twist `delta` and twist rate `rate`.
///
/// With `b > 0` one flank touches at a time: the torque is k·dz + c·rate while in
/// contact, clamped to the sign of the contact (a separating flank pushes nothing,
/// it does not pull), and 0 inside the gap. With `b = 0` (a preloaded mesh, both
/// flanks engaged) it is the linear spring-damper k·δ + c·rate in both directions.
#[inline(always)]
pub(crate) fn mesh_torque(k: f64, c: f64, b: f64, delta: f64, rate: f64) -> f64 {
    if b == 0.0 {
        return k * delta + c * rate;
    }
    let dz = dead_zone(delta, b);
    contact_torque(dz, k * dz + c * rate)
}

/// The torque `t` = k·dz + c·rate clamped to the sign of the contact `dz` (0 in the gap).
#[inline(always)]
fn contact_torque(dz: f64, t: f64) -> f64 {
    let pull = if dz < 0.0 { t.min(0.0) } else { 0.0 };
    if dz > 0.0 {
        t.max(0.0)
    } else {
        pull
    }
}

/// [`mesh_torque`] for each lane, each with its own `k`, `c` and `b`; `gapped`
/// says whether the gaps are positive (in every lane) or zero (in every lane: a
/// preloaded mesh, linear).
#[inline(always)]
pub(crate) fn mesh_torque_lanes<const L: usize>(
    (k, c, b): (Lanes<L>, Lanes<L>, Lanes<L>),
    gapped: bool,
    delta: Lanes<L>,
    rate: Lanes<L>,
) -> Lanes<L> {
    if !gapped {
        return k * delta + c * rate;
    }
    let dz = delta.zip(b, dead_zone);
    dz.zip(k * dz + c * rate, contact_torque)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_torque_inside_the_gap_whatever_the_rate() {
        for &d in &[-0.99e-4, -3e-5, 0.0, 2e-5, 0.99e-4] {
            for &v in &[-10.0, 0.0, 10.0] {
                assert_eq!(mesh_torque(3e5, 0.1, 1e-4, d, v), 0.0, "d={d} v={v}");
            }
        }
    }

    #[test]
    fn contact_transmits_spring_plus_damper() {
        let t = mesh_torque(3e5, 0.1, 1e-4, 3e-4, 2.0);
        assert!((t - (3e5 * 2e-4 + 0.2)).abs() < 1e-12);
        let t = mesh_torque(3e5, 0.1, 1e-4, -3e-4, -2.0);
        assert!((t + (3e5 * 2e-4 + 0.2)).abs() < 1e-12);
    }

    #[test]
    fn a_separating_flank_never_pulls() {
        // In contact on the positive flank but separating fast: damping would pull.
        assert_eq!(mesh_torque(3e5, 100.0, 1e-4, 1.01e-4, -50.0), 0.0);
        assert_eq!(mesh_torque(3e5, 100.0, 1e-4, -1.01e-4, 50.0), 0.0);
    }

    #[test]
    fn the_lane_form_equals_the_scalar_law() {
        let delta = Lanes([-3e-4, -1.01e-4, -1e-4, 0.0, 5e-5, 1e-4, 1.01e-4, 3e-4]);
        for rate in [-50.0, -2.0, 0.0, 2.0, 50.0] {
            for b in [0.0, 1e-4] {
                let mesh = (Lanes::splat(3e5), Lanes::splat(100.0), Lanes::splat(b));
                let t = mesh_torque_lanes(mesh, b > 0.0, delta, Lanes::splat(rate));
                for l in 0..8 {
                    assert_eq!(t.0[l], mesh_torque(3e5, 100.0, b, delta.0[l], rate));
                }
            }
        }
    }

    #[test]
    fn a_preloaded_mesh_is_linear_both_ways() {
        assert_eq!(mesh_torque(1e6, 2.0, 0.0, 1e-6, -5.0), 1e6 * 1e-6 - 10.0);
    }
}
