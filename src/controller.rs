//! The discrete servo controller of the paper's Fig. 6 (MODEL.md §4).
//!
//! Every period Tc the controller samples the encoders and computes a torque command
//! that the D/A converter holds until the next sample:
//!
//! ```text
//! θm,meas = Q_m(θm(t − delay))                 motor encoder: dead time, then counts
//! θt,meas = Q_t(θt(t))                         table encoder, 0.0001° by default
//! e   = θref/(Rg·Rw) − θm,meas                 semi-closed loop (motor radians)
//! e   = (θref − θt,meas)/(Rg·Rw)               full-closed loop (motor radians)
//! ω*  = clamp(Kpp·e, ±speed_limit)             P position loop
//! ω   = (θm,meas[k] − θm,meas[k−1]) / Tc       backward difference (1 − z⁻¹)/Tc
//! I  += Tc·(ω* − ω)                            integrator Tc·z/(z − 1)
//! T   = clamp(Kvp·(ω* − ω) + Kvi·I, ±torque_limit)
//! ```
//!
//! The integrator stops while the output is saturated in the direction the error
//! pushes (conditional integration), so a long move at the torque or speed limit
//! does not wind it up. Gains ([`Gains`], `Copy`) are kept apart from the state that
//! `update(&mut self, …)` changes.

use crate::model::params::{LoopMode, Params};

/// Longest encoder dead time, in control periods, the delay line holds.
pub const MAX_DELAY_PERIODS: usize = 62;
const HISTORY: usize = MAX_DELAY_PERIODS + 2;

/// Controller settings that no simulation can satisfy.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ControllerError {
    #[error("encoder_delay = {delay} s exceeds the controller's delay line of {max} s ({periods} periods of Tc); shorten it or lengthen Tc")]
    DelayTooLong {
        delay: f64,
        max: f64,
        periods: usize,
    },
}

/// The controller's fixed settings, derived from [`Params`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gains {
    pub kpp: f64,
    pub kvp: f64,
    pub kvi: f64,
    /// Control period, s.
    pub tc: f64,
    pub torque_limit: f64,
    pub speed_limit: f64,
    /// Motor encoder quantum, rad (0: none).
    pub motor_quantum: f64,
    /// Table encoder quantum, rad (0: none).
    pub table_quantum: f64,
    pub loop_mode: LoopMode,
    /// Table turns per motor turn, Rg·Rw.
    pub ratio: f64,
    /// Encoder dead time in whole periods and the remaining fraction of a period.
    delay_periods: usize,
    delay_fraction: f64,
}

impl Gains {
    /// The controller settings of `p` (assumed validated).
    pub fn new(p: &Params) -> Result<Self, ControllerError> {
        let c = &p.controller;
        let periods = p.encoder_delay / c.tc;
        if periods > MAX_DELAY_PERIODS as f64 {
            return Err(ControllerError::DelayTooLong {
                delay: p.encoder_delay,
                max: MAX_DELAY_PERIODS as f64 * c.tc,
                periods: MAX_DELAY_PERIODS,
            });
        }
        Ok(Gains {
            kpp: c.kpp,
            kvp: c.kvp,
            kvi: c.kvi,
            tc: c.tc,
            torque_limit: c.torque_limit,
            speed_limit: c.speed_limit,
            motor_quantum: if c.motor_encoder_counts > 0.0 {
                std::f64::consts::TAU / c.motor_encoder_counts
            } else {
                0.0
            },
            table_quantum: c.table_encoder_resolution,
            loop_mode: c.loop_mode,
            ratio: p.ratio(),
            delay_periods: periods.floor() as usize,
            delay_fraction: periods - periods.floor(),
        })
    }
}

/// An encoder reading: the angle rounded down to a whole number of counts.
#[inline]
pub fn quantise(angle: f64, quantum: f64) -> f64 {
    if quantum > 0.0 {
        (angle / quantum).floor() * quantum
    } else {
        angle
    }
}

/// The controller's memory: integrator, last velocity sample, the encoder delay line
/// and the torque the D/A holds.
#[derive(Clone, Debug)]
pub struct Controller {
    gains: Gains,
    integral: f64,
    previous_motor: f64,
    torque: f64,
    history: [f64; HISTORY],
    head: usize,
}

impl Controller {
    /// A controller at rest, its encoders reading the given true angles.
    pub fn new(gains: Gains, motor_angle: f64, table_angle: f64) -> Self {
        let _ = table_angle;
        Controller {
            gains,
            integral: 0.0,
            previous_motor: quantise(motor_angle, gains.motor_quantum),
            torque: 0.0,
            history: [motor_angle; HISTORY],
            head: 0,
        }
    }

    /// The settings.
    pub fn gains(&self) -> &Gains {
        &self.gains
    }

    /// The torque command currently held by the D/A, N·m.
    pub fn torque(&self) -> f64 {
        self.torque
    }

    /// The last motor encoder reading (delayed and quantised), rad.
    pub fn motor_reading(&self) -> f64 {
        self.previous_motor
    }

    /// One control period: samples the true motor and table angles, returns the new
    /// torque command for the reference table angle `reference` (rad).
    pub fn update(&mut self, reference: f64, motor_angle: f64, table_angle: f64) -> f64 {
        let g = &self.gains;
        self.head = (self.head + 1) % HISTORY;
        self.history[self.head] = motor_angle;
        let motor = quantise(self.delayed_motor_angle(), g.motor_quantum);
        let error = match g.loop_mode {
            LoopMode::SemiClosed => reference / g.ratio - motor,
            LoopMode::FullClosed => (reference - quantise(table_angle, g.table_quantum)) / g.ratio,
        };
        let speed_command = (g.kpp * error).clamp(-g.speed_limit, g.speed_limit);
        let speed = (motor - self.previous_motor) / g.tc;
        self.previous_motor = motor;
        let speed_error = speed_command - speed;
        let integral = self.integral + g.tc * speed_error;
        let unlimited = g.kvp * speed_error + g.kvi * integral;
        let torque = unlimited.clamp(-g.torque_limit, g.torque_limit);
        // Conditional integration: hold the integrator while saturated the same way.
        if torque == unlimited || unlimited.signum() != speed_error.signum() {
            self.integral = integral;
        }
        self.torque = torque;
        torque
    }

    /// The motor angle `encoder_delay` ago, interpolated between samples.
    fn delayed_motor_angle(&self) -> f64 {
        let g = &self.gains;
        let at = |back: usize| self.history[(self.head + HISTORY - back) % HISTORY];
        let newer = at(g.delay_periods);
        if g.delay_fraction == 0.0 {
            newer
        } else {
            newer + g.delay_fraction * (at(g.delay_periods + 1) - newer)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn gains(mode: LoopMode, delay: f64) -> Gains {
        let mut p = presets::load("worm-gear").unwrap();
        p.controller.loop_mode = mode;
        p.controller.motor_encoder_counts = 0.0;
        p.controller.table_encoder_resolution = 0.0;
        p.encoder_delay = delay;
        Gains::new(&p).unwrap()
    }

    #[test]
    fn quantisation_rounds_down_to_whole_counts() {
        assert_eq!(quantise(2.7, 1.0), 2.0);
        assert_eq!(quantise(-0.2, 1.0), -1.0);
        assert_eq!(quantise(0.3, 0.0), 0.3);
    }

    #[test]
    fn proportional_then_integral_action() {
        let g = gains(LoopMode::SemiClosed, 0.0);
        let mut c = Controller::new(g, 0.0, 0.0);
        // A small table error: 1e-4 rad at the table = 1e-4/ratio at the motor.
        let e = 1e-4 / g.ratio;
        let t1 = c.update(1e-4, 0.0, 0.0);
        let w = g.kpp * e;
        assert!((t1 - (g.kvp * w + g.kvi * g.tc * w)).abs() < 1e-12, "{t1}");
        let t2 = c.update(1e-4, 0.0, 0.0);
        assert!((t2 - t1 - g.kvi * g.tc * w).abs() < 1e-12);
    }

    #[test]
    fn full_closed_loop_feeds_back_the_table() {
        // Motor already at the commanded position, table behind it (drive twist).
        let g = gains(LoopMode::FullClosed, 0.0);
        let motor = 1e-4 / g.ratio;
        let mut c = Controller::new(g, motor, 0.0);
        assert!(c.update(1e-4, motor, 0.0) > 0.0);
        let g = gains(LoopMode::SemiClosed, 0.0);
        let mut c = Controller::new(g, motor, 0.0);
        assert!(c.update(1e-4, motor, 0.0).abs() < 1e-9);
    }

    #[test]
    fn torque_is_limited_and_the_integrator_does_not_wind_up() {
        let g = gains(LoopMode::SemiClosed, 0.0);
        let mut c = Controller::new(g, 0.0, 0.0);
        for _ in 0..1000 {
            assert_eq!(c.update(10.0, 0.0, 0.0), g.torque_limit);
        }
        // Once at the target the command falls back at once: no stored windup.
        let at_target = 10.0 / g.ratio;
        let t = c.update(10.0, at_target, 10.0);
        assert!(t < g.torque_limit, "{t}");
    }

    #[test]
    fn encoder_dead_time_delays_the_motor_reading() {
        // Delay 2.5 periods: a motor jump shows half after 2 periods, fully after 3.
        let g = gains(LoopMode::SemiClosed, 2.5 * 2.5e-4);
        let mut c = Controller::new(g, 0.0, 0.0);
        let readings: Vec<f64> = (0..5)
            .map(|_| {
                c.update(0.0, 1.0, 0.0);
                c.motor_reading()
            })
            .collect();
        assert_eq!(readings, [0.0, 0.0, 0.5, 1.0, 1.0]);
    }

    #[test]
    fn too_long_a_delay_is_an_error() {
        let mut p = presets::load("worm-gear").unwrap();
        p.encoder_delay = 1.0;
        assert!(matches!(
            Gains::new(&p),
            Err(ControllerError::DelayTooLong { .. })
        ));
    }
}
