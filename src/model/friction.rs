//! Coulomb friction with true stick (docs/model.md §2), treated as a clamp: a body at
//! rest stays at rest while the torque needed to hold it, which is the sum of every
//! other torque on it (the model's mass matrix is diagonal), lies within ±fc; it
//! slides with fc opposing its motion otherwise.
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
//!
//! **The Stribeck law** ([`Stribeck`]): a sliding body meets
//! f(ω) = fc + rise·exp(−(|ω|/vs)^δ) — its Coulomb level plus a rise that falls off
//! with speed — and a body at rest breaks away only when the torque on it exceeds the
//! static level fc + rise. The clamp is the same, compared with the static level; the
//! kernel decides stick and direction at a step's first stage as above and evaluates
//! f at every stage's velocity (the level changes within a step, its sign does not).
//! With every rise 0 (the default) the drive has no [`Stribeck`] and the kernel runs
//! the Coulomb path alone, unchanged.

use super::lanes::Lanes;
use super::params::{Params, Topology};

/// The Stribeck law of motor, shaft and table (docs/model.md §2): per body the Coulomb
/// level, the rise above it at rest and 1/vs; one shape exponent δ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stribeck {
    coulomb: [f64; 3],
    rise: [f64; 3],
    inv_speed: [f64; 3],
    shape: f64,
    /// The static level fc + rise: what the clamp compares with.
    pub(crate) fs: [f64; 3],
}

impl Stribeck {
    /// The law of `p` with the bodies' Coulomb levels `fc` (as the kernel lumps them:
    /// the direct topology's motor carries the shaft's); `None` when every rise is 0.
    /// The shaft's rise applies to the spur-gear topology only.
    pub(crate) fn of(p: &Params, fc: [f64; 3]) -> Option<Self> {
        let spur = p.topology == Topology::SpurGear;
        let rise = [p.fsm, if spur { p.fsw } else { 0.0 }, p.fst];
        if rise.iter().all(|r| *r == 0.0) {
            return None;
        }
        let speed = [p.vsm, if spur { p.vsw } else { 0.0 }, p.vst];
        let inv_speed = [0, 1, 2].map(|b| if rise[b] > 0.0 { 1.0 / speed[b] } else { 0.0 });
        Some(Stribeck {
            coulomb: fc,
            rise,
            inv_speed,
            shape: p.stribeck_shape,
            fs: [0, 1, 2].map(|b| fc[b] + rise[b]),
        })
    }

    /// The friction of body `b` sliding at `speed` ≥ 0: fc + rise·exp(−(speed/vs)^δ).
    #[inline(always)]
    pub(crate) fn level(&self, b: usize, speed: f64) -> f64 {
        self.coulomb[b] + self.rise[b] * decay(speed * self.inv_speed[b], self.shape)
    }
}

/// exp(−x^δ), with δ = 2 and δ = 1 spared the power.
#[inline(always)]
fn decay(x: f64, shape: f64) -> f64 {
    let power = if shape == 2.0 {
        x * x
    } else if shape == 1.0 {
        x
    } else {
        x.powf(shape)
    };
    (-power).exp()
}

/// The friction state of one body over one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Friction {
    /// Friction torque opposing the motion, N·m (signed; 0 when stuck).
    pub torque: f64,
    /// 1 while the body moves, 0 while it sticks (multiplies its acceleration).
    pub free: f64,
}

impl Friction {
    /// Decides, from the sum `t` of all other torques on a body, its velocity `w`
    /// and its Coulomb friction `fc`, whether it sticks, and against which friction
    /// torque it slides otherwise (breaking away from rest: opposing `t`).
    #[inline(always)]
    pub(crate) fn decide(t: f64, w: f64, fc: f64) -> Self {
        Friction {
            torque: decided_torque(t, w, fc),
            free: decided_free(t, w, fc),
        }
    }

    /// The net torque on the body (0 while stuck).
    #[inline(always)]
    pub(crate) fn net(self, t: f64) -> f64 {
        (t - self.torque) * self.free
    }

    /// Whether the body sticks.
    pub fn stuck(self) -> bool {
        self.free == 0.0
    }
}

/// The friction torque of [`Friction::decide`]: fc against the motion, or against
/// `t` when breaking away from rest; 0 when stuck.
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

/// The direction the friction of [`Friction::decide`] acts in, with the static level
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

/// 1 if the body of [`Friction::decide`] moves, 0 if it sticks.
#[inline(always)]
fn decided_free(t: f64, w: f64, fc: f64) -> f64 {
    if (w > 0.0) | (w < 0.0) | (t > fc) | (t < -fc) {
        1.0
    } else {
        0.0
    }
}

/// [`Friction::decide`] for each lane: (friction torques, free flags).
#[inline(always)]
pub(crate) fn decide_lanes<const L: usize>(
    t: Lanes<L>,
    w: Lanes<L>,
    fc: f64,
) -> (Lanes<L>, Lanes<L>) {
    (
        t.zip(w, |t, w| decided_torque(t, w, fc)),
        t.zip(w, |t, w| decided_free(t, w, fc)),
    )
}

/// The stick decision of a Stribeck body with static level `fs`, for each lane:
/// (directions ±1 or 0, free flags).
#[inline(always)]
pub(crate) fn decide_direction_lanes<const L: usize>(
    t: Lanes<L>,
    w: Lanes<L>,
    fs: f64,
) -> (Lanes<L>, Lanes<L>) {
    (
        t.zip(w, |t, w| decided_direction(t, w, fs)),
        t.zip(w, |t, w| decided_free(t, w, fs)),
    )
}

/// [`stop_at_reversal`] for each lane.
#[inline(always)]
pub(crate) fn stop_at_reversal_lanes<const L: usize>(
    w_before: Lanes<L>,
    w_after: Lanes<L>,
    fc: f64,
) -> Lanes<L> {
    if fc > 0.0 {
        w_before.zip(w_after, |b, a| if b * a < 0.0 { 0.0 } else { a })
    } else {
        w_after
    }
}

/// After a step: a sliding body (with friction) whose velocity changed sign is put
/// to rest, so that the next step decides between sticking and reversing.
#[inline(always)]
pub(crate) fn stop_at_reversal(w_before: f64, w_after: &mut f64, fc: f64) {
    if fc > 0.0 && w_before * *w_after < 0.0 {
        *w_after = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_within_the_friction_band() {
        let f = Friction::decide(0.13, 0.0, 0.26);
        assert!(f.stuck());
        assert_eq!(f.net(0.13), 0.0);
    }

    #[test]
    fn breaks_away_above_it_with_exactly_fc_opposing() {
        assert_eq!(Friction::decide(0.5, 0.0, 0.26).net(0.5), 0.5 - 0.26);
        assert_eq!(Friction::decide(-0.5, 0.0, 0.26).net(-0.5), -0.5 + 0.26);
    }

    #[test]
    fn slides_against_the_velocity() {
        assert_eq!(Friction::decide(0.0, 1.0, 0.26).net(0.0), -0.26);
        assert_eq!(Friction::decide(0.0, -1e-9, 0.26).net(0.0), 0.26);
    }

    #[test]
    fn without_friction_only_a_balanced_body_at_rest_sticks() {
        assert!(Friction::decide(0.0, 0.0, 0.0).stuck());
        assert_eq!(Friction::decide(1e-9, 0.0, 0.0).net(1e-9), 1e-9);
    }

    #[test]
    fn the_stribeck_level_falls_from_static_to_coulomb() {
        let mut p = crate::model::presets::load("direct-drive").unwrap();
        (p.ft, p.fst, p.vst) = (2.0, 1.0, 0.1);
        let law = Stribeck::of(&p, [0.0, 0.0, 2.0]).unwrap();
        assert_eq!(law.level(2, 0.0), 3.0);
        assert!((law.level(2, 0.1) - (2.0 + (-1.0f64).exp())).abs() < 1e-15);
        assert_eq!(law.level(2, 10.0), 2.0);
        p.stribeck_shape = 1.0;
        let law = Stribeck::of(&p, [0.0, 0.0, 2.0]).unwrap();
        assert!((law.level(2, 0.2) - (2.0 + (-2.0f64).exp())).abs() < 1e-15);
        p.stribeck_shape = 0.5;
        let law = Stribeck::of(&p, [0.0, 0.0, 2.0]).unwrap();
        assert!((law.level(2, 0.4) - (2.0 + (-2.0f64).exp())).abs() < 1e-15);
        p.fst = 0.0;
        assert!(Stribeck::of(&p, [0.0, 0.0, 2.0]).is_none());
    }

    #[test]
    fn a_stribeck_body_breaks_away_at_the_static_level() {
        let held = decide_direction_lanes(Lanes([2.9]), Lanes([0.0]), 3.0);
        assert_eq!((held.0 .0, held.1 .0), ([0.0], [0.0]));
        let breaks = decide_direction_lanes(Lanes([-3.1]), Lanes([0.0]), 3.0);
        assert_eq!((breaks.0 .0, breaks.1 .0), ([-1.0], [1.0]));
        let slides = decide_direction_lanes(Lanes([5.0]), Lanes([-1e-9]), 3.0);
        assert_eq!((slides.0 .0, slides.1 .0), ([-1.0], [1.0]));
    }

    #[test]
    fn reversal_only_stops_bodies_with_friction() {
        let mut w = -1e-6;
        stop_at_reversal(1e-6, &mut w, 0.26);
        assert_eq!(w, 0.0);
        let mut w = -1e-6;
        stop_at_reversal(1e-6, &mut w, 0.0);
        assert_eq!(w, -1e-6);
    }
}
