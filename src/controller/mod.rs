//! The discrete servo controller (docs/model.md §1 "Servo as real drives have it", §4;
//! the paper's Fig. 6).
//!
//! Every period Tc the controller samples the encoders and computes an output u that
//! the D/A converter holds until the next sample (zero-order hold); the drive turns it
//! into torque (force) T = drive_gain·u:
//!
//! ```text
//! θm,meas = Q_m(θm(t − delay))                 motor encoder: dead time, then counts
//! θt,meas = Q_t(θt(t))                         table encoder, 0.0001° by default
//! e   = θref/(Rg·Rw) − θm,meas                 semi-closed loop (motor radians)
//! e   = (θref − θt,meas)/(Rg·Rw)               full-closed loop (motor radians)
//! Ie += Tc·e                                   only with Kpi > 0 (position PI)
//! ω*  = clamp(Kpp·e + Kpi·Ie, ±speed_limit)    position loop
//! ω   = (θm,meas[k] − θm,meas[k−1]) / Tc       backward difference (1 − z⁻¹)/Tc
//! I  += Tc·(ω* − ω)                            integrator Tc·z/(z − 1)
//! u   = clamp(Kvp·(ω* − ω) + Kvi·I + a_k, ±torque_limit)   a_k: the added signal
//! T   = drive_gain·u                           applied at sample k, or at k + 1 with
//!                                              output_delay_periods = 1
//! ```
//!
//! The position loop (its error, the feed-forward, the compensations, ω*) runs every
//! N-th sample, N = position_period_s/Tc (SINUMERIK's position-control cycle; 1 by
//! default), ω* held between. With a current loop lag T_i > 0 the torque follows
//! the output through a first-order lag sampled at Tc:
//! T_k = T_{k−1} + (1 − e^{−Tc/T_i})·(drive_gain·u − T_{k−1}).
//!
//! On a linear axis read m for rad. `torque_limit` is the output's limit in the
//! output's own unit (N·m for a torque command, V or A with a drive gain). With the
//! defaults (Kpi = 0, drive_gain = 1, no delay, nothing added) this is the controller
//! of the paper's presets, computed exactly as before. The EMPS benchmark's law,
//! u_k = kv·(kp·(r_k − q_k) − (q_k − q_{k−1})/Ts), is Kpi = Kvi = 0, Kpp = kp, Kvp = kv
//! (A. Janot, M. Gautier, M. Brunot, "Data Set and Reference Models of EMPS", 2019).
//!
//! The integrators stop while their output is saturated in the direction the error
//! pushes (conditional integration), so a long move at the torque or speed limit does
//! not wind them up. Gains ([`Gains`], `Copy`) are kept apart from the state that
//! `update(&mut self, …)` changes.

mod compensation;
mod feedforward;
mod filters;

pub use compensation::{Compensation, ErrorTable, FrictionCompensation, ReversalPulse, TableError};
pub use filters::{Biquad, FilterChain};

use feedforward::{Motion, ReferenceMotion};

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
    /// Position loop integral gain, 1/s² (0: P position loop).
    pub kpi: f64,
    pub kvp: f64,
    pub kvi: f64,
    /// Control period, s.
    pub tc: f64,
    /// Limit of the output, in the output's unit.
    pub torque_limit: f64,
    pub speed_limit: f64,
    /// Torque (force) per unit of output.
    pub drive_gain: f64,
    /// Whether u_k is applied one sample late (at k + 1).
    pub one_sample_late: bool,
    /// Motor encoder quantum, rad or m (0: none).
    pub motor_quantum: f64,
    /// Table encoder quantum, rad or m (0: none).
    pub table_quantum: f64,
    pub loop_mode: LoopMode,
    /// Table turns per motor turn, Rg·Rw.
    pub ratio: f64,
    /// Encoder dead time in whole periods and the remaining fraction of a period.
    delay_periods: usize,
    delay_fraction: f64,
    /// Velocity feed-forward, the fraction of the reference's speed.
    pub kvff: f64,
    /// Torque feed-forward, output per motor rad/s² (m/s²).
    pub kaff: f64,
    /// The symmetrising lag's factor 1 − e^{−Tp/T} at the position cycle Tp (0: none).
    pub symmetrising: f64,
    /// The torque-setpoint filters, at rest.
    pub filters: FilterChain,
    /// Control periods per position-controller cycle (1: every period).
    pub position_every: u32,
    /// The current loop's lag factor 1 − e^{−Tc/T_i} (0: none, the torque follows at
    /// once).
    pub current_lag: f64,
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
            kpi: c.kpi,
            kvp: c.kvp,
            kvi: c.kvi,
            tc: c.tc,
            torque_limit: c.torque_limit,
            speed_limit: c.speed_limit,
            drive_gain: c.drive_gain,
            one_sample_late: c.output_delay_periods == 1.0,
            motor_quantum: c.motor_quantum(),
            table_quantum: c.table_encoder_resolution,
            loop_mode: c.loop_mode,
            ratio: p.ratio(),
            delay_periods: periods.floor() as usize,
            delay_fraction: periods - periods.floor(),
            kvff: c.kvff,
            kaff: c.kaff,
            symmetrising: if c.symmetrising_s > 0.0 {
                let tp = c.tc * f64::from(c.position_every());
                -(-tp / c.symmetrising_s).exp_m1()
            } else {
                0.0
            },
            filters: FilterChain::new(&c.filters, c.tc),
            position_every: c.position_every(),
            current_lag: if c.current_lag_s > 0.0 {
                -(-c.tc / c.current_lag_s).exp_m1()
            } else {
                0.0
            },
        })
    }

    /// The position controller's cycle, s.
    pub fn position_period(&self) -> f64 {
        self.tc * f64::from(self.position_every)
    }

    /// Whether the controller derives anything from the reference's motion (feed-
    /// forward or the symmetrising lag).
    fn shapes_the_reference(&self) -> bool {
        self.kvff != 0.0 || self.kaff != 0.0 || self.symmetrising != 0.0
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

/// The controller's memory: integrators, last velocity sample, the encoder delay line,
/// the output the D/A holds (and the one waiting a sample), and the signal added to
/// the output.
#[derive(Clone, Debug)]
pub struct Controller {
    gains: Gains,
    integral: f64,
    position_integral: f64,
    previous_motor: f64,
    table_reading: f64,
    output: f64,
    pending: f64,
    torque: f64,
    added: f64,
    history: [f64; HISTORY],
    head: usize,
    reference: ReferenceMotion,
    filters: FilterChain,
    compensation: Compensation,
    /// Samples since the position loop last ran, modulo its cycle.
    tick: u32,
    /// The speed command and the torque feed-forward the position loop holds.
    speed_command: f64,
    torque_ff: f64,
    /// The torque the current loop's lag has reached (with a lag).
    lagged_torque: f64,
}

impl Controller {
    /// A controller at rest, its encoders reading the given true angles.
    pub fn new(gains: Gains, motor_angle: f64, table_angle: f64) -> Self {
        Controller {
            gains,
            integral: 0.0,
            position_integral: 0.0,
            previous_motor: quantise(motor_angle, gains.motor_quantum),
            table_reading: quantise(table_angle, gains.table_quantum),
            output: 0.0,
            pending: 0.0,
            torque: 0.0,
            added: 0.0,
            history: [motor_angle; HISTORY],
            head: 0,
            reference: ReferenceMotion::default(),
            filters: gains.filters,
            compensation: Compensation::default(),
            tick: 0,
            speed_command: 0.0,
            torque_ff: 0.0,
            lagged_torque: 0.0,
        }
    }

    /// Sets the compensations (backlash, error table, friction) applied from the next
    /// sample on; [`Compensation::default`] switches them off.
    pub fn set_compensation(&mut self, compensation: Compensation) {
        self.compensation = compensation;
    }

    /// Starts in motion (call right after [`Controller::new`]): the motor has been
    /// turning at `motor_velocity` (rad/s or m/s) up to the angle the controller was
    /// created at, so the delay line and the previous reading, one period before the
    /// first sample, see that motion (for a replay that starts while the axis moves).
    pub fn start_moving(&mut self, motor_velocity: f64) {
        let g = self.gains;
        let now = self.history[self.head];
        for back in 0..HISTORY {
            self.history[(self.head + HISTORY - back) % HISTORY] =
                now - (back + 1) as f64 * g.tc * motor_velocity;
        }
        self.previous_motor = quantise(self.delayed_motor_angle(), g.motor_quantum);
        self.reference.start_moving(motor_velocity);
    }

    /// The settings.
    pub fn gains(&self) -> &Gains {
        &self.gains
    }

    /// The torque (force) the drive applies now, N·m or N: drive_gain × the output
    /// the D/A holds.
    pub fn torque(&self) -> f64 {
        self.torque
    }

    /// The output the D/A holds now, in the controller's unit (N·m or N for a torque
    /// command, V or A with a drive gain), the added signal included.
    pub fn output(&self) -> f64 {
        self.output
    }

    /// The last motor encoder reading (delayed and quantised), rad or m.
    pub fn motor_reading(&self) -> f64 {
        self.previous_motor
    }

    /// The last table encoder reading (quantised), rad or m.
    pub fn table_reading(&self) -> f64 {
        self.table_reading
    }

    /// Sets the signal added to the output from the next sample on (test pulses,
    /// dither), in the output's unit; 0 adds nothing. The sum is saturated.
    pub fn set_added(&mut self, added: f64) {
        self.added = added;
    }

    /// One control period: samples the true motor and table angles, returns the
    /// torque (force) applied from now on for the reference table angle `reference`
    /// (rad or m).
    pub fn update(&mut self, reference: f64, motor_angle: f64, table_angle: f64) -> f64 {
        let g = self.gains;
        self.head = (self.head + 1) % HISTORY;
        self.history[self.head] = motor_angle;
        let motor = quantise(self.delayed_motor_angle(), g.motor_quantum);
        self.table_reading = quantise(table_angle, g.table_quantum);
        if self.tick == 0 {
            let (position, speed_ff, torque_ff) = if self.shaping() {
                self.shaped(reference)
            } else {
                (reference, 0.0, 0.0)
            };
            let error = match g.loop_mode {
                LoopMode::SemiClosed => position / g.ratio - motor,
                LoopMode::FullClosed => (position - self.table_reading) / g.ratio,
            };
            self.speed_command = self.position_loop(error, speed_ff);
            self.torque_ff = torque_ff;
        }
        self.tick = (self.tick + 1) % g.position_every;
        let speed = (motor - self.previous_motor) / g.tc;
        self.previous_motor = motor;
        let output = self.velocity_loop(self.speed_command - speed, self.torque_ff);
        self.hold(output)
    }

    /// Whether feed-forward, the symmetrising lag or a compensation act.
    fn shaping(&self) -> bool {
        self.gains.shapes_the_reference() || !self.compensation.is_off()
    }

    /// The position loop's reference (compensated, then symmetrised), the velocity
    /// feed-forward (motor rad/s) and the torque feed-forward with the friction
    /// compensation (output units) at reference `r`.
    fn shaped(&mut self, r: f64) -> (f64, f64, f64) {
        let g = self.gains;
        let motion: Motion = self.reference.sample(r, g.position_period(), g.ratio);
        let c = &self.compensation;
        let mut position = r + c.position_offset(r, motion.downwards);
        if g.symmetrising != 0.0 {
            position = self.reference.symmetrise(position, g.symmetrising);
        }
        let friction = c
            .friction
            .as_ref()
            .map_or(0.0, |f| self.reference.friction(f, &motion));
        let torque = g.kaff * motion.acceleration + friction / g.drive_gain;
        (position, g.kvff * motion.speed, torque)
    }

    /// The velocity command for the position error `error`: Kpp·e, plus Kpi·Ie with a
    /// position integrator, plus the velocity feed-forward `ff`, clamped to the speed
    /// limit.
    fn position_loop(&mut self, error: f64, ff: f64) -> f64 {
        let g = &self.gains;
        if g.kpi == 0.0 {
            let command = g.kpp * error;
            let command = if ff != 0.0 { command + ff } else { command };
            return command.clamp(-g.speed_limit, g.speed_limit);
        }
        let integral = self.position_integral + g.position_period() * error;
        let unlimited = g.kpp * error + g.kpi * integral;
        let unlimited = if ff != 0.0 { unlimited + ff } else { unlimited };
        let command = unlimited.clamp(-g.speed_limit, g.speed_limit);
        if command == unlimited || unlimited.signum() != error.signum() {
            self.position_integral = integral;
        }
        command
    }

    /// The saturated output for the velocity error: the PI law plus the torque
    /// feed-forward `ff`, through the setpoint filters, plus the added signal.
    fn velocity_loop(&mut self, speed_error: f64, ff: f64) -> f64 {
        let g = &self.gains;
        let integral = self.integral + g.tc * speed_error;
        let law = g.kvp * speed_error + g.kvi * integral;
        let law = if ff != 0.0 { law + ff } else { law };
        let law = if self.filters.is_empty() {
            law
        } else {
            self.filters.filter(law)
        };
        let unlimited = if self.added != 0.0 {
            law + self.added
        } else {
            law
        };
        let output = unlimited.clamp(-g.torque_limit, g.torque_limit);
        // Conditional integration: hold the integrator while saturated the same way.
        if output == unlimited || unlimited.signum() != speed_error.signum() {
            self.integral = integral;
        }
        output
    }

    /// Puts `output` on the D/A now, or after one sample; returns the torque applied
    /// (through the current loop's lag, with one).
    fn hold(&mut self, output: f64) -> f64 {
        let g = &self.gains;
        self.output = if g.one_sample_late {
            std::mem::replace(&mut self.pending, output)
        } else {
            output
        };
        let torque = g.drive_gain * self.output;
        self.torque = if g.current_lag > 0.0 {
            self.lagged_torque += g.current_lag * (torque - self.lagged_torque);
            self.lagged_torque
        } else {
            torque
        };
        self.torque
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

    /// The EMPS-like P/P law on an ideal encoder: u = Kvp·(Kpp·e − ω).
    fn drive_with_gain(late: bool) -> Gains {
        let mut p = presets::load("direct-drive").unwrap();
        let c = &mut p.controller;
        (c.kpp, c.kvp, c.kvi, c.tc) = (160.0, 240.0, 0.0, 1e-3);
        (c.torque_limit, c.drive_gain) = (10.0, 35.0);
        c.output_delay_periods = if late { 1.0 } else { 0.0 };
        (c.motor_encoder_counts, c.table_encoder_resolution) = (0.0, 0.0);
        Gains::new(&p).unwrap()
    }

    #[test]
    fn the_output_is_saturated_in_its_own_unit_and_scaled_by_the_drive_gain() {
        let g = drive_with_gain(false);
        let mut c = Controller::new(g, 0.0, 0.0);
        // 1e-4 m of error: 240·160·1e-4 = 3.84 V, 134.4 N.
        let torque = c.update(1e-4, 0.0, 0.0);
        assert!((c.output() - 3.84).abs() < 1e-12, "{}", c.output());
        assert_eq!(torque, 35.0 * c.output());
        // 1 mm: 38.4 V, saturated at 10 V = 350 N.
        let mut c = Controller::new(g, 0.0, 0.0);
        assert_eq!(c.update(1e-3, 0.0, 0.0), 350.0);
        assert_eq!(c.output(), 10.0);
    }

    #[test]
    fn one_sample_late_applies_each_output_a_period_later() {
        let (now, late) = (drive_with_gain(false), drive_with_gain(true));
        let (mut a, mut b) = (
            Controller::new(now, 0.0, 0.0),
            Controller::new(late, 0.0, 0.0),
        );
        let mut previous = 0.0;
        for k in 0..20 {
            let (r, q) = (1e-5 * k as f64, 0.7e-5 * k as f64);
            a.update(r, q, q);
            b.update(r, q, q);
            assert_eq!(b.output(), previous, "sample {k}");
            previous = a.output();
        }
    }

    #[test]
    fn the_added_signal_is_in_the_output_and_saturated_with_it() {
        let g = drive_with_gain(false);
        let mut plain = Controller::new(g, 0.0, 0.0);
        let mut dithered = Controller::new(g, 0.0, 0.0);
        dithered.set_added(0.25);
        plain.update(1e-5, 0.0, 0.0);
        dithered.update(1e-5, 0.0, 0.0);
        assert!((dithered.output() - plain.output() - 0.25).abs() < 1e-15);
        dithered.set_added(50.0);
        dithered.update(1e-5, 0.0, 0.0);
        assert_eq!(dithered.output(), 10.0);
    }

    #[test]
    fn a_position_integrator_accumulates_the_error() {
        let mut p = presets::load("direct-drive").unwrap();
        p.controller.kpi = 400.0;
        (p.controller.motor_encoder_counts, p.controller.kvi) = (0.0, 0.0);
        let g = Gains::new(&p).unwrap();
        let mut c = Controller::new(g, 0.0, 0.0);
        let e = 1e-4;
        let first = c.update(e, 0.0, 0.0);
        let second = c.update(e, 0.0, 0.0);
        // ω* grows by Kpi·Tc·e per period; the output by Kvp times that.
        assert!(
            (second - first - g.kvp * g.kpi * g.tc * e).abs() < 1e-9,
            "{first} {second}"
        );
    }

    #[test]
    fn a_slower_position_cycle_holds_the_speed_command_between_its_samples() {
        let mut p = presets::load("direct-drive").unwrap();
        (p.controller.motor_encoder_counts, p.controller.kvi) = (0.0, 0.0);
        p.controller.position_period_s = 4.0 * p.controller.tc;
        let g = Gains::new(&p).unwrap();
        assert_eq!(g.position_every, 4);
        let mut c = Controller::new(g, 0.0, 0.0);
        // The reference moves every sample; the position loop sees it every fourth:
        // u = Kvp·(ω* − ω) with ω* = Kpp·e at the last position sample, the motor
        // held at 0.
        let outputs: Vec<f64> = (0..8)
            .map(|k| c.update(1e-5 * k as f64, 0.0, 0.0))
            .collect();
        let u = |e: f64| g.kvp * g.kpp * e;
        for (k, out) in outputs.iter().enumerate() {
            let sampled = 1e-5 * (4 * (k / 4)) as f64;
            assert!(
                (out - u(sampled)).abs() < 1e-9,
                "sample {k}: {out} vs {}",
                u(sampled)
            );
        }
    }

    #[test]
    fn the_current_loop_lags_the_torque_behind_the_output() {
        let mut p = presets::load("direct-drive").unwrap();
        (p.controller.motor_encoder_counts, p.controller.kvi) = (0.0, 0.0);
        p.controller.current_lag_s = 2.0 * p.controller.tc;
        let g = Gains::new(&p).unwrap();
        let mut c = Controller::new(g, 0.0, 0.0);
        let a = 1.0 - (-0.5f64).exp();
        let first = c.update(1e-6, 0.0, 0.0);
        let u = c.output() * g.drive_gain;
        assert!((first - a * u).abs() < 1e-12, "{first} vs {}", a * u);
        let second = c.update(1e-6, 0.0, 0.0);
        assert!((second - (first + a * (u - first))).abs() < 1e-12);
    }

    #[test]
    fn a_moving_start_sees_the_motion_in_its_first_velocity_sample() {
        let g = drive_with_gain(false);
        let mut c = Controller::new(g, 0.5, 0.5);
        c.start_moving(0.01);
        // At the first sample the motor is where it was made: the backward difference
        // is the velocity, 0.01 m/s, and the reference matches the position.
        c.update(0.5, 0.5, 0.5);
        assert!((c.output() + g.kvp * 0.01).abs() < 1e-9, "{}", c.output());
    }
}
