//! Running one simulation: the kernel at a fixed step, driven open loop by a
//! [`TorqueInput`] or closed loop by the [`Controller`] following a [`Trajectory`],
//! with every step checked for divergence and reported to a [`Recorder`].
//! [`LaneSimulation`] advances several independent simulations of one model in
//! lockstep lanes, for batches such as the frequencies of a sweep.

use std::fmt::Write as _;

use crate::controller::{Controller, ControllerError, Gains};
use crate::input::{TorqueInput, Trajectory};
use crate::model::drive::idx::*;
use crate::model::lanes::Lanes;
use crate::model::{Drive, Kernel, LaneDrive, LaneMismatch, ParamError, Params, States, NSTATE};

pub mod batch;
mod lanes;
use crate::recorder::Recorder;
pub use lanes::{LaneSimulation, LANES};

/// The RK4 step is chosen so that |λ|·dt ≤ this for the fastest eigenvalue λ of the
/// linearised model (docs/model.md gives the resulting errors).
pub const STEP_ACCURACY: f64 = 0.2;
/// Beyond |λ|·dt = this a step is refused (RK4's stability limit is ≈ 2.8; past 1
/// the fastest mode is badly resolved).
pub const STEP_LIMIT: f64 = 1.0;
/// |velocity| (rad/s or m/s) above which a run is declared diverged.
pub const VELOCITY_LIMIT: f64 = 1e6;

/// The names of the states, as in the CSV output.
pub const STATE_NAMES: [&str; NSTATE] = [
    "motor_angle_rad",
    "motor_velocity_rad_per_s",
    "shaft_angle_rad",
    "shaft_velocity_rad_per_s",
    "axial_displacement_m",
    "axial_velocity_m_per_s",
    "table_angle_rad",
    "table_velocity_rad_per_s",
];

/// Why a simulation cannot run or did not finish.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error(transparent)]
    Controller(#[from] ControllerError),
    #[error("integration step dt = {} s must be positive and finite", crate::names::Num(*dt))]
    BadStep { dt: f64 },
    #[error("integration step dt = {} s is too large for the stiffest mode of this model (|λ| = {rate:.4e} rad/s): use dt ≤ {max:.3e} s", crate::names::Num(*dt))]
    StepTooLarge { dt: f64, rate: f64, max: f64 },
    #[error("control period Tc = {tc} s is not a whole number of integration steps dt = {dt} s")]
    ControlPeriod { tc: f64, dt: f64 },
    #[error("simulation diverged at t = {time:.6} s: {state}")]
    Diverged { time: f64, state: String },
    #[error(transparent)]
    Lanes(#[from] LaneMismatch),
    #[error("lane {lane} is integrated with dt = {dt} s, lane 0 with {dt0} s: lanes of one batch share the step")]
    LaneStep { lane: usize, dt: f64, dt0: f64 },
    /// A sine the step cannot resolve: above the Nyquist frequency 1/(2·dt).
    #[error("a sine of {} Hz on an integration step of {dt:e} s, above its Nyquist frequency {} Hz: the run would alias it to another frequency (lower freq_hz, or give a shorter dt)", crate::names::Num(*freq_hz), crate::names::Num((0.5e6 / *dt).round() / 1e6))]
    AboveNyquist { freq_hz: f64, dt: f64 },
    /// A control period the model cannot run: longer than its slowest mode's period.
    #[error("control period Tc = {} s is longer than the period of the drive's slowest mode ({} Hz, {:.3e} s): a servo sampled that slowly does not control the drive (a unit slip? Tc is in seconds, e.g. 1e-3)", crate::names::Num(*tc), crate::names::Num(*mode_hz), 1.0 / *mode_hz)]
    ControlPeriodTooLong { tc: f64, mode_hz: f64 },
    /// Stopped at a request ([`crate::interrupt`]) at time `time`.
    #[error("simulation interrupted at t = {time:.6} s")]
    Interrupted { time: f64 },
}

/// The default integration step for `params`: the largest of 1e-5 s, 5e-6 s, 2e-6 s,
/// 1e-6 s, … with |λ|·dt ≤ [`STEP_ACCURACY`] for the fastest eigenvalue λ of the
/// linearised model, and a whole number of steps per control period. The ladder is
/// searched one decade below its largest accurate step; a control period none of
/// those divides (a recorded one, 0.0039999999 s) is divided evenly instead, into
/// the fewest steps that are accurate — never a descent to 1e-11 s, whose run would
/// take hours.
pub fn default_step(params: &Params) -> Result<f64, SimError> {
    let rate = crate::model::modes::max_rate(params)?;
    let tc = params.controller.tc;
    let mut accurate = (5..12)
        .flat_map(|exponent| [1.0, 0.5, 0.25, 0.2].map(|m| m / 10f64.powi(exponent)))
        .filter(|dt| rate * dt <= STEP_ACCURACY);
    let Some(largest) = accurate.next() else {
        return Err(SimError::StepTooLarge {
            dt: 1e-12,
            rate,
            max: STEP_ACCURACY / rate,
        });
    };
    let dividing = std::iter::once(largest)
        .chain(accurate.take_while(|&dt| dt >= 0.1 * largest))
        .find(|&dt| whole_steps(tc, dt).is_some());
    Ok(dividing.unwrap_or_else(|| tc / (tc / largest).ceil()))
}

/// The [`default_step`] every set of `params` shares; an error names the first set
/// whose own step differs from the first's (lanes of one batch share their step).
pub fn common_step(params: &[Params]) -> Result<f64, SimError> {
    let dt0 = default_step(&params[0])?;
    for (lane, p) in params.iter().enumerate().skip(1) {
        let dt = default_step(p)?;
        if dt != dt0 {
            return Err(SimError::LaneStep { lane, dt, dt0 });
        }
    }
    Ok(dt0)
}

/// `Some(n)` if `period` is `n` steps of `dt` (to 1e-9 relative).
fn whole_steps(period: f64, dt: f64) -> Option<usize> {
    let n = (period / dt).round();
    (n >= 1.0 && (n * dt - period).abs() <= 1e-9 * period).then_some(n as usize)
}

/// One simulated rotary table.
#[derive(Clone, Debug)]
pub struct Simulation {
    drive: Drive,
    /// The drive as the kernel reads it.
    lane: LaneDrive<1>,
    dt: f64,
    steps: u64,
    y: States<1>,
    kernel: Kernel<1>,
    load: f64,
}

impl Simulation {
    /// A table at rest at zero angles, integrated with step `dt` (checked against the
    /// model's stiffest mode), with no external load but its `Tload`.
    pub fn new(params: &Params, dt: f64) -> Result<Self, SimError> {
        let drive = checked_drive(params, dt)?;
        Ok(Simulation {
            drive,
            lane: LaneDrive::splat(&drive),
            dt,
            steps: 0,
            y: [[0.0]; NSTATE],
            kernel: Kernel::default(),
            load: drive.tload(),
        })
    }

    /// As [`Simulation::new`] with the [`default_step`].
    pub fn with_default_step(params: &Params) -> Result<Self, SimError> {
        Self::new(params, default_step(params)?)
    }

    /// The integration step, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The simulated time, s.
    pub fn time(&self) -> f64 {
        self.steps as f64 * self.dt
    }

    /// The compiled model.
    pub fn drive(&self) -> &Drive {
        &self.drive
    }

    /// The current state (see `model::idx`).
    pub fn state(&self) -> [f64; NSTATE] {
        self.y.map(|s| s[0])
    }

    /// Sets the state. Slots the topology does not integrate follow the ones it does
    /// ([`Drive::mirror`]: in the direct and two-mass topologies the shaft follows the
    /// motor, in direct_drive motor and shaft follow the table).
    pub fn set_state(&mut self, mut y: [f64; NSTATE]) {
        self.drive.mirror(&mut y);
        self.y = y.map(|v| [v]);
    }

    /// Sets an external table torque (e.g. a brake), N·m (N on a linear axis); the
    /// parameter `Tload` adds to it.
    pub fn set_load(&mut self, torque: f64) {
        self.load = torque + self.drive.tload();
    }

    /// Whether motor, shaft and table stuck in the last step.
    pub fn stuck(&self) -> [bool; 3] {
        self.kernel.stuck(0)
    }

    /// Steps split at a contact event so far (diagnostics; docs/model.md).
    pub fn contact_events(&self) -> u64 {
        self.kernel.events()
    }

    /// A controller for this table, at rest at the current angles.
    pub fn controller(&self, params: &Params) -> Result<Controller, SimError> {
        check_control_period(params)?;
        let gains = Gains::new(params)?;
        Ok(Controller::new(
            gains,
            self.y[THETA_M][0],
            self.y[THETA_T][0],
        ))
    }

    /// Runs `duration` seconds open loop.
    pub fn run_open_loop<I: TorqueInput, R: Recorder>(
        &mut self,
        input: &mut I,
        duration: f64,
        recorder: &mut R,
    ) -> Result<(), SimError> {
        // The drive's form is chosen once, outside the step loop (kernel.rs,
        // `Kernel::step_meshed`).
        if self.drive.form == crate::model::drive::Form::Rigid {
            self.open_loop::<true, I, R>(input, duration, recorder)
        } else {
            self.open_loop::<false, I, R>(input, duration, recorder)
        }
    }

    fn open_loop<const RIGID: bool, I: TorqueInput, R: Recorder>(
        &mut self,
        input: &mut I,
        duration: f64,
        recorder: &mut R,
    ) -> Result<(), SimError> {
        let n = (duration / self.dt).round() as u64;
        if self.steps == 0 {
            recorder.record(0.0, &self.state(), input.step_torques(0.0, self.dt)[0]);
        }
        for _ in 0..n {
            let motor = input.step_torques(self.time(), self.dt);
            self.advance::<RIGID>(&motor.map(|m| [m]))?;
            recorder.record(self.time(), &self.state(), motor[2]);
        }
        Ok(())
    }

    /// Runs `duration` seconds under `controller`, which follows `trajectory` (table
    /// angle command, rad or m) and updates every control period, holding its output.
    pub fn run_closed_loop<T: Trajectory + ?Sized, R: Recorder>(
        &mut self,
        controller: &mut Controller,
        trajectory: &T,
        duration: f64,
        recorder: &mut R,
    ) -> Result<(), SimError> {
        if self.drive.form == crate::model::drive::Form::Rigid {
            self.closed_loop::<true, T, R>(controller, trajectory, duration, recorder)
        } else {
            self.closed_loop::<false, T, R>(controller, trajectory, duration, recorder)
        }
    }

    fn closed_loop<const RIGID: bool, T: Trajectory + ?Sized, R: Recorder>(
        &mut self,
        controller: &mut Controller,
        trajectory: &T,
        duration: f64,
        recorder: &mut R,
    ) -> Result<(), SimError> {
        let tc = controller.gains().tc;
        let per =
            whole_steps(tc, self.dt).ok_or(SimError::ControlPeriod { tc, dt: self.dt })? as u64;
        let n = (duration / self.dt).round() as u64;
        if self.steps == 0 {
            recorder.record(0.0, &self.state(), controller.torque());
        }
        for _ in 0..n {
            if self.steps % per == 0 {
                let t = self.time();
                controller.update(trajectory.angle(t), self.y[THETA_M][0], self.y[THETA_T][0]);
            }
            let u = controller.torque();
            self.advance::<RIGID>(&[[u]; 3])?;
            recorder.record(self.time(), &self.state(), u);
        }
        Ok(())
    }

    /// One step, then the divergence check.
    #[inline]
    fn advance<const RIGID: bool>(&mut self, motor: &[[f64; 1]; 3]) -> Result<(), SimError> {
        let (d, y, load) = (&self.lane, &mut self.y, &[self.load]);
        if RIGID {
            self.kernel.step_rigid(d, y, motor, load, self.dt);
        } else {
            self.kernel.step_meshed(d, y, motor, load, self.dt);
        }
        self.steps += 1;
        if diverged(&self.y).is_none() {
            if crate::interrupt::at_step(self.steps) {
                return Err(SimError::Interrupted { time: self.time() });
            }
            Ok(())
        } else {
            Err(SimError::Diverged {
                time: self.time(),
                state: describe(&self.state()),
            })
        }
    }
}

/// Refuses a control period longer than the period of the drive's slowest
/// (motor-free, elastic) mode: such a servo cannot hold the drive, and a 10 s `Tc` is a
/// slip for 10 ms. A rigid drive has no such mode and no such limit.
pub fn check_control_period(params: &Params) -> Result<(), SimError> {
    let tc = params.controller.tc;
    let slowest = crate::model::modes::modes(params)?
        .free_hz
        .into_iter()
        .filter(|f| *f > 0.0 && f.is_finite())
        .fold(f64::INFINITY, f64::min);
    if slowest.is_finite() && tc * slowest > 1.0 {
        return Err(SimError::ControlPeriodTooLong {
            tc,
            mode_hz: slowest,
        });
    }
    Ok(())
}

/// The compiled model, after checking the step `dt` against its stiffest mode.
fn checked_drive(params: &Params, dt: f64) -> Result<Drive, SimError> {
    let drive = Drive::new(params)?;
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(SimError::BadStep { dt });
    }
    let rate = crate::model::modes::max_rate(params)?;
    if rate * dt > STEP_LIMIT {
        return Err(SimError::StepTooLarge {
            dt,
            rate,
            max: STEP_ACCURACY / rate,
        });
    }
    Ok(drive)
}

/// The first lane whose state diverged, if any. A NaN or infinity anywhere reaches
/// the velocities within a step; checking them (and the angles' sum) catches every
/// divergence at little cost.
#[inline(always)]
fn diverged<const L: usize>(y: &States<L>) -> Option<usize> {
    let speed = |i: usize| Lanes(y[i]).map(f64::abs);
    let fastest = speed(OMEGA_M)
        .zip(speed(OMEGA_W), f64::max)
        .zip(speed(V_W), f64::max)
        .zip(speed(OMEGA_T), f64::max);
    let angles = Lanes(y[THETA_M]) + Lanes(y[THETA_W]) + Lanes(y[X_W]) + Lanes(y[THETA_T]);
    let bad = fastest.zip(angles, |v, a| {
        if v < VELOCITY_LIMIT && a.is_finite() {
            0.0
        } else {
            1.0
        }
    });
    if bad.any(|b| b != 0.0) {
        bad.0.iter().position(|&b| b != 0.0)
    } else {
        None
    }
}

/// "motor_angle_rad = …, …" for error messages.
/// The states that left the finite numbers (or the largest, if none did), briefly.
fn describe(y: &[f64; NSTATE]) -> String {
    let bad: Vec<&str> = STATE_NAMES
        .iter()
        .zip(y)
        .filter(|(_, v)| !v.is_finite())
        .map(|(n, _)| *n)
        .collect();
    if !bad.is_empty() {
        let more = if bad.len() > 2 { ", …" } else { "" };
        return format!("{} not finite{more}", bad[..bad.len().min(2)].join(", "));
    }
    let (name, v) = STATE_NAMES
        .iter()
        .zip(y)
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map_or(("state", 0.0), |(n, v)| (*n, *v));
    let mut s = String::new();
    let _ = write!(s, "{name} = {v:.3e}");
    s
}
