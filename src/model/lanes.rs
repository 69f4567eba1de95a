//! Lane-wise arithmetic for the kernel: `L` independent `f64` values (one per
//! trajectory) combined element by element. Every operation is a plain loop over a
//! `[f64; L]` without branches or calls, which the compiler turns into vector
//! instructions (two AVX2 registers for `L = 8`); decisions are made with
//! [`Lanes::zip`]-style selects, never with per-lane control flow.
//!
//! The operations are exactly the scalar IEEE operations applied to each lane (no
//! reassociation, no fused multiply-add), so lane `l` of an `L`-lane computation is
//! bit for bit the same as the scalar computation on lane `l` alone.

use std::ops::{Add, Mul, Neg, Sub};

/// `L` lanes of `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lanes<const L: usize>(pub [f64; L]);

impl<const L: usize> Lanes<L> {
    /// The same value in every lane.
    #[inline(always)]
    pub(crate) fn splat(x: f64) -> Self {
        Lanes([x; L])
    }

    /// `f` applied to every lane.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        let mut out = self.0;
        for v in &mut out {
            *v = f(*v);
        }
        Lanes(out)
    }

    /// `f` applied lane by lane to `self` and `b`. (Indexed loops on purpose: in
    /// this form the compiler vectorised the kernel best; measured.)
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    pub fn zip(self, b: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut out = self.0;
        for l in 0..L {
            out[l] = f(out[l], b.0[l]);
        }
        Lanes(out)
    }

    /// Whether `f` holds for any lane (evaluated for all, without early exit, so the
    /// test vectorises).
    #[inline(always)]
    pub fn any(self, f: impl Fn(f64) -> bool) -> bool {
        let mut any = false;
        for v in self.0 {
            any |= f(v);
        }
        any
    }
}

impl<const L: usize> Add for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        self.zip(b, |a, b| a + b)
    }
}

impl<const L: usize> Sub for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        self.zip(b, |a, b| a - b)
    }
}

impl<const L: usize> Mul for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        self.zip(b, |a, b| a * b)
    }
}

impl<const L: usize> Neg for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.map(|a| -a)
    }
}

impl<const L: usize> Add<f64> for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, b: f64) -> Self {
        self.map(|a| a + b)
    }
}

impl<const L: usize> Sub<f64> for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, b: f64) -> Self {
        self.map(|a| a - b)
    }
}

impl<const L: usize> Mul<f64> for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: f64) -> Self {
        self.map(|a| a * b)
    }
}

impl<const L: usize> Add<Lanes<L>> for f64 {
    type Output = Lanes<L>;
    #[inline(always)]
    fn add(self, b: Lanes<L>) -> Lanes<L> {
        b.map(|b| self + b)
    }
}

impl<const L: usize> Sub<Lanes<L>> for f64 {
    type Output = Lanes<L>;
    #[inline(always)]
    fn sub(self, b: Lanes<L>) -> Lanes<L> {
        b.map(|b| self - b)
    }
}

impl<const L: usize> Mul<Lanes<L>> for f64 {
    type Output = Lanes<L>;
    #[inline(always)]
    fn mul(self, b: Lanes<L>) -> Lanes<L> {
        b.map(|b| self * b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operations_act_lane_by_lane_in_the_written_order() {
        let a = Lanes([1.0, -2.0, 3.0, 0.5]);
        let b = Lanes([4.0, 5.0, -6.0, 0.25]);
        assert_eq!((a + b).0, [5.0, 3.0, -3.0, 0.75]);
        assert_eq!((2.0 * a - b * 0.5).0, [0.0, -6.5, 9.0, 0.875]);
        assert_eq!((-a).0, [-1.0, 2.0, -3.0, -0.5]);
        assert_eq!(a.zip(b, f64::max).0, [4.0, 5.0, 3.0, 0.5]);
        assert!(a.any(|x| x < 0.0) && !a.any(|x| x > 3.0));
    }
}
