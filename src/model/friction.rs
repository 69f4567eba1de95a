//! Coulomb friction with true stick (MODEL.md §2), treated as a clamp: a body at
//! rest stays at rest while the torque needed to hold it, which is the sum of every
//! other torque on it (the model's mass matrix is diagonal), lies within ±fc; it
//! slides with fc opposing its motion otherwise.
//!
//! The kernel decides stick once per integration step, at the step's first stage,
//! and holds that decision through the step's remaining stages. A sliding body whose
//! velocity changes sign within a step is put to rest at the end of the step (its
//! velocity set to exactly zero), so the next step decides between stick and
//! reversal. A stuck body's velocity is exactly zero and stays so: it cannot creep.

/// Net torque on a body with Coulomb friction `fc`, given the sum `t` of all other
/// torques on it and its velocity `w`. When `decide` is set, `stuck` is updated to
/// whether the body sticks now; otherwise the earlier decision is kept.
#[inline(always)]
pub fn net_torque(t: f64, w: f64, fc: f64, stuck: &mut bool, decide: bool) -> f64 {
    if decide {
        *stuck = w == 0.0 && t.abs() <= fc;
    }
    if *stuck {
        0.0
    } else if w != 0.0 {
        t - fc.copysign(w)
    } else {
        // Breaking away from rest: friction opposes the applied torque.
        if t > fc {
            t - fc
        } else if t < -fc {
            t + fc
        } else {
            0.0
        }
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
        let mut stuck = false;
        assert_eq!(net_torque(0.13, 0.0, 0.26, &mut stuck, true), 0.0);
        assert!(stuck);
    }

    #[test]
    fn breaks_away_above_it_with_exactly_fc_opposing() {
        let mut stuck = false;
        assert_eq!(net_torque(0.5, 0.0, 0.26, &mut stuck, true), 0.5 - 0.26);
        assert_eq!(net_torque(-0.5, 0.0, 0.26, &mut stuck, true), -0.5 + 0.26);
        assert!(!stuck);
    }

    #[test]
    fn slides_against_the_velocity() {
        let mut stuck = false;
        assert_eq!(net_torque(0.0, 1.0, 0.26, &mut stuck, true), -0.26);
        assert_eq!(net_torque(0.0, -1e-9, 0.26, &mut stuck, true), 0.26);
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
