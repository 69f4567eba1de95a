//! What the controller derives from the reference alone (docs/model.md §1 "Servo as
//! real drives have it"): its motion at the motor by backward differences, the
//! commanded direction and the time since it last reversed, the symmetrising lag of
//! the position loop's reference, and the torque the feed-forward and the friction
//! compensation add:
//!
//! ```text
//! ω_ref,k = (r_k − r_{k−1})/(Tc·Rg·Rw)          reference speed at the motor
//! α_ref,k = (ω_ref,k − ω_ref,k−1)/Tc            reference acceleration
//! ω*     += Kvff·ω_ref,k                         velocity feed-forward
//! u      += Kaff·α_ref,k + T_fc/drive_gain      torque feed-forward, friction
//! r_sym,k = r_sym,k−1 + (1 − e^{−Tc/T})·(r_k − r_sym,k−1)   symmetrising lag
//! T_fc    = f(ω_ref) + Fo (ω_ref ≠ 0) + A·e^{−t/τ}·dir    friction compensation
//! ```
//!
//! with f the identified law at the motor, t the time since the commanded direction
//! last reversed and dir its sign.

use super::compensation::FrictionCompensation;

/// The reference's state across samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ReferenceMotion {
    started: bool,
    previous: f64,
    /// Reference speed at the motor, rad/s (m/s), at the last sample.
    speed: f64,
    /// Motor speed the axis had before the first sample (`Controller::start_moving`).
    initial_speed: f64,
    /// Whether the last commanded motion was negative.
    downwards: bool,
    /// Whether the commanded direction has reversed since the start.
    reversed: bool,
    /// Time since the last reversal, s.
    since_reversal: f64,
    /// The symmetrising lag's output.
    lagged: f64,
}

/// The reference's motion at one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Motion {
    /// Reference speed at the motor, rad/s (m/s).
    pub speed: f64,
    /// Reference acceleration at the motor, rad/s² (m/s²).
    pub acceleration: f64,
    /// Whether the commanded direction is negative.
    pub downwards: bool,
}

impl ReferenceMotion {
    /// Starts in motion at `motor_speed` (before the first sample).
    pub fn start_moving(&mut self, motor_speed: f64) {
        self.initial_speed = motor_speed;
        self.downwards = motor_speed < 0.0;
    }

    /// The motion at reference `r` (table rad or m), with `tc` and `ratio` (Rg·Rw).
    pub fn sample(&mut self, r: f64, tc: f64, ratio: f64) -> Motion {
        if !self.started {
            self.started = true;
            self.previous = r - tc * ratio * self.initial_speed;
            self.speed = self.initial_speed;
            self.lagged = r;
        }
        let speed = (r - self.previous) / (tc * ratio);
        let acceleration = (speed - self.speed) / tc;
        (self.previous, self.speed) = (r, speed);
        self.since_reversal += tc;
        if speed != 0.0 && (speed < 0.0) != self.downwards {
            self.downwards = speed < 0.0;
            self.reversed = true;
            self.since_reversal = 0.0;
        }
        Motion {
            speed,
            acceleration,
            downwards: self.downwards,
        }
    }

    /// The position loop's reference `r` through the symmetrising lag with the factor
    /// 1 − e^{−Tc/T}.
    pub fn symmetrise(&mut self, r: f64, factor: f64) -> f64 {
        self.lagged += factor * (r - self.lagged);
        self.lagged
    }

    /// The friction compensation's torque (force) at the motor for `motion`.
    pub fn friction(&self, f: &FrictionCompensation, motion: &Motion) -> f64 {
        let law = if motion.speed != 0.0 {
            f.law.effort(motion.speed) + f.offset
        } else {
            0.0
        };
        let pulse = match f.pulse {
            Some(p) if self.reversed => {
                let sign = if motion.downwards { -1.0 } else { 1.0 };
                sign * p.amplitude * (-self.since_reversal / p.decay_s).exp()
            }
            _ => 0.0,
        };
        law + pulse
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::ReversalPulse;
    use crate::model::friction::SteadyFriction;

    #[test]
    fn the_references_motion_by_backward_differences() {
        let mut m = ReferenceMotion::default();
        let (tc, ratio) = (1e-3, 0.5);
        let first = m.sample(1.0, tc, ratio);
        assert_eq!((first.speed, first.acceleration), (0.0, 0.0));
        let second = m.sample(1.0 + 1e-3, tc, ratio);
        assert!((second.speed - 2.0).abs() < 1e-9 && (second.acceleration - 2000.0).abs() < 1e-6);
        assert!(!second.downwards);
        let back = m.sample(1.0, tc, ratio);
        assert!(back.downwards && back.speed < 0.0);
        // A moving start sees its speed in the first sample, no acceleration.
        let mut m = ReferenceMotion::default();
        m.start_moving(-3.0);
        let first = m.sample(0.2, tc, ratio);
        assert!((first.speed + 3.0).abs() < 1e-9 && first.acceleration.abs() < 1e-6);
        assert!(first.downwards);
    }

    #[test]
    fn friction_compensation_follows_the_commanded_speed_and_pulses_at_reversals() {
        let f = FrictionCompensation {
            law: SteadyFriction {
                coulomb: 0.5,
                viscous: 0.01,
                rise: None,
            },
            offset: 0.0,
            pulse: Some(ReversalPulse {
                amplitude: 0.2,
                decay_s: 0.01,
            }),
        };
        let (tc, ratio) = (1e-3, 1.0);
        let mut m = ReferenceMotion::default();
        let at_rest = m.sample(0.0, tc, ratio);
        assert_eq!(m.friction(&f, &at_rest), 0.0);
        let up = m.sample(0.01, tc, ratio);
        // No reversal yet: the law alone, 0.5 + 0.01·10.
        assert!((m.friction(&f, &up) - 0.6).abs() < 1e-12);
        let down = m.sample(0.0, tc, ratio);
        assert!((m.friction(&f, &down) + 0.6 + 0.2).abs() < 1e-12);
        let later = m.sample(-0.01, tc, ratio);
        let pulse = 0.2 * (-0.1f64).exp();
        assert!((m.friction(&f, &later) + 0.6 + pulse).abs() < 1e-12);
    }
}
