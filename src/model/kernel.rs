//! The simulation kernel: the equations of motion of docs/model.md §2 and a classical
//! fourth-order Runge–Kutta step, for `L` independent trajectories advanced in
//! lockstep ("lanes", structure of arrays: state `i` of lane `l` is `y[i][l]`).
//! `L = 1` is one trajectory; wider lanes let the compiler vectorise independent
//! simulations (the frequencies of a frequency-response sweep, or the parameter sets
//! of a batch: every constant is read per lane from a [`LaneDrive`], so each lane may
//! hold another drive of the same shape).
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
//! Friction is the stick/slip clamp of `friction/clamp.rs` with the drive's law
//! (`friction/`): Coulomb levels, or a law whose level is evaluated at each stage's
//! velocity, such as Stribeck's (the kernel is generic over the [`FrictionLaw`] and
//! the drive picks its law outside the step loop). Tload is the lane's external
//! table torque, which includes the drive's constant `Tload` parameter (added by
//! the caller, see [`Kernel::step`]).
//!
//! The `two_mass` topology is the direct form with Rw = 1 and no axial degree of
//! freedom (1/r = Kb = Cb = 1/Mw = 0 in the compiled drive, so xw stays 0): the
//! coupling Tk is Tw, and Jm·ωm' = Tm − Cm·ωm − (1 + e')·Tk − friction_m. The
//! `direct_drive` topology is one rigid body integrated by its own short step
//! (`rigid_rk4`): Jt·ωt' = Tm − Ct·ωt − m·g·e·sin(θt + ψ) + Tload − friction_t, the
//! motor and shaft slots mirroring the table. On a linear axis the same equations
//! hold in m, N, kg.
//!
//! **Lanes.** The common path of a step has no per-lane control flow: the dead
//! zones, the contact clamp, the friction decision and the stop at a velocity
//! reversal (in the rigid step: after a branch on whether any lane reverses) are
//! selects between values computed for every lane (backlash.rs,
//! friction/clamp.rs, lanes.rs), so the compiler vectorises the `L` lanes. What is rare
//! is taken out of line, and only when some lane needs it: the library `sin_cos` of
//! the fluctuation phase (every 1024 steps, or after a jump), and the re-integration
//! of a step split at a contact event (2.8 % of worm steps at ±5 N·m), which is done
//! for the affected lane alone by the same code at `L = 1`. Lane `l` of a `Kernel<L>`
//! therefore follows bit for bit the trajectory that a `Kernel<1>` would compute for
//! it (tested: `tests/lanes.rs`).
//!
//! **Contact events.** A mesh entering or leaving contact puts a kink into the
//! equations; RK4 stepping across it drops to second order (measured: the energy of
//! the undamped worm with backlash drifts 1.2e-3 over 1 s at dt = 1e-5 s). So a step
//! in which any mesh of a lane changes contact is split at the crossing: the twist
//! is interpolated over the step by the cubic Hermite polynomial of its values and
//! rates at both ends, its crossing of the gap edge located by bisection, and the
//! lane re-integrated from the step's start to the crossing and from there to the
//! step's end (lanes without an event keep their full step, untouched). Inputs inside the step
//! come from the quadratic through the three given values (exact for the held
//! torque of the controller).
//!
//! **Fluctuation.** sin/cos of N·θw + φ is carried from step start to step start
//! by small rotations (computed afresh every 1024 steps, drive.rs); later stages
//! use the cubic Taylor polynomial of e about the step start.
//!
//! **Unbalance.** sin(θt + ψ) is carried along the table angle the same way
//! ([`Carried`]) and rotated from the step start to each later stage's angle: one
//! library call per 1024 steps where there was one per stage and lane.
//!
//! The step allocates nothing: stage derivatives and step-start values live in the
//! [`Kernel`], which the caller owns and reuses.

use super::backlash::mesh_torque_lanes;
use super::drive::{idx::*, taylor_sin_cos, NSTATE, PHASE_RESYNC, SMALL_ANGLE};
use super::friction::clamp::{decide_direction_lanes, decide_lanes, stop_at_reversal_lanes};
use super::friction::lanes::{with_lane_law, LaneLaw};
use super::friction::FrictionLaw;
use super::lane_drive::LaneDrive;
use super::lanes::Lanes;

/// The state of `L` lanes: `y[i][l]` is state `i` (see [`idx`](super::drive::idx)) of lane `l`.
pub type States<const L: usize> = [[f64; L]; NSTATE];

/// What the kernel remembers per lane: the friction decisions of the current step,
/// and the values at the start of the current (sub)step computed by the first stage
/// for the later stages and the event check.
#[derive(Clone, Copy, Debug)]
struct LaneState<const L: usize> {
    /// Friction torque of motor, shaft, table opposing the motion (0 when stuck).
    friction: [[f64; L]; 3],
    /// 1 while the body moves, 0 while it sticks.
    free: [[f64; L]; 3],
    /// With a Stribeck law: the sign of the friction of motor, shaft, table (±1
    /// against the motion, 0 when stuck), its level evaluated at each stage.
    direction: [[f64; L]; 3],
    /// free / inertia: net torque → acceleration (0 while stuck).
    gain: [[f64; L]; 3],
    /// The fluctuation's phase N·θw + φ, carried along the shaft angle.
    phase: Carried<L>,
    /// The unbalance's angle θt + ψ, carried along the table angle.
    table: Carried<L>,
    /// Taylor coefficients of e(θ0 + Δ) = e0 + e1·Δ + e2·Δ²/2 + e3·Δ³/6 at the
    /// step start: [e0, e1, e2/2, e3/6, e2, e3/2].
    taylor: [[f64; L]; 6],
    /// Twist and twist rate of the spur mesh (0) and the drive mesh (1).
    twist: [[f64; L]; 2],
    rate: [[f64; L]; 2],
}

impl<const L: usize> Default for LaneState<L> {
    fn default() -> Self {
        LaneState {
            friction: [[0.0; L]; 3],
            free: [[1.0; L]; 3],
            direction: [[0.0; L]; 3],
            gain: [[0.0; L]; 3],
            phase: Carried::default(),
            table: Carried::default(),
            taylor: [[0.0; L]; 6],
            twist: [[0.0; L]; 2],
            rate: [[0.0; L]; 2],
        }
    }
}

impl<const L: usize> LaneState<L> {
    /// Lane `l` alone.
    fn lane(&self, l: usize) -> LaneState<1> {
        LaneState {
            friction: self.friction.map(|b| [b[l]]),
            free: self.free.map(|b| [b[l]]),
            direction: self.direction.map(|b| [b[l]]),
            gain: self.gain.map(|b| [b[l]]),
            phase: self.phase.lane(l),
            table: self.table.lane(l),
            taylor: self.taylor.map(|t| [t[l]]),
            twist: self.twist.map(|t| [t[l]]),
            rate: self.rate.map(|t| [t[l]]),
        }
    }

    /// Replaces lane `l` by `one`.
    fn set_lane(&mut self, l: usize, one: &LaneState<1>) {
        for b in 0..3 {
            self.friction[b][l] = one.friction[b][0];
            self.free[b][l] = one.free[b][0];
            self.direction[b][l] = one.direction[b][0];
            self.gain[b][l] = one.gain[b][0];
        }
        self.phase.set_lane(l, &one.phase);
        self.table.set_lane(l, &one.table);
        for k in 0..6 {
            self.taylor[k][l] = one.taylor[k][0];
        }
        for m in 0..2 {
            self.twist[m][l] = one.twist[m][0];
            self.rate[m][l] = one.rate[m][0];
        }
    }

    /// Decides the friction of body `b` (inverse inertia `inv_j`) from the sum `t`
    /// of its other torques and its velocity `w`: with a constant level (Coulomb)
    /// its torque for the whole step, with another law its direction.
    #[inline(always)]
    fn decide<F: FrictionLaw>(
        &mut self,
        law: &LaneLaw<F, L>,
        b: usize,
        t: Lanes<L>,
        w: Lanes<L>,
        inv_j: Lanes<L>,
    ) {
        let free = if F::CONSTANT_LEVEL {
            let (torque, free) = decide_lanes(t, w, law.breakaway(b));
            self.friction[b] = torque.0;
            free
        } else {
            let (direction, free) = decide_direction_lanes(t, w, law.breakaway(b));
            self.direction[b] = direction.0;
            free
        };
        self.free[b] = free.0;
        self.gain[b] = (free * inv_j).0;
    }

    /// The acceleration of body `b` at velocity `w` under the other torques `t`:
    /// (t − friction)/J, 0 while stuck. (free ∈ {0, 1}, so this equals
    /// ((t − friction)·free)/J exactly.) With a law whose level varies the
    /// friction's level is that of `w`.
    #[inline(always)]
    fn accel<F: FrictionLaw>(
        &self,
        law: &LaneLaw<F, L>,
        b: usize,
        t: Lanes<L>,
        w: Lanes<L>,
    ) -> Lanes<L> {
        let friction = if F::CONSTANT_LEVEL {
            Lanes(self.friction[b])
        } else {
            Lanes(self.direction[b]) * law.sliding(b, w.map(f64::abs))
        };
        (t - friction) * Lanes(self.gain[b])
    }

    /// e and e' at a step's start: sin/cos of the phase carried from the previous
    /// step's start ([`Carried::advance`]). Stores the Taylor coefficients for later
    /// stages.
    #[inline(always)]
    fn fluctuation_first(&mut self, d: &LaneDrive<L>, shaft: Lanes<L>) -> (Lanes<L>, Lanes<L>) {
        let (s, c) = self
            .phase
            .advance(d.n, shaft, |l, shaft| d.exact_phase(l, shaft));
        let e0 = d.w * s;
        let e1 = (d.w * d.n) * c;
        let (e2, e3) = ((-d.n * d.n) * e0, (-d.n * d.n) * e1);
        self.taylor = [
            e0.0,
            e1.0,
            (0.5 * e2).0,
            (e3 * (1.0 / 6.0)).0,
            e2.0,
            (0.5 * e3).0,
        ];
        (e0, e1)
    }

    /// Tu = −m·g·e·sin(θt + ψ) at table angles `table`: at a step's start (`FIRST`)
    /// the angle's sin carried from the previous step's start, at later stages
    /// rotated from there ([`Carried`]); the library's `sin` of every stage before.
    #[inline(always)]
    fn unbalance<const FIRST: bool>(&mut self, d: &LaneDrive<L>, table: Lanes<L>) -> Lanes<L> {
        let exact = |l: usize, t: f64| d.exact_unbalance(l, t);
        let s = if FIRST {
            self.table.advance(Lanes::splat(1.0), table, exact).0
        } else {
            self.table.near(Lanes::splat(1.0), table).0
        };
        -d.mge * s
    }

    /// e and e' at a later stage: the cubic Taylor polynomial of e about the step
    /// start (error below W·(N·Δθ)⁴/24 < 4e-10·W; its slope is the polynomial's
    /// exact derivative, so the mesh energy stays consistent), or the exact rotation
    /// for a lane that moved |N·Δθ| ≥ 0.01 within the step (out of line).
    #[inline(always)]
    fn fluctuation_later(&self, d: &LaneDrive<L>, shaft: Lanes<L>) -> (Lanes<L>, Lanes<L>) {
        let dx = shaft - Lanes(self.phase.base);
        let t = self.taylor.map(Lanes);
        let mut e = t[0] + dx * (t[1] + dx * (t[2] + dx * t[3]));
        let mut ep = t[1] + dx * (t[4] + dx * t[5]);
        if (d.n * dx).any(far) {
            self.far_fluctuation(d, shaft, &mut e, &mut ep);
        }
        (e, ep)
    }

    #[cold]
    #[inline(never)]
    fn far_fluctuation(
        &self,
        d: &LaneDrive<L>,
        shaft: Lanes<L>,
        e: &mut Lanes<L>,
        ep: &mut Lanes<L>,
    ) {
        let p = &self.phase;
        for l in 0..L {
            if far(d.n.0[l] * (shaft.0[l] - p.base[l])) {
                (e.0[l], ep.0[l]) =
                    d.fluctuation_near(l, shaft.0[l], p.base[l], (p.sin[l], p.cos[l]));
            }
        }
    }

    /// e and e' at `shaft` by the exact rotation from the step start (drive.rs's
    /// `fluctuation_near`, lane-wise; the library `sin_cos` out of line for lanes
    /// with |N·Δθ| ≥ 0.01).
    #[inline(always)]
    fn fluctuation_near(&self, d: &LaneDrive<L>, shaft: Lanes<L>) -> (Lanes<L>, Lanes<L>) {
        let (s, c) = self.phase.near(d.n, shaft);
        (d.w * s, (d.w * d.n) * c)
    }
}

/// sin and cos of an angle a·θ + φ carried along θ from step start to step start by
/// small rotations (the library's `sin_cos` every [`PHASE_RESYNC`] steps, after a
/// jump and on the first step, out of line for the lanes that need it), and rotated
/// from the step start to a later stage's θ: exact to rounding, with one library
/// call per 1024 steps instead of one per stage.
#[derive(Clone, Copy, Debug)]
struct Carried<const L: usize> {
    /// θ at the step start, and sin, cos of a·θ + φ there.
    base: [f64; L],
    sin: [f64; L],
    cos: [f64; L],
    /// Steps left before the angle is computed afresh (0: compute now); a whole
    /// number, kept as `f64` so that its update vectorises with the rest.
    fresh: [f64; L],
}

impl<const L: usize> Default for Carried<L> {
    fn default() -> Self {
        Carried {
            base: [0.0; L],
            sin: [0.0; L],
            cos: [1.0; L],
            fresh: [0.0; L],
        }
    }
}

impl<const L: usize> Carried<L> {
    fn lane(&self, l: usize) -> Carried<1> {
        Carried {
            base: [self.base[l]],
            sin: [self.sin[l]],
            cos: [self.cos[l]],
            fresh: [self.fresh[l]],
        }
    }

    fn set_lane(&mut self, l: usize, one: &Carried<1>) {
        self.base[l] = one.base[0];
        self.sin[l] = one.sin[0];
        self.cos[l] = one.cos[0];
        self.fresh[l] = one.fresh[0];
    }

    /// sin, cos of a·θ + φ at the step start `theta` (`a` = `scale`), made the new
    /// base: rotated from the previous base, or `exact(l, θ)` where lane `l`'s
    /// counter ran out or the angle moved |a·Δθ| ≥ 0.01.
    #[inline(always)]
    fn advance(
        &mut self,
        scale: Lanes<L>,
        theta: Lanes<L>,
        exact: impl Fn(usize, f64) -> (f64, f64),
    ) -> (Lanes<L>, Lanes<L>) {
        let x = scale * (theta - Lanes(self.base));
        let sx = x.map(|x| taylor_sin_cos(x).0);
        let cx = x.map(|x| taylor_sin_cos(x).1);
        let (s0, c0) = (Lanes(self.sin), Lanes(self.cos));
        let mut s = s0 * cx + c0 * sx;
        let mut c = c0 * cx - s0 * sx;
        let resync_at = PHASE_RESYNC as f64;
        let fresh = Lanes(self.fresh).zip(x, |fresh, x| {
            if (fresh > 0.0) & (x.abs() < SMALL_ANGLE) {
                fresh - 1.0
            } else {
                resync_at
            }
        });
        self.fresh = fresh.0;
        if fresh.any(|f| f == resync_at) {
            self.resync(theta, &mut s, &mut c, exact);
        }
        self.base = theta.0;
        self.sin = s.0;
        self.cos = c.0;
        (s, c)
    }

    /// The library's sin/cos for the lanes whose counter was just reset.
    #[cold]
    #[inline(never)]
    fn resync(
        &self,
        theta: Lanes<L>,
        s: &mut Lanes<L>,
        c: &mut Lanes<L>,
        exact: impl Fn(usize, f64) -> (f64, f64),
    ) {
        for l in 0..L {
            if self.fresh[l] == PHASE_RESYNC as f64 {
                (s.0[l], c.0[l]) = exact(l, theta.0[l]);
            }
        }
    }

    /// sin, cos of a·θ + φ at `theta` within a step: the base rotated by a·Δθ
    /// (Taylor polynomials, the library out of line where |a·Δθ| ≥ 0.01).
    #[inline(always)]
    fn near(&self, scale: Lanes<L>, theta: Lanes<L>) -> (Lanes<L>, Lanes<L>) {
        let x = scale * (theta - Lanes(self.base));
        let mut sx = x.map(|x| taylor_sin_cos(x).0);
        let mut cx = x.map(|x| taylor_sin_cos(x).1);
        if x.any(far) {
            library_sin_cos(x, &mut sx, &mut cx);
        }
        let (s0, c0) = (Lanes(self.sin), Lanes(self.cos));
        (s0 * cx + c0 * sx, c0 * cx - s0 * sx)
    }
}

/// Whether the angle `x` is beyond the Taylor polynomials' range (or NaN).
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn far(x: f64) -> bool {
    !(x.abs() < SMALL_ANGLE)
}

/// sin, cos of `x` by the library in the lanes where |x| ≥ 0.01.
#[cold]
#[inline(never)]
fn library_sin_cos<const L: usize>(x: Lanes<L>, s: &mut Lanes<L>, c: &mut Lanes<L>) {
    for l in 0..L {
        if far(x.0[l]) {
            (s.0[l], c.0[l]) = x.0[l].sin_cos();
        }
    }
}

/// The integrator's memory for `L` lanes: per-step stick decisions of motor, shaft
/// and table, and step-start values. Owned and reused by the caller.
#[derive(Clone, Debug)]
pub struct Kernel<const L: usize> {
    lanes: LaneState<L>,
    /// Number of steps split at a contact event (all lanes), for diagnostics.
    events: u64,
}

impl<const L: usize> Default for Kernel<L> {
    fn default() -> Self {
        Kernel {
            lanes: LaneState::default(),
            events: 0,
        }
    }
}

impl<const L: usize> Kernel<L> {
    /// Advances every lane of `y` by one step of length `h`.
    ///
    /// `motor[s][l]` is lane `l`'s motor torque at the step's start (`s = 0`), middle
    /// (`s = 1`) and end (`s = 2`); `load[l]` the external table torque, held over the
    /// step, **including** the drive's constant `Tload` ([`Drive::tload`](crate::model::Drive::tload): the
    /// simulations add it to their loads, so the kernel never spends an addition on
    /// it).
    #[inline]
    pub fn step(
        &mut self,
        d: &LaneDrive<L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        if d.form == crate::model::drive::Form::Rigid {
            self.step_rigid(d, y, motor, load, h);
        } else {
            self.step_meshed(d, y, motor, load, h);
        }
    }

    /// [`Kernel::step`] with a friction law of the caller's in place of the drive's
    /// own ([`Drive::friction_law`](crate::model::Drive::friction_law)): a law under development runs through the same
    /// clamp, integrator and events before it has its
    /// [`DriveFriction`](super::friction::DriveFriction) variant
    /// (`model/friction/tests.rs` runs one). `step` is this with the drive's law.
    pub fn step_with_law<F: FrictionLaw>(
        &mut self,
        d: &LaneDrive<L>,
        law: &LaneLaw<F, L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        if d.form == crate::model::drive::Form::Rigid {
            rigid_rk4(d, law, &mut self.lanes, y, motor, load, h);
        } else if d.spur {
            self.step_with_events::<true, F>(d, law, y, motor, load, h);
        } else {
            self.step_with_events::<false, F>(d, law, y, motor, load, h);
        }
    }

    /// [`Kernel::step`] for a drive with meshes (`spur_gear`, `direct`, `two_mass`).
    /// A loop over steps of one drive calls this (or [`Kernel::step_rigid`]) directly,
    /// the choice made once outside the loop: with the rigid form's branch inside the
    /// loop the compiler allocated the meshed forms' registers worse (measured: 24
    /// more instructions per step on the roller-gear cam, 5 %, mostly spills).
    #[inline]
    pub(crate) fn step_meshed(
        &mut self,
        d: &LaneDrive<L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        with_lane_law!(&d.friction, law => if d.spur {
            self.step_with_events::<true, _>(d, law, y, motor, load, h)
        } else {
            self.step_with_events::<false, _>(d, law, y, motor, load, h)
        })
    }

    /// [`Kernel::step`] for the single rigid body of `direct_drive`.
    #[inline]
    pub(crate) fn step_rigid(
        &mut self,
        d: &LaneDrive<L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        with_lane_law!(&d.friction, law => rigid_rk4(d, law, &mut self.lanes, y, motor, load, h));
    }

    /// Whether motor, shaft and table of lane `l` were stuck during the last step.
    pub fn stuck(&self, l: usize) -> [bool; 3] {
        [0, 1, 2].map(|b| self.lanes.free[b][l] == 0.0)
    }

    /// Lane-steps split at a contact event so far.
    pub fn events(&self) -> u64 {
        self.events
    }

    /// Forgets lane `l`'s memory, as for a new trajectory (a fresh `Kernel` lane).
    pub(crate) fn reset_lane(&mut self, l: usize) {
        self.lanes.set_lane(l, &LaneState::default());
    }

    #[inline(always)]
    fn step_with_events<const SPUR: bool, F: FrictionLaw>(
        &mut self,
        d: &LaneDrive<L>,
        law: &LaneLaw<F, L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
    ) {
        let y0 = *y;
        rk4::<L, SPUR, F>(
            d,
            law,
            &mut self.lanes,
            &y0,
            y,
            motor,
            load,
            Lanes::splat(h),
        );
        let gaps = [SPUR && d.gapped[0], d.gapped[1]];
        if !(gaps[0] || gaps[1]) {
            return;
        }
        // Twist and rate of both meshes at the step's end; a lane whose region
        // (below, inside, above the gap) changed over the step had a contact event.
        let st = &self.lanes;
        let v = |i: usize| Lanes(y[i]);
        let (shaft, ws) = if SPUR {
            (v(THETA_W), v(OMEGA_W))
        } else {
            (v(THETA_M), v(OMEGA_M))
        };
        let mut twist = [Lanes::splat(0.0); 2];
        let mut rate = [Lanes::splat(0.0); 2];
        let mut changed = false;
        if gaps[0] {
            twist[0] = d.rg * v(THETA_M) - shaft;
            rate[0] = d.rg * v(OMEGA_M) - ws;
            changed |= region_changed(Lanes(st.twist[0]), twist[0], d.bg);
        }
        if gaps[1] {
            let (e, ep) = if d.fluct {
                st.fluctuation_near(d, shaft)
            } else {
                (Lanes::splat(0.0), Lanes::splat(0.0))
            };
            twist[1] = d.rw * shaft + e + v(X_W) * d.inv_r - v(THETA_T);
            rate[1] = (d.rw + ep) * ws + v(V_W) * d.inv_r - v(OMEGA_T);
            changed |= region_changed(Lanes(st.twist[1]), twist[1], d.bw);
        }
        if changed {
            self.resolve_events::<SPUR, F>(d, law, &y0, y, motor, load, h, &twist, &rate);
        }
    }

    /// Splits the step of each lane with a contact event at the crossing.
    #[cold]
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn resolve_events<const SPUR: bool, F: FrictionLaw>(
        &mut self,
        d: &LaneDrive<L>,
        law: &LaneLaw<F, L>,
        y0: &States<L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
        twist: &[Lanes<L>; 2],
        rate: &[Lanes<L>; 2],
    ) {
        for l in 0..L {
            let gaps = [if SPUR { d.bg.0[l] } else { 0.0 }, d.bw.0[l]];
            let mut earliest: Option<f64> = None;
            for (mesh, &b) in gaps.iter().enumerate() {
                if b > 0.0 {
                    let start = (self.lanes.twist[mesh][l], self.lanes.rate[mesh][l]);
                    let end = (twist[mesh].0[l], rate[mesh].0[l]);
                    if let Some(s) = crossing(start, end, b, h) {
                        earliest = Some(earliest.map_or(s, |e: f64| e.min(s)));
                    }
                }
            }
            if let Some(s) = earliest.filter(|&s| s > 0.0 && s < 1.0) {
                self.split_lane::<SPUR, F>(d, law, y0, y, motor, load, h, l, s);
            }
        }
    }

    /// Re-integrates lane `l` from the step's start in two pieces split at fraction
    /// `s` of the step, alone (`L = 1`), so that its result does not depend on the
    /// other lanes.
    #[allow(clippy::too_many_arguments)]
    fn split_lane<const SPUR: bool, F: FrictionLaw>(
        &mut self,
        d: &LaneDrive<L>,
        law: &LaneLaw<F, L>,
        y0: &States<L>,
        y: &mut States<L>,
        motor: &[[f64; L]; 3],
        load: &[f64; L],
        h: f64,
        l: usize,
        s: f64,
    ) {
        self.events += 1;
        let mut one = self.lanes.lane(l);
        let mut part: States<1> = [[0.0]; NSTATE];
        for i in 0..NSTATE {
            part[i] = [y0[i][l]];
        }
        let m = [motor[0][l], motor[1][l], motor[2][l]];
        let m1 = [0.0, 0.5 * s, s].map(|at| [quadratic(&m, at)]);
        let m2 = [s, 0.5 * (1.0 + s), 1.0].map(|at| [quadratic(&m, at)]);
        let load = [load[l]];
        let mut mid = part;
        let (d, law) = (&d.lane(l), &law.lane(l));
        rk4::<1, SPUR, F>(
            d,
            law,
            &mut one,
            &part,
            &mut mid,
            &m1,
            &load,
            Lanes([s * h]),
        );
        rk4::<1, SPUR, F>(
            d,
            law,
            &mut one,
            &mid,
            &mut part,
            &m2,
            &load,
            Lanes([(1.0 - s) * h]),
        );
        for i in 0..NSTATE {
            y[i][l] = part[i][0];
        }
        self.lanes.set_lane(l, &one);
    }
}

/// -1 below the gap, 0 inside it (no contact), +1 above it.
#[inline(always)]
fn region(twist: f64, b: f64) -> f64 {
    let below = if twist < -b { -1.0 } else { 0.0 };
    if twist > b {
        1.0
    } else {
        below
    }
}

/// Whether any lane's twist changed region between `start` and `end`.
#[inline(always)]
#[allow(clippy::needless_range_loop)]
fn region_changed<const L: usize>(start: Lanes<L>, end: Lanes<L>, b: Lanes<L>) -> bool {
    let mut change = start.0;
    for l in 0..L {
        change[l] = region(start.0[l], b.0[l]) - region(end.0[l], b.0[l]);
    }
    Lanes(change).any(|d| d != 0.0)
}

/// The fraction of a step of length `h` at which a mesh's twist, going from
/// (twist, rate) `start` to `end`, crosses the edge of its gap `b`; `None` if it
/// stays in its region or starts exactly on the edge.
fn crossing((t0, r0): (f64, f64), (t1, r1): (f64, f64), b: f64, h: f64) -> Option<f64> {
    let (g0, g1) = (region(t0, b), region(t1, b));
    if g0 == g1 {
        return None;
    }
    let edge = b * if g0 != 0.0 { g0 } else { g1 };
    if t0 == edge {
        return None;
    }
    Some(hermite_crossing(t0 - edge, h * r0, t1 - edge, h * r1))
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

/// One classical RK4 step of the single rigid body of `direct_drive` (motor rotor and
/// table, slots θt, ωt; motor and shaft slots mirror them):
///
/// ```text
/// Jt·ωt' = Tm − Ct·ωt − friction_t − m·g·e·sin(θt + ψ) + Tload
/// ```
///
/// with the stick/slip decision of friction/clamp.rs at the step's first stage and the stop
/// at a velocity reversal, as for the table of the other forms. No mesh, so no
/// contact events. Lane-wise (each lane its own Ct, Jt, friction, load), out of line:
/// its mere presence inside the other forms' step changed how the compiler allocated
/// registers there (measured: 24 more instructions per step on the roller-gear cam,
/// mostly spills).
#[inline(never)]
fn rigid_rk4<const L: usize, F: FrictionLaw>(
    d: &LaneDrive<L>,
    laws: &LaneLaw<F, L>,
    st: &mut LaneState<L>,
    y: &mut States<L>,
    motor: &[[f64; L]; 3],
    load: &[f64; L],
    h: f64,
) {
    let (ct, load) = (d.ct, Lanes(*load));
    let (t1, w1) = (Lanes(y[THETA_T]), Lanes(y[OMEGA_T]));
    // Without unbalance its term is left out rather than added as 0: (x + 0) + load
    // is x + load for every x and a load that is not −0 (a load is 0 + Tload), one
    // addition fewer on the chain from stage to stage.
    let torque = |t: Lanes<L>, w: Lanes<L>, m: [f64; L]| {
        let own = Lanes(m) - ct * w;
        let own = if d.unbalance {
            own + rigid_unbalance(d, t)
        } else {
            own
        };
        own + load
    };
    let first = torque(t1, w1, motor[0]);
    let friction = RigidFriction::decide(laws, first, w1, d.inv_jt);
    let accel = |t: Lanes<L>, w: Lanes<L>| friction.accel(t, w);
    let a1 = accel(first, w1);
    let (t2, w2) = (t1 + 0.5 * h * w1, w1 + 0.5 * h * a1);
    let a2 = accel(torque(t2, w2, motor[1]), w2);
    let (t3, w3) = (t1 + 0.5 * h * w2, w1 + 0.5 * h * a2);
    let a3 = accel(torque(t3, w3, motor[1]), w3);
    let (t4, w4) = (t1 + h * w3, w1 + h * a3);
    let a4 = accel(torque(t4, w4, motor[2]), w4);
    let sixth = h * (1.0 / 6.0);
    let angle = t1 + sixth * (w1 + 2.0 * (w2 + w3) + w4);
    let speed = w1 + sixth * (a1 + 2.0 * (a2 + a3) + a4);
    // A reversal is rare: a branch on it keeps the select off the velocity's chain
    // from step to step (measured: the select on every step cost 4-7 % of the
    // lone direct drive's time).
    let speed = if (w1 * speed).any(|x| x < 0.0) {
        stop_at_reversal_lanes(w1, speed, laws.breakaway(2))
    } else {
        speed
    };
    for (pos, vel) in [(THETA_M, OMEGA_M), (THETA_W, OMEGA_W), (THETA_T, OMEGA_T)] {
        y[pos] = angle.0;
        y[vel] = speed.0;
    }
    // Motor and shaft are the table: they stick when it does.
    st.free = [friction.free.0; 3];
}

/// The rigid body's friction over one step, per lane: with a constant level
/// (Coulomb) its torque, else its direction with the law to evaluate at each stage.
#[derive(Clone, Copy)]
struct RigidFriction<'a, F, const L: usize> {
    /// The friction torque (constant level) or its sign (±1, 0 when stuck).
    torque_or_direction: Lanes<L>,
    /// 1 while the body moves, 0 while it sticks.
    free: Lanes<L>,
    /// free / Jt: net torque → acceleration (0 while stuck).
    gain: Lanes<L>,
    laws: &'a LaneLaw<F, L>,
}

impl<'a, F: FrictionLaw, const L: usize> RigidFriction<'a, F, L> {
    /// The stick decision from the torque `t` on the body at velocity `w`, its
    /// inverse inertia `inv_j`.
    #[inline(always)]
    fn decide(laws: &'a LaneLaw<F, L>, t: Lanes<L>, w: Lanes<L>, inv_j: Lanes<L>) -> Self {
        let (torque_or_direction, free) = if F::CONSTANT_LEVEL {
            decide_lanes(t, w, laws.breakaway(2))
        } else {
            decide_direction_lanes(t, w, laws.breakaway(2))
        };
        RigidFriction {
            torque_or_direction,
            free,
            gain: free * inv_j,
            laws,
        }
    }

    /// The acceleration at velocity `w` under the other torques `t`:
    /// (t − friction)·(free/Jt), 0 while stuck. (free ∈ {0, 1} and 1/Jt > 0, so
    /// this equals ((t − friction)·free)/Jt bit for bit, one multiplication fewer
    /// on the chain from stage to stage.)
    #[inline(always)]
    fn accel(self, t: Lanes<L>, w: Lanes<L>) -> Lanes<L> {
        let torque = if F::CONSTANT_LEVEL {
            self.torque_or_direction
        } else {
            self.torque_or_direction * self.laws.sliding(2, w.map(f64::abs))
        };
        (t - torque) * self.gain
    }
}

/// Tu = −m·g·e·sin(θt + ψ) on the rigid body at table angles `t` (0 without
/// unbalance).
#[inline(always)]
fn rigid_unbalance<const L: usize>(d: &LaneDrive<L>, t: Lanes<L>) -> Lanes<L> {
    if d.unbalance {
        Lanes(std::array::from_fn(|l| d.unbalance_torque(l, t.0[l])))
    } else {
        Lanes::splat(0.0)
    }
}

/// `y + a·k`, lane-wise.
#[inline(always)]
fn axpy<const L: usize>(y: &States<L>, a: Lanes<L>, k: &States<L>) -> States<L> {
    let mut out = [[0.0; L]; NSTATE];
    for i in 0..NSTATE {
        out[i] = (Lanes(y[i]) + a * Lanes(k[i])).0;
    }
    out
}

/// One classical RK4 step of length `h[l]` for each lane from `y0` into `y`, then
/// the stop of sliding bodies whose velocity reversed (friction/clamp.rs). Stage values
/// are locals, not fields, so the compiler can keep them in registers.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn rk4<const L: usize, const SPUR: bool, F: FrictionLaw>(
    d: &LaneDrive<L>,
    law: &LaneLaw<F, L>,
    st: &mut LaneState<L>,
    y0: &States<L>,
    y: &mut States<L>,
    motor: &[[f64; L]; 3],
    load: &[f64; L],
    h: Lanes<L>,
) {
    let half = h.map(|h| 0.5 * h);
    let load = Lanes(*load);
    let k1 = derivative::<L, SPUR, true, F>(d, law, y0, Lanes(motor[0]), load, st);
    let k2 =
        derivative::<L, SPUR, false, F>(d, law, &axpy(y0, half, &k1), Lanes(motor[1]), load, st);
    let k3 =
        derivative::<L, SPUR, false, F>(d, law, &axpy(y0, half, &k2), Lanes(motor[1]), load, st);
    let k4 = derivative::<L, SPUR, false, F>(d, law, &axpy(y0, h, &k3), Lanes(motor[2]), load, st);
    let sixth = h.map(|h| h * (1.0 / 6.0));
    for i in 0..NSTATE {
        let (a, b, c, e) = (Lanes(k1[i]), Lanes(k2[i]), Lanes(k3[i]), Lanes(k4[i]));
        y[i] = (Lanes(y0[i]) + sixth * (a + 2.0 * (b + c) + e)).0;
    }
    let stop = |y: &States<L>, i: usize, b: usize| {
        stop_at_reversal_lanes(Lanes(y0[i]), Lanes(y[i]), law.breakaway(b)).0
    };
    y[OMEGA_M] = stop(y, OMEGA_M, 0);
    if SPUR {
        y[OMEGA_W] = stop(y, OMEGA_W, 1);
    } else {
        y[THETA_W] = y[THETA_M];
        y[OMEGA_W] = y[OMEGA_M];
    }
    y[OMEGA_T] = stop(y, OMEGA_T, 2);
}

/// The right-hand side of the equations of motion for every lane. With `FIRST`
/// (a step's first stage), each body's stick state is decided from the torques at
/// `y`, and the step-start values are stored in `st` for the later stages.
#[inline(always)]
fn derivative<const L: usize, const SPUR: bool, const FIRST: bool, F: FrictionLaw>(
    d: &LaneDrive<L>,
    law: &LaneLaw<F, L>,
    y: &States<L>,
    motor: Lanes<L>,
    load: Lanes<L>,
    st: &mut LaneState<L>,
) -> States<L> {
    let v = |i: usize| Lanes(y[i]);
    let zero = Lanes::splat(0.0);
    let (wm, xw, vw, tt, wt) = (v(OMEGA_M), v(X_W), v(V_W), v(THETA_T), v(OMEGA_T));
    let (shaft, ws) = if SPUR {
        (v(THETA_W), v(OMEGA_W))
    } else {
        (v(THETA_M), wm)
    };
    let (e, ep) = if !d.fluct {
        (zero, zero)
    } else if FIRST {
        st.fluctuation_first(d, shaft)
    } else {
        st.fluctuation_later(d, shaft)
    };
    let lever = d.rw + ep;
    let dw = d.rw * shaft + e + xw * d.inv_r - tt;
    let dw_rate = lever * ws + vw * d.inv_r - wt;
    let tw = mesh_torque_lanes((d.kw, d.ciw, d.bw), d.gapped[1], dw, dw_rate);

    let unbalance = if d.unbalance {
        st.unbalance::<FIRST>(d, tt)
    } else {
        zero
    };
    let table = tw - d.ct * wt + unbalance + load;
    if FIRST {
        st.decide(law, 2, table, wt, d.inv_jt);
    }
    let at = st.accel(law, 2, table, wt);
    let ax = (-d.cb * vw - d.kb * xw - tw * d.inv_r) * d.inv_mw;

    let mut out = [[0.0; L]; NSTATE];
    let am = if SPUR {
        let dg = d.rg * v(THETA_M) - shaft;
        let dg_rate = d.rg * wm - ws;
        if FIRST {
            st.twist[0] = dg.0;
            st.rate[0] = dg_rate.0;
        }
        let tg = mesh_torque_lanes((d.kg, d.cig, d.bg), d.gapped[0], dg, dg_rate);
        let m = motor - d.cm * wm - d.rg * tg;
        let s = tg - d.cw * ws - lever * tw;
        if FIRST {
            st.decide(law, 0, m, wm, d.inv_jm);
            st.decide(law, 1, s, ws, d.inv_jw);
        }
        out[OMEGA_W] = st.accel(law, 1, s, ws).0;
        out[THETA_W] = ws.0;
        st.accel(law, 0, m, wm)
    } else {
        let m = motor - d.cm * wm - lever * tw;
        if FIRST {
            st.decide(law, 0, m, wm, d.inv_jm);
        }
        let a = st.accel(law, 0, m, wm);
        out[OMEGA_W] = a.0;
        out[THETA_W] = wm.0;
        a
    };
    if FIRST {
        st.twist[1] = dw.0;
        st.rate[1] = dw_rate.0;
    }
    out[THETA_M] = wm.0;
    out[OMEGA_M] = am.0;
    out[X_W] = vw.0;
    out[V_W] = ax.0;
    out[THETA_T] = wt.0;
    out[OMEGA_T] = at.0;
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
