//! The stick/slip clamp every friction law shares (docs/model.md §2): a body at rest
//! stays at rest while the torque needed to hold it, which is the sum of every other
//! torque on it (the model's mass matrix is diagonal), lies within ± its break-away
//! level; it slides against its law's level otherwise.
//!
//! The kernel decides once per integration step, at the step's first stage, and
//! holds the decision — stuck, or sliding against a friction torque of fixed sign —
//! through the step's remaining stages. A sliding body whose velocity changes sign
//! within a step is put to rest at the end of the step (its velocity set to exactly
//! zero), so the next step decides between sticking and reversing. A stuck body's
//! velocity is exactly zero and stays so: it cannot creep.
//!
//! The decision is a select among constants (no branch on the state), so the
//! kernel's lane-wise form [`decide_lanes`] vectorises with the scalar result in
//! every lane.

use crate::model::lanes::Lanes;

/// The friction torque on a body at velocity `w` under the sum `t` of all its other
/// torques, with Coulomb level `fc`: fc against the motion, or against `t` when
/// breaking away from rest; 0 when it sticks (|t| within ±fc at rest).
#[inline(always)]
fn decided_torque(t: f64, w: f64, fc: f64) -> f64 {
    // Written as selects (non-short-circuit `|`, one level of `if`) so that the
    // lane-wise form compiles to compare-and-blend instructions, not branches.
    let moving = (w > 0.0) | (w < 0.0);
    let direction = if moving { w } else { t };
    let slides = moving | (t > fc) | (t < -fc);
    if slides {
        fc.copysign(direction)
    } else {
        0.0
    }
}

/// The direction the friction of [`decided_torque`] acts in, with the static level
/// `fs`: ±1 against the motion (against `t` when breaking away), 0 when stuck.
#[inline(always)]
fn decided_direction(t: f64, w: f64, fs: f64) -> f64 {
    let moving = (w > 0.0) | (w < 0.0);
    let direction = if moving { w } else { t };
    let slides = moving | (t > fs) | (t < -fs);
    if slides {
        1.0f64.copysign(direction)
    } else {
        0.0
    }
}

/// 1 if the body of [`decided_torque`] moves, 0 if it sticks.
#[inline(always)]
fn decided_free(t: f64, w: f64, fc: f64) -> f64 {
    if (w > 0.0) | (w < 0.0) | (t > fc) | (t < -fc) {
        1.0
    } else {
        0.0
    }
}

/// The stick decision of a body with a constant friction level, for each lane with
/// its own level `fc`: (friction torques [`decided_torque`], free flags 1 or 0).
/// The net torque on a body is then (t − torque)·free.
#[inline(always)]
pub(crate) fn decide_lanes<const L: usize>(
    t: Lanes<L>,
    w: Lanes<L>,
    fc: Lanes<L>,
) -> (Lanes<L>, Lanes<L>) {
    (
        lane_wise(t, w, fc, decided_torque),
        lane_wise(t, w, fc, decided_free),
    )
}

/// The stick decision of a Stribeck body with static level `fs`, for each lane:
/// (directions ±1 or 0, free flags).
#[inline(always)]
pub(crate) fn decide_direction_lanes<const L: usize>(
    t: Lanes<L>,
    w: Lanes<L>,
    fs: Lanes<L>,
) -> (Lanes<L>, Lanes<L>) {
    (
        lane_wise(t, w, fs, decided_direction),
        lane_wise(t, w, fs, decided_free),
    )
}

/// After a step: a sliding body (with friction, level `fc` > 0) whose velocity
/// changed sign is put to rest, so that the next step decides between sticking and
/// reversing; for each lane, with its own level.
#[inline(always)]
pub(crate) fn stop_at_reversal_lanes<const L: usize>(
    w_before: Lanes<L>,
    w_after: Lanes<L>,
    fc: Lanes<L>,
) -> Lanes<L> {
    lane_wise(w_before, w_after, fc, |b, a, fc| {
        if (fc > 0.0) & (b * a < 0.0) {
            0.0
        } else {
            a
        }
    })
}

/// `f` applied lane by lane to three lanes' values (an indexed loop: it vectorises).
#[inline(always)]
#[allow(clippy::needless_range_loop)]
fn lane_wise<const L: usize>(
    a: Lanes<L>,
    b: Lanes<L>,
    c: Lanes<L>,
    f: impl Fn(f64, f64, f64) -> f64,
) -> Lanes<L> {
    let mut out = a.0;
    for l in 0..L {
        out[l] = f(out[l], b.0[l], c.0[l]);
    }
    Lanes(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decision of one body: (net torque under `t`, stuck).
    fn decide(t: f64, w: f64, fc: f64) -> (f64, bool) {
        let (torque, free) = decide_lanes(Lanes([t]), Lanes([w]), Lanes([fc]));
        ((t - torque.0[0]) * free.0[0], free.0[0] == 0.0)
    }

    #[test]
    fn holds_within_the_friction_band() {
        assert_eq!(decide(0.13, 0.0, 0.26), (0.0, true));
    }

    #[test]
    fn breaks_away_above_it_with_exactly_fc_opposing() {
        assert_eq!(decide(0.5, 0.0, 0.26), (0.5 - 0.26, false));
        assert_eq!(decide(-0.5, 0.0, 0.26), (-0.5 + 0.26, false));
    }

    #[test]
    fn slides_against_the_velocity() {
        assert_eq!(decide(0.0, 1.0, 0.26).0, -0.26);
        assert_eq!(decide(0.0, -1e-9, 0.26).0, 0.26);
    }

    #[test]
    fn without_friction_only_a_balanced_body_at_rest_sticks() {
        assert!(decide(0.0, 0.0, 0.0).1);
        assert_eq!(decide(1e-9, 0.0, 0.0), (1e-9, false));
    }

    #[test]
    fn a_stribeck_body_breaks_away_at_the_static_level() {
        let held = decide_direction_lanes(Lanes([2.9]), Lanes([0.0]), Lanes([3.0]));
        assert_eq!((held.0 .0, held.1 .0), ([0.0], [0.0]));
        let breaks = decide_direction_lanes(Lanes([-3.1]), Lanes([0.0]), Lanes([3.0]));
        assert_eq!((breaks.0 .0, breaks.1 .0), ([-1.0], [1.0]));
        let slides = decide_direction_lanes(Lanes([5.0]), Lanes([-1e-9]), Lanes([3.0]));
        assert_eq!((slides.0 .0, slides.1 .0), ([-1.0], [1.0]));
    }

    #[test]
    fn reversal_only_stops_bodies_with_friction() {
        let stop =
            |fc: f64| stop_at_reversal_lanes(Lanes([1e-6]), Lanes([-1e-6]), Lanes([fc])).0[0];
        assert_eq!(stop(0.26), 0.0);
        assert_eq!(stop(0.0), -1e-6);
    }
}
