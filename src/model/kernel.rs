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
//! Friction is the stick/slip clamp of friction.rs. The step allocates nothing: the
//! stage derivatives live in the [`Kernel`], which the caller owns and reuses.

use super::backlash::mesh_torque;
use super::drive::{idx::*, Drive, NSTATE};
use super::friction::{net_torque, stop_at_reversal};

/// The state of `L` lanes: `y[i][l]` is state `i` (see [`idx`](super::drive::idx)) of lane `l`.
pub type States<const L: usize> = [[f64; L]; NSTATE];

/// Integrator scratch and the per-step stick decisions of motor, shaft and table.
#[derive(Clone, Debug)]
pub struct Kernel<const L: usize> {
    k: [States<L>; 4],
    tmp: States<L>,
    stuck: [[bool; L]; 3],
}

impl<const L: usize> Default for Kernel<L> {
    fn default() -> Self {
        Kernel {
            k: [[[0.0; L]; NSTATE]; 4],
            tmp: [[0.0; L]; NSTATE],
            stuck: [[false; L]; 3],
        }
    }
}

impl<const L: usize> Kernel<L> {
    /// Advances every lane of `y` by one RK4 step of length `h`.
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
            self.step_impl::<true>(d, y, motor, load, h);
        } else {
            self.step_impl::<false>(d, y, motor, load, h);
        }
    }

    /// Whether motor, shaft and table of lane `l` were stuck during the last step.
    pub fn stuck(&self, l: usize) -> [bool; 3] {
        [self.stuck[0][l], self.stuck[1][l], self.stuck[2][l]]
    }

    #[inline(always)]
    fn step_impl<const SPUR: bool>(
        &mut self,
        d: &Drive,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        let y0 = *y;
        let half = 0.5 * h;
        derivative::<L, SPUR>(
            d,
            &y0,
            &motor[0],
            load,
            &mut self.stuck,
            true,
            &mut self.k[0],
        );
        axpy(&mut self.tmp, &y0, half, &self.k[0]);
        derivative::<L, SPUR>(
            d,
            &self.tmp,
            &motor[1],
            load,
            &mut self.stuck,
            false,
            &mut self.k[1],
        );
        axpy(&mut self.tmp, &y0, half, &self.k[1]);
        derivative::<L, SPUR>(
            d,
            &self.tmp,
            &motor[1],
            load,
            &mut self.stuck,
            false,
            &mut self.k[2],
        );
        axpy(&mut self.tmp, &y0, h, &self.k[2]);
        derivative::<L, SPUR>(
            d,
            &self.tmp,
            &motor[2],
            load,
            &mut self.stuck,
            false,
            &mut self.k[3],
        );
        let sixth = h / 6.0;
        let [k1, k2, k3, k4] = &self.k;
        for i in 0..NSTATE {
            for l in 0..L {
                y[i][l] = y0[i][l] + sixth * (k1[i][l] + 2.0 * (k2[i][l] + k3[i][l]) + k4[i][l]);
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

/// `out = y + a·k`, lane-wise.
#[inline(always)]
fn axpy<const L: usize>(out: &mut States<L>, y: &States<L>, a: f64, k: &States<L>) {
    for i in 0..NSTATE {
        for l in 0..L {
            out[i][l] = y[i][l] + a * k[i][l];
        }
    }
}

/// The right-hand side of the equations of motion for every lane. With `decide`,
/// each body's stick state is decided from the torques at `y` (first RK stage).
#[inline(always)]
fn derivative<const L: usize, const SPUR: bool>(
    d: &Drive,
    y: &States<L>,
    motor: &[f64; L],
    load: &[f64; L],
    stuck: &mut [[bool; L]; 3],
    decide: bool,
    out: &mut States<L>,
) {
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
        let (e, ep) = d.fluctuation(shaft);
        let lever = d.rw + ep;
        let dw = d.rw * shaft + e + xw * d.inv_r - tt;
        let dw_rate = lever * ws + vw * d.inv_r - wt;
        let tw = mesh_torque(d.kw, d.ciw, d.bw, dw, dw_rate);

        let unbalance = if d.unbalance {
            -d.mge * (tt + d.psi).sin()
        } else {
            0.0
        };
        let table = tw - d.ct * wt + unbalance + load[l];
        let at = net_torque(table, wt, d.fc[2], &mut stuck[2][l], decide) * d.inv_jt;
        let ax = (-d.cb * vw - d.kb * xw - tw * d.inv_r) * d.inv_mw;

        let am = if SPUR {
            let dg = d.rg * y[THETA_M][l] - shaft;
            let dg_rate = d.rg * wm - ws;
            let tg = mesh_torque(d.kg, d.cig, d.bg, dg, dg_rate);
            let m = motor[l] - d.cm * wm - d.rg * tg;
            let s = tg - d.cw * ws - lever * tw;
            out[OMEGA_W][l] = net_torque(s, ws, d.fc[1], &mut stuck[1][l], decide) * d.inv_jw;
            out[THETA_W][l] = ws;
            net_torque(m, wm, d.fc[0], &mut stuck[0][l], decide) * d.inv_jm
        } else {
            let m = motor[l] - d.cm * wm - lever * tw;
            let a = net_torque(m, wm, d.fc[0], &mut stuck[0][l], decide) * d.inv_jm;
            out[OMEGA_W][l] = a;
            out[THETA_W][l] = wm;
            a
        };
        out[THETA_M][l] = wm;
        out[OMEGA_M][l] = am;
        out[X_W][l] = vw;
        out[V_W][l] = ax;
        out[THETA_T][l] = wt;
        out[OMEGA_T][l] = at;
    }
}
