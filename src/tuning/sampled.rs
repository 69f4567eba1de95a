//! The loop as it runs, exactly on the sampled loop (docs/tuning.md, "The cascade"):
//! the drive's linear model discretised with an exact zero-order hold over one control
//! period, and the controller of docs/model.md §6 sample by sample — the encoder dead
//! time as the controller interpolates it, the backward-difference speed, the PI and
//! position integrators as they are updated, the setpoint filters in direct form II
//! transposed, the output delay — as one discrete state-space system
//!
//! ```text
//! x[k+1] = A·x[k] + B·w[k]        w: the torque applied over [k, k+1)
//! y[k]   = C·x[k]                 y: the torque the controller puts out at k
//! ```
//!
//! opened at the torque setpoint. Its open loop L(z) = −C·(zI − A)⁻¹·B is exact at
//! z = e^{jωTc} (no aliasing neglected), and the loop closed with its gain scaled by κ
//! has the state matrix A + κ·B·C: it is stable exactly when every eigenvalue of that
//! matrix lies inside the unit circle. The linear model has no backlash, no Coulomb
//! friction, no encoder quantisation and no limits.
//!
//! Two loops: the velocity loop alone (the position loop open, Kpp = Kpi = 0), and the
//! cascade as configured (the position loop closed at its Kpp, semi-closed on the
//! motor encoder or full-closed on the table encoder through the drive's compliance).

use std::f64::consts::TAU;

use nalgebra::{Complex, DMatrix, DVector, RowDVector};

use crate::controller::Biquad;
use crate::model::modes::{LinearModel, SCHUR_ITERATIONS};
use crate::model::params::{ControllerParams, LoopMode};
use crate::model::{ParamError, Params};

/// Which loop is closed around the torque setpoint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Closure {
    /// The velocity loop alone: no position feedback.
    Velocity,
    /// The velocity loop inside the position loop, in the controller's loop type.
    Cascade,
}

/// The drive's linear model, held over a control period: x' = Φ·x + Γ·T.
#[derive(Clone, Debug)]
pub struct DiscretePlant {
    phi: DMatrix<f64>,
    gamma: DVector<f64>,
    /// The state's motor and table coordinates.
    motor: usize,
    table: usize,
    ratio: f64,
    tc: f64,
    encoder_delay: f64,
}

impl DiscretePlant {
    /// `p`'s drive (validated) held over `p`'s control period: Φ and Γ from the
    /// exponential of [[A, B], [0, 0]]·Tc.
    pub fn new(p: &Params) -> Result<Self, ParamError> {
        let model = LinearModel::new(p)?;
        let n = model.n_dof();
        let table = model.index("theta_t").expect("every topology has theta_t");
        let motor = model.index("theta_m").unwrap_or(table);
        let tc = p.controller.tc;
        let mut augmented = DMatrix::zeros(2 * n + 1, 2 * n + 1);
        augmented
            .view_mut((0, 0), (2 * n, 2 * n))
            .copy_from(&model.state_matrix());
        augmented[(n + motor, 2 * n)] = 1.0 / model.m[(motor, motor)];
        let held = (augmented * tc).exp();
        Ok(DiscretePlant {
            phi: held.view((0, 0), (2 * n, 2 * n)).into_owned(),
            gamma: held.view((0, 2 * n), (2 * n, 1)).column(0).into_owned(),
            motor,
            table,
            ratio: p.ratio(),
            tc,
            encoder_delay: p.encoder_delay,
        })
    }

    /// The control period, s.
    pub fn tc(&self) -> f64 {
        self.tc
    }
}

/// The open loop of one controller setting on a [`DiscretePlant`].
#[derive(Clone, Debug)]
pub struct SampledLoop {
    a: DMatrix<f64>,
    b: DVector<f64>,
    c: RowDVector<f64>,
    tc: f64,
}

impl SampledLoop {
    /// The loop `closure` of the controller `c` on `plant`.
    pub fn new(plant: &DiscretePlant, c: &ControllerParams, closure: Closure) -> SampledLoop {
        Builder::new(plant, c, closure).build()
    }

    /// The Nyquist frequency, Hz.
    pub fn nyquist_hz(&self) -> f64 {
        0.5 / self.tc
    }

    /// L at `hz`, exact on the sampled loop; `None` where z = e^{jωTc} is a pole
    /// (0 Hz: the integrators).
    pub fn at(&self, hz: f64) -> Option<Complex<f64>> {
        let z = Complex::new(0.0, TAU * hz * self.tc).exp();
        let n = self.a.nrows();
        let m = DMatrix::from_fn(n, n, |i, j| {
            let diagonal = if i == j { z } else { Complex::new(0.0, 0.0) };
            diagonal - self.a[(i, j)]
        });
        let b = self.b.map(|x| Complex::new(x, 0.0));
        let v = m.lu().solve(&b)?;
        let l = -(0..n).map(|i| v[i] * self.c[i]).sum::<Complex<f64>>();
        l.is_finite().then_some(l)
    }

    /// The largest eigenvalue magnitude of the loop closed with its gain times
    /// `gain`: below 1, stable. `None` where the eigenvalues are not found.
    pub fn spectral_radius(&self, gain: f64) -> Option<f64> {
        let closed = &self.a + gain * &self.b * &self.c;
        let schur = closed.try_schur(f64::EPSILON, SCHUR_ITERATIONS)?;
        Some(
            schur
                .complex_eigenvalues()
                .iter()
                .map(|l| l.norm())
                .fold(0.0, f64::max),
        )
    }
}

/// An affine expression of the loop's state and input: coefficients over the state,
/// then the input's.
type Expr = DVector<f64>;

/// Assembles the state-space form sample by sample, as `Controller::update` computes.
struct Builder<'a> {
    plant: &'a DiscretePlant,
    c: &'a ControllerParams,
    closure: Closure,
    /// State size: the plant's, then the controller's memories.
    n: usize,
    /// Next state of each coordinate, as expressions of this sample's.
    next: Vec<(usize, Expr)>,
}

/// The controller's memories' state coordinates, and how far back the encoder is
/// read.
struct Memories {
    /// The encoder's dead time: whole control periods and a fraction of one.
    whole: usize,
    fraction: f64,
    /// θm one, two, … periods back.
    history: Vec<usize>,
    /// The reading a period back (the backward-difference speed).
    previous: usize,
    speed_integral: Option<usize>,
    /// Whether the position loop is closed.
    cascade: bool,
    position_integral: Option<usize>,
    sections: Vec<Biquad>,
    /// Each section's two states (direct form II transposed).
    filter_states: Vec<[usize; 2]>,
    /// The output held a period (output delay).
    pending: Option<usize>,
    /// The current loop's lag.
    lag: Option<usize>,
    /// The position loop's past outputs (its slower cycle).
    held: Vec<usize>,
}

impl<'a> Builder<'a> {
    fn new(plant: &'a DiscretePlant, c: &'a ControllerParams, closure: Closure) -> Self {
        Builder {
            plant,
            c,
            closure,
            n: plant.phi.nrows(),
            next: Vec::new(),
        }
    }

    /// A new state coordinate.
    fn state(&mut self) -> usize {
        self.n += 1;
        self.n - 1
    }

    /// The controller's law from the plant's state to the torque it puts out, and
    /// the matrices. Every memory is allocated before any expression is formed, so
    /// that the expressions have the final length.
    fn build(mut self) -> SampledLoop {
        let m = self.memories();
        self.plant_rows();
        let reading = self.reading(&m);
        let speed = (&reading - self.unit(m.previous)) / self.c.tc;
        self.next.push((m.previous, reading.clone()));
        let command = self.command(&m, &reading);
        let law = self.speed_law(&m, command - speed);
        let output = self.applied(&m, law) * self.c.drive_gain;
        self.matrices(output)
    }

    /// The controller's memories, each a new state coordinate.
    fn memories(&mut self) -> Memories {
        let periods = self.plant.encoder_delay / self.c.tc;
        let (whole, fraction) = (periods.floor() as usize, periods - periods.floor());
        let depth = whole + usize::from(fraction > 0.0);
        let history: Vec<usize> = (0..depth).map(|_| self.state()).collect();
        let previous = self.state();
        let speed_integral = (self.c.kvi != 0.0).then(|| self.state());
        let cascade = self.closure == Closure::Cascade;
        let position_integral = (cascade && self.c.kpi != 0.0).then(|| self.state());
        let sections: Vec<Biquad> = (self.c.filters.iter())
            .map(|f| Biquad::new(f, self.c.tc))
            .collect();
        let filter_states = (sections.iter())
            .map(|_| [self.state(), self.state()])
            .collect();
        let pending = (self.c.output_delay_periods == 1.0).then(|| self.state());
        let lag = (self.c.current_lag_s > 0.0).then(|| self.state());
        let every = self.c.position_every() as usize;
        let held = if cascade {
            (1..every).map(|_| self.state()).collect()
        } else {
            Vec::new()
        };
        Memories {
            whole,
            fraction,
            history,
            previous,
            speed_integral,
            cascade,
            position_integral,
            sections,
            filter_states,
            pending,
            lag,
            held,
        }
    }

    /// The expression of state coordinate `i` alone.
    fn unit(&self, i: usize) -> Expr {
        let mut e = Expr::zeros(self.n + 1);
        e[i] = 1.0;
        e
    }

    /// The plant: Φ·x + Γ·w.
    fn plant_rows(&mut self) {
        let len = self.n + 1;
        let plant_rows = self.plant.phi.nrows();
        for i in 0..plant_rows {
            let mut e = Expr::zeros(len);
            e.rows_mut(0, plant_rows)
                .copy_from(&self.plant.phi.row(i).transpose());
            e[len - 1] = self.plant.gamma[i];
            self.next.push((i, e));
        }
    }

    /// The motor angle the controller reads, `whole` periods and `fraction` of one
    /// back (interpolated), and the history's shift.
    fn reading(&mut self, m: &Memories) -> Expr {
        // θm[k − i] is `motor` for i = 0, history[i − 1] after.
        let back = |i: usize| {
            if i == 0 {
                self.unit(self.plant.motor)
            } else {
                self.unit(m.history[i - 1])
            }
        };
        let reading = if m.fraction > 0.0 {
            back(m.whole) * (1.0 - m.fraction) + back(m.whole + 1) * m.fraction
        } else {
            back(m.whole)
        };
        let shifted: Vec<_> = (m.history.iter().enumerate())
            .map(|(i, &h)| (h, back(i)))
            .collect();
        self.next.extend(shifted);
        reading
    }

    /// The position loop's speed command (zero for the velocity loop alone).
    fn command(&mut self, m: &Memories, reading: &Expr) -> Expr {
        if !m.cascade {
            return Expr::zeros(self.n + 1);
        }
        let error = match self.c.loop_mode {
            LoopMode::SemiClosed => -reading.clone(),
            LoopMode::FullClosed => -self.unit(self.plant.table) / self.plant.ratio,
        };
        let now = match m.position_integral {
            Some(i) => {
                let integral = self.unit(i) + &error * self.c.tc;
                self.next.push((i, integral.clone()));
                &error * self.c.kpp + integral * self.c.kpi
            }
            None => error * self.c.kpp,
        };
        self.held_average(now, &m.held)
    }

    /// The speed controller's PI on `speed_error`, then the setpoint filters.
    fn speed_law(&mut self, m: &Memories, speed_error: Expr) -> Expr {
        let mut law = &speed_error * self.c.kvp;
        if let Some(i) = m.speed_integral {
            let integral = self.unit(i) + &speed_error * self.c.tc;
            self.next.push((i, integral.clone()));
            law += integral * self.c.kvi;
        }
        for (s, z) in m.sections.iter().zip(&m.filter_states) {
            let (b, a) = s.coefficients();
            let out = &law * b[0] + self.unit(z[0]);
            let first = &law * b[1] - &out * a[0] + self.unit(z[1]);
            self.next.push((z[0], first));
            self.next.push((z[1], &law * b[2] - &out * a[1]));
            law = out;
        }
        law
    }

    /// The law as the current loop applies it: a period's output delay, the
    /// current loop's first-order lag.
    fn applied(&mut self, m: &Memories, law: Expr) -> Expr {
        let applied = match m.pending {
            Some(i) => {
                self.next.push((i, law));
                self.unit(i)
            }
            None => law,
        };
        match m.lag {
            Some(i) => {
                let a = -(-self.c.tc / self.c.current_lag_s).exp_m1();
                let lagged = self.unit(i) * (1.0 - a) + applied * a;
                self.next.push((i, lagged.clone()));
                lagged
            }
            None => applied,
        }
    }

    /// The position loop's output `now` as the velocity loop sees it when the
    /// position controller runs every N-th sample (N − 1 = `held.len()` memories of
    /// its past outputs): the sample-and-hold's baseband response, the mean of the
    /// last N outputs (its images at the position cycle's rate neglected: docs/
    /// tuning.md, "The position controller's cycle"); `now` itself for N = 1.
    fn held_average(&mut self, now: Expr, held: &[usize]) -> Expr {
        if held.is_empty() {
            return now;
        }
        let n = (held.len() + 1) as f64;
        let mut sum = now.clone();
        for (i, &h) in held.iter().enumerate() {
            sum += self.unit(h);
            let previous = if i == 0 {
                now.clone()
            } else {
                self.unit(held[i - 1])
            };
            self.next.push((h, previous));
        }
        sum / n
    }

    /// A, B and C from the next-state expressions and the output's.
    fn matrices(self, output: Expr) -> SampledLoop {
        let n = self.n;
        let mut a = DMatrix::zeros(n, n);
        let mut b = DVector::zeros(n);
        for (i, e) in &self.next {
            a.row_mut(*i).copy_from(&e.rows(0, n).transpose());
            b[*i] = e[n];
        }
        debug_assert_eq!(output[n], 0.0, "the output does not feed through");
        SampledLoop {
            a,
            b,
            c: output.rows(0, n).transpose(),
            tc: self.c.tc,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;
    use crate::tuning::open_loop::{VelocityLoop, VelocityPi};

    /// Below Nyquist the exact sampled velocity loop is the quasi-continuous one of
    /// `open_loop` but for the plant's aliased images: within a few 0.1 % at 100 Hz
    /// on the worm gear (its compliance falls as 1/ω² above its resonances).
    #[test]
    fn the_exact_velocity_loop_is_the_quasi_continuous_one_below_nyquist() {
        for name in ["worm-gear", "two-mass", "direct-drive"] {
            let p = presets::load(name).unwrap();
            let plant = DiscretePlant::new(&p).unwrap();
            let exact = SampledLoop::new(&plant, &p.controller, Closure::Velocity);
            let quasi = VelocityLoop::new(&p, &p.controller.filters).unwrap();
            let pi = VelocityPi {
                kvp: p.controller.kvp,
                kvi: p.controller.kvi,
            };
            for hz in [1.0, 10.0, 100.0] {
                let (e, q) = (exact.at(hz).unwrap(), quasi.at(pi, hz).unwrap());
                assert!((e / q - 1.0).norm() < 5e-3, "{name} {hz} Hz: {e} vs {q}");
            }
        }
    }

    /// The cascade of the semi-closed loop is the velocity loop times
    /// 1 + Kpp·Tc/(1 − z⁻¹): the position error's path through the same reading.
    #[test]
    fn the_semi_closed_cascade_adds_the_position_path() {
        let p = presets::load("worm-gear").unwrap();
        let plant = DiscretePlant::new(&p).unwrap();
        let v = SampledLoop::new(&plant, &p.controller, Closure::Velocity);
        let c = SampledLoop::new(&plant, &p.controller, Closure::Cascade);
        for hz in [0.5, 7.0, 150.0, 1500.0] {
            let z_inv = Complex::new(0.0, -TAU * hz * p.controller.tc).exp();
            let expected =
                v.at(hz).unwrap() * (1.0 + p.controller.kpp * p.controller.tc / (1.0 - z_inv));
            let got = c.at(hz).unwrap();
            assert!(
                (got / expected - 1.0).norm() < 1e-9,
                "{hz}: {got} vs {expected}"
            );
        }
    }

    /// The preset's loop is stable and a gain 100 times larger is not.
    #[test]
    fn the_closed_loops_poles_decide_stability() {
        let p = presets::load("worm-gear").unwrap();
        let plant = DiscretePlant::new(&p).unwrap();
        let c = SampledLoop::new(&plant, &p.controller, Closure::Cascade);
        assert!(c.spectral_radius(1.0).unwrap() < 1.0);
        assert!(c.spectral_radius(100.0).unwrap() > 1.0);
    }
}
