//! [`Drive`]: the validated parameters compiled into the constants the kernel reads
//! (inverse inertias, merged bodies of the direct topology, flags for the optional
//! terms). A plain `Copy` struct, built once per simulation.
//!
//! The four topologies share one state layout ([`idx`], 8 slots). The kernel has three
//! forms of the equations ([`Form`]): the spur-gear drive; the drive with the motor on
//! the driving shaft (`direct`, and `two_mass`, which is that form with Rw = 1 and no
//! axial degree of freedom: 1/r = Kb = Cb = 1/Mw = 0, so xw stays 0); and the single
//! rigid body of `direct_drive`.

use super::backlash::{dead_zone, mesh_torque};
use super::friction::DriveFriction;
use super::params::{ParamError, Params, Topology, GRAVITY};

/// Index of each state in the kernel's state vector. Slots a topology does not
/// integrate mirror the ones it does ([`Drive::mirror`]): the shaft follows the motor
/// in the `direct` and `two_mass` topologies (θw ≡ θm), motor and shaft follow the table
/// in `direct_drive` (θm ≡ θw ≡ θt); xw stays 0 without an axial bearing.
pub mod idx {
    /// Motor angle θm, rad.
    pub const THETA_M: usize = 0;
    /// Motor velocity ωm, rad/s.
    pub const OMEGA_M: usize = 1;
    /// Driving-shaft angle θw, rad.
    pub const THETA_W: usize = 2;
    /// Driving-shaft velocity ωw, rad/s.
    pub const OMEGA_W: usize = 3;
    /// Axial displacement of the driving unit xw, m.
    pub const X_W: usize = 4;
    /// Axial velocity vw, m/s.
    pub const V_W: usize = 5;
    /// Table angle θt, rad.
    pub const THETA_T: usize = 6;
    /// Table velocity ωt, rad/s.
    pub const OMEGA_T: usize = 7;
}

/// Number of states.
pub const NSTATE: usize = 8;

/// Which equations the kernel integrates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Form {
    /// Motor, spur mesh, driving shaft, drive mesh, axial bearing, table (`spur_gear`).
    Spur,
    /// Motor with the driving shaft, drive mesh, axial bearing, table (`direct`,
    /// `two_mass`).
    Shaft,
    /// One rigid body: motor and table (`direct_drive`).
    Rigid,
}

/// The model's constants in the form the kernel uses them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    /// Whether a spur-gear stage separates motor and driving shaft (4 DOF).
    pub spur: bool,
    /// The drive train.
    pub topology: Topology,
    /// The equations the kernel integrates.
    pub form: Form,
    pub(crate) inv_jm: f64,
    pub(crate) inv_jw: f64,
    pub(crate) inv_jt: f64,
    pub(crate) inv_mw: f64,
    pub(crate) cm: f64,
    pub(crate) cw: f64,
    pub(crate) cb: f64,
    pub(crate) ct: f64,
    pub(crate) cig: f64,
    pub(crate) ciw: f64,
    /// Coulomb friction of motor, shaft, table (direct: motor includes the shaft's).
    pub(crate) fc: [f64; 3],
    /// The friction law of motor, shaft, table (friction/): the paper's Coulomb
    /// levels `fc`, or another law; the kernel runs each law's own path.
    pub(crate) friction: DriveFriction,
    pub(crate) kg: f64,
    pub(crate) kw: f64,
    pub(crate) kb: f64,
    pub(crate) rg: f64,
    pub(crate) rw: f64,
    pub(crate) inv_r: f64,
    pub(crate) bg: f64,
    pub(crate) bw: f64,
    pub(crate) fluct: bool,
    pub(crate) w: f64,
    pub(crate) n: f64,
    pub(crate) phase: f64,
    pub(crate) unbalance: bool,
    /// m·g·e of the unbalance, N·m.
    pub(crate) mge: f64,
    pub(crate) psi: f64,
    /// Constant external table torque Tload, N·m (N).
    pub(crate) tload: f64,
}

impl Drive {
    /// Validates `p` and compiles it.
    pub fn new(p: &Params) -> Result<Self, ParamError> {
        p.validate()?;
        let spur = p.topology == Topology::SpurGear;
        let form = match p.topology {
            Topology::SpurGear => Form::Spur,
            Topology::Direct | Topology::TwoMass => Form::Shaft,
            Topology::DirectDrive => Form::Rigid,
        };
        // Direct drive: the shaft is part of the motor body (for two_mass the
        // shaft's parameters do not apply and hold 0).
        let (jm, cm, fm) = if spur {
            (p.jm, p.cm, p.fm)
        } else {
            (p.jm + p.jw, p.cm + p.cw, p.fm + p.fw)
        };
        // Without an axial bearing (two_mass, direct_drive) xw stays 0: 1/Mw = 0.
        let axial = matches!(form, Form::Spur) || p.topology == Topology::Direct;
        Ok(Drive {
            spur,
            topology: p.topology,
            form,
            inv_jm: if form == Form::Rigid { 0.0 } else { 1.0 / jm },
            inv_jw: if spur { 1.0 / p.jw } else { 0.0 },
            inv_jt: 1.0 / p.jt,
            inv_mw: if axial { 1.0 / p.mw } else { 0.0 },
            cm,
            cw: if spur { p.cw } else { 0.0 },
            cb: p.cb,
            ct: p.ct,
            cig: p.cig.unwrap_or(0.0),
            ciw: p.ciw,
            fc: [fm, if spur { p.fw } else { 0.0 }, p.ft],
            friction: DriveFriction::of(p, [fm, if spur { p.fw } else { 0.0 }, p.ft]),
            kg: p.kg.unwrap_or(0.0),
            kw: p.kw,
            kb: p.kb,
            rg: p.rg.unwrap_or(1.0),
            rw: p.rw,
            inv_r: if axial { 1.0 / p.r } else { 0.0 },
            bg: p.theta_bg.unwrap_or(0.0),
            bw: p.theta_bw,
            fluct: p.w != 0.0,
            w: p.w,
            n: p.fluct_order,
            phase: p.fluct_phase,
            unbalance: p.unbalance_mass > 0.0,
            mge: p.unbalance_mass * GRAVITY * p.unbalance_radius,
            psi: p.unbalance_phase,
            tload: p.tload,
        })
    }

    /// Sets the slots this topology does not integrate from the ones it does (see
    /// [`idx`]).
    pub fn mirror(&self, y: &mut [f64; NSTATE]) {
        use idx::*;
        match self.form {
            Form::Spur => {}
            Form::Shaft => {
                y[THETA_W] = y[THETA_M];
                y[OMEGA_W] = y[OMEGA_M];
            }
            Form::Rigid => {
                for (pos, vel) in [(THETA_M, OMEGA_M), (THETA_W, OMEGA_W)] {
                    y[pos] = y[THETA_T];
                    y[vel] = y[OMEGA_T];
                }
            }
        }
        if self.inv_mw == 0.0 {
            y[X_W] = 0.0;
            y[V_W] = 0.0;
        }
    }

    /// The constant external table torque `Tload`, N·m (N): what a caller of the
    /// kernel adds to its external loads.
    pub fn tload(&self) -> f64 {
        self.tload
    }

    /// Total drive ratio, table turns per motor turn.
    pub fn ratio(&self) -> f64 {
        self.rg * self.rw
    }

    /// Coulomb friction torques of motor, shaft and table bodies, N·m.
    pub fn friction(&self) -> [f64; 3] {
        self.fc
    }

    /// The friction torque of each body (motor, shaft, table) sliding at `speed`
    /// (rad/s or m/s, positive), N·m (N): the Coulomb level, or the drive's law.
    pub fn sliding_friction(&self, body: usize, speed: f64) -> f64 {
        self.friction.sliding(body, speed.abs())
    }

    /// The drive's friction law.
    pub fn friction_law(&self) -> &DriveFriction {
        &self.friction
    }

    /// Total mechanical energy (kinetic + mesh and bearing springs + unbalance
    /// potential), J (rotary axis; the same in N·m = J on a linear one). Conserved by the equations without damping, friction and
    /// input; the kernel's energy test measures its drift.
    pub fn energy(&self, y: &[f64; NSTATE]) -> f64 {
        let [tm, wm, tw, ww, xw, vw, tt, wt] = *y;
        // A body without inertia of its own (the motor of direct_drive, the axial
        // unit of two_mass) has 1/J = 0 and no kinetic energy of its own.
        let kinetic = |v: f64, inv_j: f64| {
            if inv_j > 0.0 {
                0.5 * v * v / inv_j
            } else {
                0.0
            }
        };
        let mut e = kinetic(wm, self.inv_jm)
            + kinetic(vw, self.inv_mw)
            + 0.5 * wt * wt / self.inv_jt
            + 0.5 * self.kb * xw * xw;
        let shaft = if self.spur {
            e += 0.5 * ww * ww / self.inv_jw;
            let dg = dead_zone(self.rg * tm - tw, self.bg);
            e += 0.5 * self.kg * dg * dg;
            tw
        } else {
            tm
        };
        let dw = self.rw * shaft + self.fluctuation(shaft).0 + xw * self.inv_r - tt;
        let dz = dead_zone(dw, self.bw);
        e += 0.5 * self.kw * dz * dz;
        if self.unbalance {
            e -= self.mge * (tt + self.psi).cos();
        }
        e
    }

    /// Mesh torques [Tg, Tw] at state `y` (Tg = 0 without a spur stage), N·m: what
    /// the kernel applies, for diagnostics and contact statistics.
    pub fn mesh_torques(&self, y: &[f64; NSTATE]) -> [f64; 2] {
        let [tm, wm, tw, ww, xw, vw, tt, wt] = *y;
        let (shaft, ws) = if self.spur { (tw, ww) } else { (tm, wm) };
        let (e, ep) = self.fluctuation(shaft);
        let dw = self.rw * shaft + e + xw * self.inv_r - tt;
        let dw_rate = (self.rw + ep) * ws + vw * self.inv_r - wt;
        let t_w = mesh_torque(self.kw, self.ciw, self.bw, dw, dw_rate);
        let t_g = if self.spur {
            mesh_torque(
                self.kg,
                self.cig,
                self.bg,
                self.rg * tm - tw,
                self.rg * wm - ww,
            )
        } else {
            0.0
        };
        [t_g, t_w]
    }

    /// Backlash half-widths [θbg, θbw] (0 for a preloaded or absent mesh, which can
    /// never be out of contact).
    pub fn gaps(&self) -> [f64; 2] {
        [if self.spur { self.bg } else { 0.0 }, self.bw]
    }

    /// Dead-zone deflections [dz(δg), dz(δw)] at state `y`: zero while a mesh is
    /// inside its gap (out of contact).
    pub fn mesh_deflections(&self, y: &[f64; NSTATE]) -> [f64; 2] {
        let [tm, _, tw, _, xw, _, tt, _] = *y;
        let shaft = if self.spur { tw } else { tm };
        let dw = self.rw * shaft + self.fluctuation(shaft).0 + xw * self.inv_r - tt;
        let dg = if self.spur {
            dead_zone(self.rg * tm - tw, self.bg)
        } else {
            0.0
        };
        [dg, dead_zone(dw, self.bw)]
    }

    /// Gear fluctuation e(θw) = W·sin(N·θw + φ) and its slope e'(θw), table rad.
    #[inline(always)]
    pub fn fluctuation(&self, shaft_angle: f64) -> (f64, f64) {
        if !self.fluct {
            return (0.0, 0.0);
        }
        let (s, c) = (self.n * shaft_angle + self.phase).sin_cos();
        (self.w * s, self.w * self.n * c)
    }
}

/// Steps between exact evaluations of the fluctuation phase.
pub(crate) const PHASE_RESYNC: u32 = 1024;

/// sin and cos of `x`: Taylor polynomials for |x| < 0.01 (errors below x⁷/5040 and
/// x⁶/720, i.e. < 2e-18 and 1.4e-15), the library functions otherwise.
#[inline(always)]
pub(crate) fn small_sin_cos(x: f64) -> (f64, f64) {
    if x.abs() < SMALL_ANGLE {
        taylor_sin_cos(x)
    } else {
        x.sin_cos()
    }
}

/// Below this |x| the Taylor polynomials of [`taylor_sin_cos`] are used.
pub(crate) const SMALL_ANGLE: f64 = 0.01;

/// The Taylor polynomials of sin and cos used for |x| < [`SMALL_ANGLE`].
#[inline(always)]
pub(crate) fn taylor_sin_cos(x: f64) -> (f64, f64) {
    let x2 = x * x;
    let s = x * (1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0)));
    let c = 1.0 - x2 * (0.5 - x2 * (1.0 / 24.0));
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_angle_sin_cos_is_accurate_to_2e_15() {
        for i in -1000..=1000 {
            let x = i as f64 * 1e-4;
            let (s, c) = small_sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 2e-17 && (c - x.cos()).abs() < 2e-15,
                "{x}"
            );
        }
    }
}
