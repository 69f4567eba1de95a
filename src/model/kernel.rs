//! The simulation kernel: the equations of motion of MODEL.md §2 and a classical
//! fourth-order Runge–Kutta step, for `L` independent trajectories advanced in
//! lockstep ("lanes", structure of arrays: state `i` of lane `l` is `y[i][l]`).
//! `L = 1` is one trajectory; wider lanes let the compiler vectorise independent
//! simulations (e.g. the frequencies of a frequency-response sweep).
//!
//! Equations as implemented (SI units; the shaft slots mirror the motor in the
//! direct topology, where Rg = 1 and there is no spur mesh):
//!
//! ```text
//! δg = Rg·θm − θw                 δg' = Rg·ωm − ωw
//! δw = Rw·θw + e(θw) + xw/r − θt   δw' = (Rw + e'(θw))·ωw + vw/r − ωt
//! e(θ) = W·sin(N·θ + φ)            e'(θ) = W·N·cos(N·θ + φ)
//! Tg = mesh(Kg, Cig, θbg, δg, δg')  Tw = mesh(Kw, Ciw, θbw, δw, δw')   (backlash.rs)
//! Jm·ωm' = Tm − Cm·ωm − Rg·Tg − friction_m
//! Jw·ωw' = Tg − Cw·ωw − (Rw + e')·Tw − friction_w
//! Mw·vw' = −Cb·vw − Kb·xw − Tw/r
//! Jt·ωt' = Tw − Ct·ωt − m·g·e·sin(θt + ψ) + Tload − friction_t
//! ```
//!
//! Friction is the stick/slip clamp of friction.rs.
//!
//! **Contact events.** A mesh entering or leaving contact puts a kink into the
//! equations; RK4 stepping across it drops to second order (measured: the energy of
//! the undamped worm with backlash drifts 1.2e-3 over 1 s at dt = 1e-5 s). So a step
//! in which any mesh of a lane changes contact is split at the crossing: the twist
//! is interpolated over the step by the cubic Hermite polynomial of its values and
//! rates at both ends, its crossing of the gap edge located by bisection, and the
//! lane re-integrated from the step's start to the crossing and from there to the
//! step's end (lanes without an event keep their full step). Inputs inside the step
//! come from the quadratic through the three given values (exact for the held
//! torque of the controller).
//!
//! **Fluctuation.** sin/cos of N·θw + φ is carried from step start to step start
//! by small rotations (computed afresh every 1024 steps, drive.rs); later stages
//! use the cubic Taylor polynomial of e about the step start.
//!
//! The step allocates nothing: stage derivatives and step-start values live in the
//! [`Kernel`], which the caller owns and reuses.

use super::backlash::mesh_torque;
use super::drive::{idx::*, Drive, NSTATE};
use super::friction::{stop_at_reversal, Friction};

/// The state of `L` lanes: `y[i][l]` is state `i` (see [`idx`](super::drive::idx)) of lane `l`.
pub type States<const L: usize> = [[f64; L]; NSTATE];

/// Values at the start of the current (sub)step, per lane, computed by the first
/// stage and used by the later stages and the event check.
#[derive(Clone, Copy, Debug)]
struct StepStart<const L: usize> {
    /// Shaft angle, and sin, cos of the fluctuation phase there.
    shaft: [f64; L],
    sin: [f64; L],
    cos: [f64; L],
    /// Steps left before the phase is computed afresh (0: compute now).
    fresh: [u32; L],
    /// Taylor coefficients of e(θ0 + Δ) = e0 + e1·Δ + e2·Δ²/2 + e3·Δ³/6 at the
    /// step start: [e0, e1, e2/2, e3/6, e2, e3/2].
    taylor: [[f64; L]; 6],
    /// Twist and twist rate of the spur mesh (0) and the drive mesh (1).
    twist: [[f64; L]; 2],
    rate: [[f64; L]; 2],
}

/// The per-step stick decisions of motor, shaft and table.
#[derive(Clone, Debug)]
pub struct Kernel<const L: usize> {
    friction: [[Friction; L]; 3],
    start: StepStart<L>,
    /// Number of steps split at a contact event (all lanes), for diagnostics.
    events: u64,
}

impl<const L: usize> Default for Kernel<L> {
    fn default() -> Self {
        Kernel {
            friction: [[Friction::default(); L]; 3],
            start: StepStart {
                shaft: [0.0; L],
                sin: [0.0; L],
                cos: [1.0; L],
                fresh: [0; L],
                taylor: [[0.0; L]; 6],
                twist: [[0.0; L]; 2],
                rate: [[0.0; L]; 2],
            },
            events: 0,
        }
    }
}

impl<const L: usize> Kernel<L> {
    /// Advances every lane of `y` by one step of length `h`.
    ///
    /// `motor[s][l]` is lane `l`'s motor torque at the step's start (`s = 0`), middle
    /// (`s = 1`) and end (`s = 2`); `load[l]` the external table torque, held over the
    /// step.
    #[inline]
    pub fn step(
        &mut self,
        d: &Drive,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        if d.spur {
            self.step_with_events::<true>(d, y, motor, load, h);
        } else {
            self.step_with_events::<false>(d, y, motor, load, h);
        }
    }

    /// Whether motor, shaft and table of lane `l` were stuck during the last step.
    pub fn stuck(&self, l: usize) -> [bool; 3] {
        [0, 1, 2].map(|b| self.friction[b][l].stuck())
    }

    /// Lane-steps split at a contact event so far.
    pub fn events(&self) -> u64 {
        self.events
    }

    #[inline(always)]
    fn step_with_events<const SPUR: bool>(
        &mut self,
        d: &Drive,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        let y0 = *y;
        self.rk4::<SPUR>(d, y, motor, load, &[h; L]);
        if !(d.bw > 0.0 || (SPUR && d.bg > 0.0)) {
            return;
        }
        let mut any = false;
        let split: [f64; L] = std::array::from_fn(|l| {
            let event = self.contact_event::<SPUR>(d, y, l, h);
            any |= event.is_some();
            event.unwrap_or(1.0)
        });
        if any {
            self.split_step::<SPUR>(d, &y0, y, motor, load, h, &split);
        }
    }

    /// Re-integrates the lanes with an event at fraction `split[l]` of the step in
    /// two pieces; the others keep the full step already in `y`.
    #[cold]
    #[allow(clippy::too_many_arguments)]
    fn split_step<const SPUR: bool>(
        &mut self,
        d: &Drive,
        y0: &States<L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
        split: &[f64; L],
    ) {
        let mut part = *y0;
        let mut first = [0.0; L];
        let mut second = [0.0; L];
        let mut m1 = [[0.0; L]; 3];
        let mut m2 = [[0.0; L]; 3];
        for l in 0..L {
            let s = split[l];
            if s < 1.0 {
                self.events += 1;
                first[l] = s * h;
                second[l] = (1.0 - s) * h;
            }
            let m = [motor[0][l], motor[1][l], motor[2][l]];
            for (j, &at) in [0.0, 0.5 * s, s].iter().enumerate() {
                m1[j][l] = quadratic(&m, at);
            }
            for (j, &at) in [s, 0.5 * (1.0 + s), 1.0].iter().enumerate() {
                m2[j][l] = quadratic(&m, at);
            }
        }
        self.rk4::<SPUR>(d, &mut part, &m1, load, &first);
        self.rk4::<SPUR>(d, &mut part, &m2, load, &second);
        for l in 0..L {
            if split[l] < 1.0 {
                for i in 0..NSTATE {
                    y[i][l] = part[i][l];
                }
            }
        }
    }

    /// The earliest fraction of the last step at which a mesh of lane `l` entered or
    /// left contact, if one did. `y` is the state at the step's end.
    #[inline(always)]
    fn contact_event<const SPUR: bool>(
        &self,
        d: &Drive,
        y: &States<L>,
        l: usize,
        h: f64,
    ) -> Option<f64> {
        let st = &self.start;
        let (shaft, ws) = if SPUR {
            (y[THETA_W][l], y[OMEGA_W][l])
        } else {
            (y[THETA_M][l], y[OMEGA_M][l])
        };
        let mut earliest: Option<f64> = None;
        let mut check = |mesh: usize, b: f64, twist: f64, rate: f64| {
            let (t0, r0) = (st.twist[mesh][l], st.rate[mesh][l]);
            let (g0, g1) = (region(t0, b), region(twist, b));
            if g0 == g1 {
                return;
            }
            let edge = b * if g0 != 0.0 { g0 } else { g1 };
            if t0 == edge {
                return;
            }
            let s = hermite_crossing(t0 - edge, h * r0, twist - edge, h * rate);
            earliest = Some(earliest.map_or(s, |e: f64| e.min(s)));
        };
        if SPUR && d.bg > 0.0 {
            check(
                0,
                d.bg,
                d.rg * y[THETA_M][l] - shaft,
                d.rg * y[OMEGA_M][l] - ws,
            );
        }
        if d.bw > 0.0 {
            let (e, ep) = if d.fluct {
                d.fluctuation_near(shaft, st.shaft[l], (st.sin[l], st.cos[l]))
            } else {
                (0.0, 0.0)
            };
            check(
                1,
                d.bw,
                d.rw * shaft + e + y[X_W][l] * d.inv_r - y[THETA_T][l],
                (d.rw + ep) * ws + y[V_W][l] * d.inv_r - y[OMEGA_T][l],
            );
        }
        earliest.filter(|&s| s > 0.0 && s < 1.0)
    }

    /// One classical RK4 step of length `h[l]` for each lane (0 leaves a lane as is).
    /// Stage values are locals, not fields, so the compiler can keep them in
    /// registers: the step is a chain of dependent stages, bound by latency.
    #[inline(always)]
    fn rk4<const SPUR: bool>(
        &mut self,
        d: &Drive,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: &[f64; L],
    ) {
        let y0 = *y;
        let half = h.map(|h| 0.5 * h);
        let friction = &mut self.friction;
        let st = &mut self.start;
        let k1 = derivative::<L, SPUR, true>(d, &y0, &motor[0], load, friction, st);
        let k2 =
            derivative::<L, SPUR, false>(d, &axpy(&y0, &half, &k1), &motor[1], load, friction, st);
        let k3 =
            derivative::<L, SPUR, false>(d, &axpy(&y0, &half, &k2), &motor[1], load, friction, st);
        let k4 = derivative::<L, SPUR, false>(d, &axpy(&y0, h, &k3), &motor[2], load, friction, st);
        let sixth = h.map(|h| h * (1.0 / 6.0));
        for i in 0..NSTATE {
            for l in 0..L {
                y[i][l] = y0[i][l] + sixth[l] * (k1[i][l] + 2.0 * (k2[i][l] + k3[i][l]) + k4[i][l]);
            }
        }
        for l in 0..L {
            stop_at_reversal(y0[OMEGA_M][l], &mut y[OMEGA_M][l], d.fc[0]);
            if SPUR {
                stop_at_reversal(y0[OMEGA_W][l], &mut y[OMEGA_W][l], d.fc[1]);
            } else {
                y[THETA_W][l] = y[THETA_M][l];
                y[OMEGA_W][l] = y[OMEGA_M][l];
            }
            stop_at_reversal(y0[OMEGA_T][l], &mut y[OMEGA_T][l], d.fc[2]);
        }
    }
}

/// -1 below the gap, 0 inside it (no contact), +1 above it.
#[inline(always)]
fn region(twist: f64, b: f64) -> f64 {
    if twist > b {
        1.0
    } else if twist < -b {
        -1.0
    } else {
        0.0
    }
}

/// The root in (0, 1) of the cubic Hermite polynomial with values `f0`, `f1` and
/// slopes (per unit fraction) `m0`, `m1` at 0 and 1; `f0` and `f1` differ in sign.
fn hermite_crossing(f0: f64, m0: f64, f1: f64, m1: f64) -> f64 {
    let p = |s: f64| {
        let s2 = s * s;
        let s3 = s2 * s;
        (2.0 * s3 - 3.0 * s2 + 1.0) * f0
            + (s3 - 2.0 * s2 + s) * m0
            + (-2.0 * s3 + 3.0 * s2) * f1
            + (s3 - s2) * m1
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    let positive_at_lo = f0 > 0.0;
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if (p(mid) > 0.0) == positive_at_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The quadratic through `m` at fractions 0, ½, 1 of a step, evaluated at `s`.
#[inline(always)]
fn quadratic(m: &[f64; 3], s: f64) -> f64 {
    let [a, b, c] = *m;
    a + s * (-3.0 * a + 4.0 * b - c) + s * s * (2.0 * a - 4.0 * b + 2.0 * c)
}

/// Tu = −m·g·e·sin(θt + ψ). Out of line on purpose: inlined, the compiler may
/// evaluate the `sin` for every stage and discard it when there is no unbalance.
#[inline(never)]
fn unbalance_torque(d: &Drive, table_angle: f64) -> f64 {
    -d.mge * (table_angle + d.psi).sin()
}

/// `y + a·k`, lane-wise.
#[inline(always)]
fn axpy<const L: usize>(y: &States<L>, a: &[f64; L], k: &States<L>) -> States<L> {
    let mut out = *y;
    for i in 0..NSTATE {
        for l in 0..L {
            out[i][l] += a[l] * k[i][l];
        }
    }
    out
}

/// The right-hand side of the equations of motion for every lane. With `first`
/// (a step's first stage), each body's stick state is decided from the torques at
/// `y`, and the step-start values are stored in `st` for the later stages.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn derivative<const L: usize, const SPUR: bool, const FIRST: bool>(
    d: &Drive,
    y: &States<L>,
    motor: &[f64; L],
    load: &[f64; L],
    friction: &mut [[Friction; L]; 3],
    st: &mut StepStart<L>,
) -> States<L> {
    let first = FIRST;
    let mut out = [[0.0; L]; NSTATE];
    for l in 0..L {
        let (wm, xw, vw, tt, wt) = (
            y[OMEGA_M][l],
            y[X_W][l],
            y[V_W][l],
            y[THETA_T][l],
            y[OMEGA_T][l],
        );
        let (shaft, ws) = if SPUR {
            (y[THETA_W][l], y[OMEGA_W][l])
        } else {
            (y[THETA_M][l], wm)
        };
        let (e, ep) = if !d.fluct {
            (0.0, 0.0)
        } else if first {
            let (s, c) =
                d.fluctuation_phase(shaft, st.shaft[l], (st.sin[l], st.cos[l]), &mut st.fresh[l]);
            st.shaft[l] = shaft;
            st.sin[l] = s;
            st.cos[l] = c;
            let (e0, e1) = (d.w * s, d.w * d.n * c);
            let (e2, e3) = (-d.n * d.n * e0, -d.n * d.n * e1);
            st.taylor[0][l] = e0;
            st.taylor[1][l] = e1;
            st.taylor[2][l] = 0.5 * e2;
            st.taylor[3][l] = e3 * (1.0 / 6.0);
            st.taylor[4][l] = e2;
            st.taylor[5][l] = 0.5 * e3;
            (e0, e1)
        } else {
            let dx = shaft - st.shaft[l];
            if (d.n * dx).abs() < 0.01 {
                // Cubic Taylor polynomial of e about the step start (error below
                // W·(N·Δθ)⁴/24 < 4e-10·W); its slope is the polynomial's exact
                // derivative, so the mesh energy stays consistent.
                let t = &st.taylor;
                (
                    t[0][l] + dx * (t[1][l] + dx * (t[2][l] + dx * t[3][l])),
                    t[1][l] + dx * (t[4][l] + dx * t[5][l]),
                )
            } else {
                d.fluctuation_near(shaft, st.shaft[l], (st.sin[l], st.cos[l]))
            }
        };
        let lever = d.rw + ep;
        let dw = d.rw * shaft + e + xw * d.inv_r - tt;
        let dw_rate = lever * ws + vw * d.inv_r - wt;
        let tw = mesh_torque(d.kw, d.ciw, d.bw, dw, dw_rate);

        let unbalance = if d.unbalance {
            unbalance_torque(d, tt)
        } else {
            0.0
        };
        let table = tw - d.ct * wt + unbalance + load[l];
        if first {
            friction[2][l] = Friction::decide(table, wt, d.fc[2]);
        }
        let at = friction[2][l].net(table) * d.inv_jt;
        let ax = (-d.cb * vw - d.kb * xw - tw * d.inv_r) * d.inv_mw;

        let am = if SPUR {
            let dg = d.rg * y[THETA_M][l] - shaft;
            let dg_rate = d.rg * wm - ws;
            if first {
                st.twist[0][l] = dg;
                st.rate[0][l] = dg_rate;
            }
            let tg = mesh_torque(d.kg, d.cig, d.bg, dg, dg_rate);
            let m = motor[l] - d.cm * wm - d.rg * tg;
            let s = tg - d.cw * ws - lever * tw;
            if first {
                friction[0][l] = Friction::decide(m, wm, d.fc[0]);
                friction[1][l] = Friction::decide(s, ws, d.fc[1]);
            }
            out[OMEGA_W][l] = friction[1][l].net(s) * d.inv_jw;
            out[THETA_W][l] = ws;
            friction[0][l].net(m) * d.inv_jm
        } else {
            let m = motor[l] - d.cm * wm - lever * tw;
            if first {
                friction[0][l] = Friction::decide(m, wm, d.fc[0]);
            }
            let a = friction[0][l].net(m) * d.inv_jm;
            out[OMEGA_W][l] = a;
            out[THETA_W][l] = wm;
            a
        };
        if first {
            st.twist[1][l] = dw;
            st.rate[1][l] = dw_rate;
        }
        out[THETA_M][l] = wm;
        out[OMEGA_M][l] = am;
        out[X_W][l] = vw;
        out[V_W][l] = ax;
        out[THETA_T][l] = wt;
        out[OMEGA_T][l] = at;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_crossing_finds_the_root_of_a_cubic() {
        // f(s) = s - 0.3 (linear): values -0.3, 0.7, slopes 1.
        let s = hermite_crossing(-0.3, 1.0, 0.7, 1.0);
        assert!((s - 0.3).abs() < 1e-10, "{s}");
        // f(s) = (s - 0.6)^3 + 0.1 (s - 0.6): exactly a cubic, root 0.6.
        let f = |s: f64| (s - 0.6f64).powi(3) + 0.1 * (s - 0.6);
        let df = |s: f64| 3.0 * (s - 0.6f64).powi(2) + 0.1;
        let s = hermite_crossing(f(0.0), df(0.0), f(1.0), df(1.0));
        assert!((s - 0.6).abs() < 1e-10, "{s}");
    }

    #[test]
    fn the_input_quadratic_passes_through_its_three_points() {
        let m = [1.0, 3.0, 2.0];
        assert_eq!(
            [quadratic(&m, 0.0), quadratic(&m, 0.5), quadratic(&m, 1.0)],
            m
        );
    }
}
