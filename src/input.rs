//! What drives a simulation: open-loop motor torques ([`TorqueInput`]) and commanded
//! table trajectories for the controller ([`Trajectory`]).

use std::f64::consts::TAU;

/// An open-loop motor torque. RK4 needs it at the start, middle and end of each step.
pub trait TorqueInput {
    /// Torques at `t`, `t + h/2` and `t + h`, N·m.
    fn step_torques(&mut self, t: f64, h: f64) -> [f64; 3];
}

/// No torque: the free response from the initial state.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoTorque;

impl TorqueInput for NoTorque {
    fn step_torques(&mut self, _t: f64, _h: f64) -> [f64; 3] {
        [0.0; 3]
    }
}

/// `offset + amplitude·sin(2π·f·t)`. The sine is advanced by exact rotations of its
/// (sin, cos) pair and recomputed from `t` every [`Sine::RESYNC`] steps, so a step
/// costs a few multiplications instead of three `sin` calls.
#[derive(Clone, Debug)]
pub struct Sine {
    amplitude: f64,
    offset: f64,
    omega: f64,
    /// sin, cos of ω·t at the next expected step start.
    sc: (f64, f64),
    /// sin, cos of ω·h/2 for the step length last used.
    half: (f64, f64),
    h: f64,
    next_t: f64,
    count: u32,
}

impl Sine {
    /// Steps between exact recomputations of the phase.
    pub const RESYNC: u32 = 4096;

    /// A sine of `amplitude_nm` at `frequency_hz` around `offset_nm`.
    pub fn new(frequency_hz: f64, amplitude_nm: f64, offset_nm: f64) -> Self {
        Sine {
            amplitude: amplitude_nm,
            offset: offset_nm,
            omega: TAU * frequency_hz,
            sc: (0.0, 1.0),
            half: (0.0, 1.0),
            h: f64::NAN,
            next_t: f64::NAN,
            count: 0,
        }
    }

    /// The torque at time `t`.
    pub fn at(&self, t: f64) -> f64 {
        self.offset + self.amplitude * (self.omega * t).sin()
    }
}

#[inline(always)]
fn rotate((s, c): (f64, f64), (sh, ch): (f64, f64)) -> (f64, f64) {
    (s * ch + c * sh, c * ch - s * sh)
}

impl TorqueInput for Sine {
    fn step_torques(&mut self, t: f64, h: f64) -> [f64; 3] {
        if h != self.h {
            self.h = h;
            self.half = (0.5 * self.omega * h).sin_cos();
            self.count = 0;
        }
        // Resynchronise periodically, and whenever the caller's clock jumps (its
        // time is steps·h, which differs from the running t + h only by rounding).
        if self.count == 0 || (t - self.next_t).abs() > 1e-6 * h {
            self.sc = (self.omega * t).sin_cos();
            self.count = Self::RESYNC;
        }
        self.count -= 1;
        let mid = rotate(self.sc, self.half);
        let end = rotate(mid, self.half);
        let out = [self.sc.0, mid.0, end.0].map(|s| self.offset + self.amplitude * s);
        self.sc = end;
        self.next_t = t + h;
        out
    }
}

/// A torque step of `torque_nm` at `at_s`.
#[derive(Clone, Copy, Debug)]
pub struct Step {
    pub torque_nm: f64,
    pub at_s: f64,
}

impl TorqueInput for Step {
    fn step_torques(&mut self, t: f64, h: f64) -> [f64; 3] {
        [t, t + 0.5 * h, t + h].map(|ti| if ti >= self.at_s { self.torque_nm } else { 0.0 })
    }
}

/// A recorded torque signal, linearly interpolated and held beyond its ends.
#[derive(Clone, Debug)]
pub struct Samples {
    time: Vec<f64>,
    torque: Vec<f64>,
    cursor: usize,
}

impl Samples {
    /// From strictly increasing times (s) and torques (N·m) of equal, non-zero length.
    pub fn new(time: Vec<f64>, torque: Vec<f64>) -> Self {
        assert!(!time.is_empty() && time.len() == torque.len());
        Samples {
            time,
            torque,
            cursor: 0,
        }
    }

    fn at(&mut self, t: f64) -> f64 {
        let n = self.time.len();
        if t <= self.time[0] {
            return self.torque[0];
        }
        if t >= self.time[n - 1] {
            return self.torque[n - 1];
        }
        if self.time[self.cursor] > t {
            self.cursor = 0;
        }
        while self.time[self.cursor + 1] < t {
            self.cursor += 1;
        }
        let (i, j) = (self.cursor, self.cursor + 1);
        let f = (t - self.time[i]) / (self.time[j] - self.time[i]);
        self.torque[i] + f * (self.torque[j] - self.torque[i])
    }
}

impl TorqueInput for Samples {
    fn step_torques(&mut self, t: f64, h: f64) -> [f64; 3] {
        [self.at(t), self.at(t + 0.5 * h), self.at(t + h)]
    }
}

/// A commanded table angle over time (rad), the controller's reference.
pub trait Trajectory {
    /// The commanded table angle at `t`, rad.
    fn angle(&self, t: f64) -> f64;
}

impl<F: Fn(f64) -> f64> Trajectory for F {
    fn angle(&self, t: f64) -> f64 {
        self(t)
    }
}

/// A move from `from` to `to` (rad): a step at t = 0 when `speed` is `None`, else a
/// ramp at `speed` rad/s of table angle.
#[derive(Clone, Copy, Debug)]
pub struct Move {
    pub from: f64,
    pub to: f64,
    pub speed: Option<f64>,
}

impl Trajectory for Move {
    fn angle(&self, t: f64) -> f64 {
        match self.speed {
            None => self.to,
            Some(v) => {
                let travel = (v * t).min((self.to - self.from).abs());
                self.from + travel.copysign(self.to - self.from)
            }
        }
    }
}

/// A harmonic motion `amplitude·sin(2π·t/period)` (rad), the torque-curve test's.
#[derive(Clone, Copy, Debug)]
pub struct Harmonic {
    pub amplitude: f64,
    pub period: f64,
}

impl Trajectory for Harmonic {
    fn angle(&self, t: f64) -> f64 {
        self.amplitude * (TAU * t / self.period).sin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotated_sine_stays_on_the_exact_one() {
        let mut s = Sine::new(137.0, 5.0, 0.3);
        let h = 1e-5;
        let mut worst: f64 = 0.0;
        for k in 0..50_000 {
            let t = k as f64 * h;
            let got = s.step_torques(t, h);
            for (i, dt) in [0.0, 0.5 * h, h].iter().enumerate() {
                worst = worst.max((got[i] - s.at(t + dt)).abs());
            }
        }
        assert!(worst < 1e-11, "{worst}");
    }

    #[test]
    fn samples_interpolate_and_hold() {
        let mut s = Samples::new(vec![0.0, 1.0, 2.0], vec![0.0, 2.0, 0.0]);
        assert_eq!(s.step_torques(0.5, 1.0), [1.0, 2.0, 1.0]);
        assert_eq!(s.step_torques(-1.0, 0.5), [0.0, 0.0, 0.0]);
        assert_eq!(s.step_torques(3.0, 1.0), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn ramp_reaches_and_holds_the_target() {
        let m = Move {
            from: 1.0,
            to: 0.0,
            speed: Some(0.5),
        };
        assert_eq!(m.angle(1.0), 0.5);
        assert_eq!(m.angle(5.0), 0.0);
    }
}
