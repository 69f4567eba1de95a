//! The motor torques of `L` lanes of sines, advanced lane-wise exactly as
//! [`Sine`] advances one.

use crate::input::Sine;
use crate::model::lanes::Lanes;

/// The motor torques `offset + amplitude·sin(ωt)` of `L` lanes, each exactly as
/// [`Sine::step_torques`] computes them for its own clock `t` = steps·dt (the same
/// rotations of (sin, cos) by half steps, the same resynchronisation every
/// [`Sine::RESYNC`] steps or on a clock jump), but advanced lane-wise.
pub(super) struct Sines<const L: usize> {
    dt: f64,
    amplitude: [f64; L],
    offset: [f64; L],
    omega: [f64; L],
    /// sin, cos of ω·t at the next step start, and of ω·dt/2.
    sin: [f64; L],
    cos: [f64; L],
    half_sin: [f64; L],
    half_cos: [f64; L],
    /// Steps taken (the lane's clock is steps·dt), and steps left before the next
    /// resynchronisation (0: now).
    steps: [f64; L],
    count: [u32; L],
    next_t: [f64; L],
}

impl<const L: usize> Sines<L> {
    /// Zero torque in every lane.
    pub(super) fn new(dt: f64) -> Self {
        Sines {
            dt,
            amplitude: [0.0; L],
            offset: [0.0; L],
            omega: [0.0; L],
            sin: [0.0; L],
            cos: [1.0; L],
            half_sin: [0.0; L],
            half_cos: [1.0; L],
            steps: [0.0; L],
            count: [u32::MAX; L],
            next_t: [0.0; L],
        }
    }

    /// Lane `l` starts `input`'s sine at t = 0 (a fresh [`Sine`]).
    pub(super) fn start(&mut self, l: usize, frequency_hz: f64, amplitude_nm: f64, offset_nm: f64) {
        self.amplitude[l] = amplitude_nm;
        self.offset[l] = offset_nm;
        self.omega[l] = std::f64::consts::TAU * frequency_hz;
        (self.half_sin[l], self.half_cos[l]) = (0.5 * self.omega[l] * self.dt).sin_cos();
        self.steps[l] = 0.0;
        self.count[l] = 0;
        self.next_t[l] = f64::NAN;
    }

    /// Lane `l` applies no torque.
    pub(super) fn stop(&mut self, l: usize) {
        (self.amplitude[l], self.offset[l]) = (0.0, 0.0);
        self.count[l] = u32::MAX;
    }

    /// The torques of every lane at the start, middle and end of the next step.
    #[inline]
    pub(super) fn step_torques(&mut self) -> [[f64; L]; 3] {
        let h = self.dt;
        let t = Lanes(self.steps) * h;
        let jump = t.zip(Lanes(self.next_t), |t, n| {
            if (t - n).abs() > 1e-6 * h {
                1.0
            } else {
                0.0
            }
        });
        let mut resync = jump.any(|j| j != 0.0);
        for c in &mut self.count {
            resync |= *c == 0;
        }
        if resync {
            self.resync(t, jump);
        }
        for c in &mut self.count {
            *c = c.wrapping_sub(1);
        }
        let rotate = |s: Lanes<L>, c: Lanes<L>| {
            let (sh, ch) = (Lanes(self.half_sin), Lanes(self.half_cos));
            (s * ch + c * sh, c * ch - s * sh)
        };
        let (s0, c0) = (Lanes(self.sin), Lanes(self.cos));
        let (s1, c1) = rotate(s0, c0);
        let (s2, c2) = rotate(s1, c1);
        let (a, o) = (Lanes(self.amplitude), Lanes(self.offset));
        self.sin = s2.0;
        self.cos = c2.0;
        self.next_t = (t + h).0;
        self.steps = (Lanes(self.steps) + 1.0).0;
        [s0, s1, s2].map(|s| (o + a * s).0)
    }

    #[cold]
    #[inline(never)]
    fn resync(&mut self, t: Lanes<L>, jump: Lanes<L>) {
        for l in 0..L {
            if self.count[l] == 0 || jump.0[l] != 0.0 {
                (self.sin[l], self.cos[l]) = (self.omega[l] * t.0[l]).sin_cos();
                self.count[l] = Sine::RESYNC;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_of_sines_equal_lone_sines() {
        use crate::input::TorqueInput;
        let dt = 1e-5;
        let mut lanes = Sines::<4>::new(dt);
        let mut lone: Vec<(Sine, u64)> = Vec::new();
        for (l, f) in [10.0, 230.0, 599.0, 47.5].into_iter().enumerate() {
            lanes.start(l, f, 5.0, 0.1 * l as f64);
            lone.push((Sine::new(f, 5.0, 0.1 * l as f64), 0));
        }
        for k in 0..20_000 {
            if k == 7_000 {
                // Lane 2 restarts with another frequency, out of step with the rest.
                lanes.start(2, 321.0, 3.0, -1.0);
                lone[2] = (Sine::new(321.0, 3.0, -1.0), 0);
            }
            let m = lanes.step_torques();
            for (l, (sine, steps)) in lone.iter_mut().enumerate() {
                let expected = sine.step_torques(*steps as f64 * dt, dt);
                *steps += 1;
                assert_eq!([m[0][l], m[1][l], m[2][l]], expected, "lane {l}, step {k}");
            }
        }
    }
}
