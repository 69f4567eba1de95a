//! [`LaneDrive`]: the constants of `L` compiled drives side by side, one lane each,
//! in the form the kernel reads them (structure of arrays: the torsional stiffness of
//! lane `l` is `kw.0[l]`). A lane may hold any parameter set; what decides the
//! *shape* of the equations must be common to all lanes ([`LaneKey`]): the form
//! (spur, shaft or rigid), whether the fluctuation and the unbalance are present,
//! whether each mesh has a gap, and the friction law's kind. Within that shape every
//! number — stiffnesses, dampings, inertias, gaps, friction levels, the fluctuation
//! and unbalance terms — is per lane, so one `Kernel<L>` step advances `L` different
//! drives, and lane `l` computes bit for bit what a lone drive computes (the kernel
//! applies the same IEEE operations lane by lane; `tests/lanes.rs`).
//!
//! One drive alone is `LaneDrive<1>` ([`LaneDrive::splat`]); a batch of one model
//! (the frequencies of a sweep) is the same drive in every lane.

use super::drive::{Drive, Form};
use super::friction::lanes::LaneFriction;
use super::lanes::Lanes;

/// What lanes of one [`LaneDrive`] must share: the shape of the equations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LaneKey {
    form: Form,
    fluct: bool,
    unbalance: bool,
    /// Whether the spur mesh and the drive mesh have a gap (b > 0).
    gapped: [bool; 2],
    /// The friction law's kind (its [`DriveFriction`](super::friction::DriveFriction)
    /// variant).
    law: u8,
}

impl LaneKey {
    /// The shape of `d`'s equations.
    pub fn of(d: &Drive) -> Self {
        LaneKey {
            form: d.form,
            fluct: d.fluct,
            unbalance: d.unbalance,
            gapped: [d.spur && d.bg > 0.0, d.bw > 0.0],
            law: d.friction.kind(),
        }
    }
}

/// Lanes whose drives differ in the shape of their equations ([`LaneKey`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("lane {lane}'s drive differs from lane 0's in the shape of its equations (form, fluctuation, unbalance, gaps or friction law): lanes of one batch share it")]
pub struct LaneMismatch {
    pub lane: usize,
}

/// The lane-wise numeric fields, listed once: the struct, the gather and the
/// extraction of one lane follow from the list.
macro_rules! lane_drive {
    ($($field:ident),* $(,)?) => {
        /// `L` compiled drives of one shape (module docs). Each numeric field is the
        /// [`Drive`] field of the same name, one value per lane.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct LaneDrive<const L: usize> {
            pub(crate) form: Form,
            pub(crate) spur: bool,
            pub(crate) fluct: bool,
            pub(crate) unbalance: bool,
            /// Whether the spur mesh and the drive mesh have a gap in every lane.
            pub(crate) gapped: [bool; 2],
            pub(crate) friction: LaneFriction<L>,
            $(pub(crate) $field: Lanes<L>,)*
        }

        impl<const L: usize> LaneDrive<L> {
            /// The numeric fields of `drives`, lane by lane; shape from lane 0.
            fn gather_unchecked(drives: &[Drive; L], friction: LaneFriction<L>) -> Self {
                let d0 = &drives[0];
                LaneDrive {
                    form: d0.form,
                    spur: d0.spur,
                    fluct: d0.fluct,
                    unbalance: d0.unbalance,
                    gapped: [d0.spur && d0.bg > 0.0, d0.bw > 0.0],
                    friction,
                    $($field: Lanes(std::array::from_fn(|l| drives[l].$field)),)*
                }
            }

            /// Lane `l` alone.
            pub(crate) fn lane(&self, l: usize) -> LaneDrive<1> {
                LaneDrive {
                    form: self.form,
                    spur: self.spur,
                    fluct: self.fluct,
                    unbalance: self.unbalance,
                    gapped: self.gapped,
                    friction: self.friction.lane(l),
                    $($field: Lanes([self.$field.0[l]]),)*
                }
            }
        }
    };
}

lane_drive!(
    inv_jm, inv_jw, inv_jt, inv_mw, cm, cw, cb, ct, cig, ciw, kg, kw, kb, rg, rw, inv_r, bg, bw, w,
    n, phase, mge, psi,
);

impl<const L: usize> LaneDrive<L> {
    /// `drives[l]` in lane `l`; an error names the first lane whose shape differs
    /// from lane 0's.
    pub fn gather(drives: &[Drive; L]) -> Result<Self, LaneMismatch> {
        let key = LaneKey::of(&drives[0]);
        if let Some(lane) = drives.iter().position(|d| LaneKey::of(d) != key) {
            return Err(LaneMismatch { lane });
        }
        let friction = LaneFriction::gather(&std::array::from_fn(|l| drives[l].friction))
            .expect("one law kind: part of the key");
        Ok(Self::gather_unchecked(drives, friction))
    }

    /// `d` in every lane.
    pub fn splat(d: &Drive) -> Self {
        Self::gather(&[*d; L]).expect("one drive has one shape")
    }

    /// sin and cos of N·θ + φ of lane `l` by the library (kept out of line: a call
    /// inside the hot loop makes the compiler spill every live register around it).
    #[cold]
    #[inline(never)]
    pub(crate) fn exact_phase(&self, l: usize, shaft_angle: f64) -> (f64, f64) {
        (self.n.0[l] * shaft_angle + self.phase.0[l]).sin_cos()
    }

    /// Lane `l`'s fluctuation e, e' at `shaft_angle` from the phase (sin, cos) known
    /// at the nearby angle `base`: a rotation by the angle N·(θ − θ0), exact to
    /// rounding for the sub-step distances of one integration step.
    #[inline(always)]
    pub(crate) fn fluctuation_near(
        &self,
        l: usize,
        shaft_angle: f64,
        base: f64,
        (s0, c0): (f64, f64),
    ) -> (f64, f64) {
        let (w, n) = (self.w.0[l], self.n.0[l]);
        let (sx, cx) = super::drive::small_sin_cos(n * (shaft_angle - base));
        let (s, c) = (s0 * cx + c0 * sx, c0 * cx - s0 * sx);
        (w * s, w * n * c)
    }

    /// Tu = −m·g·e·sin(θt + ψ) of lane `l`. Out of line on purpose: inlined, the
    /// compiler may evaluate the `sin` for every stage and discard it when there is
    /// no unbalance.
    #[inline(never)]
    pub(crate) fn unbalance_torque(&self, l: usize, table_angle: f64) -> f64 {
        -self.mge.0[l] * (table_angle + self.psi.0[l]).sin()
    }

    /// sin and cos of θt + ψ of lane `l` by the library (out of line, as
    /// [`Self::exact_phase`]).
    #[cold]
    #[inline(never)]
    pub(crate) fn exact_unbalance(&self, l: usize, table_angle: f64) -> (f64, f64) {
        (table_angle + self.psi.0[l]).sin_cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{presets, Params};

    fn drive(p: &Params) -> Drive {
        Drive::new(p).unwrap()
    }

    #[test]
    fn lanes_hold_each_drive_and_give_it_back() {
        let p = presets::load("worm-gear").unwrap();
        let mut q = p.clone();
        q.kw *= 2.0;
        q.ft = 0.0;
        let lanes = LaneDrive::gather(&[drive(&p), drive(&q)]).unwrap();
        assert_eq!(lanes.kw.0, [p.kw, 2.0 * p.kw]);
        assert_eq!(lanes.lane(1), LaneDrive::splat(&drive(&q)));
    }

    #[test]
    fn a_lane_of_another_shape_is_refused_by_its_index() {
        let p = presets::load("worm-gear").unwrap();
        let mut gapless = p.clone();
        gapless.theta_bw = 0.0;
        let err = LaneDrive::gather(&[drive(&p), drive(&p), drive(&gapless)]).unwrap_err();
        assert_eq!(err.lane, 2);
        assert!(err.to_string().contains("lane 2"), "{err}");
        let mut stribeck = p.clone();
        (stribeck.fst, stribeck.vst) = (0.1, 0.5);
        assert!(LaneDrive::gather(&[drive(&p), drive(&stribeck)]).is_err());
    }
}
