//! Coulomb friction with true stick (MODEL.md §2), treated as a clamp: a body at
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
    pub fn decide(t: f64, w: f64, fc: f64) -> Self {
        let torque = if w > 0.0 {
            fc
        } else if w < 0.0 {
            -fc
        } else if t > fc {
            fc
        } else if t < -fc {
            -fc
        } else {
            return Friction {
                torque: 0.0,
                free: 0.0,
            };
        };
        Friction { torque, free: 1.0 }
    }

    /// The net torque on the body (0 while stuck).
    #[inline(always)]
    pub fn net(self, t: f64) -> f64 {
        (t - self.torque) * self.free
    }

    /// Whether the body sticks.
    pub fn stuck(self) -> bool {
        self.free == 0.0
    }
}

/// After a step: a sliding body (with friction) whose velocity changed sign is put
/// to rest, so that the next step decides between sticking and reversing.
#[inline(always)]
pub fn stop_at_reversal(w_before: f64, w_after: &mut f64, fc: f64) {
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
    fn reversal_only_stops_bodies_with_friction() {
        let mut w = -1e-6;
        stop_at_reversal(1e-6, &mut w, 0.26);
        assert_eq!(w, 0.0);
        let mut w = -1e-6;
        stop_at_reversal(1e-6, &mut w, 0.0);
        assert_eq!(w, -1e-6);
    }
}
