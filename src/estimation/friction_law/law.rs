//! The four laws rtid fits to a map ([`Law`]): their parameters, values and gradients
//! with respect to the reported parameters.

use std::fmt;

use serde::{Deserialize, Serialize};

/// A friction law of a steady-speed map (the module documentation gives the equations).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Law {
    /// T = Fc·sgn(v) + Fv·v + Fo.
    Coulomb,
    /// T = sgn(v)·(Fc + (Fs − Fc)·exp(−(|v|/vs)^delta)) + Fv·v + Fo.
    Stribeck,
    /// T = Fc_pos + Fv_pos·v for v > 0, −Fc_neg + Fv_neg·v for v < 0.
    CoulombAsymmetric,
    /// A Stribeck curve per direction with a shared delta, no offset.
    StribeckAsymmetric,
}

/// What a parameter is, which sets its unit and how the fit scales it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// An effort, N·m or N (Fc, Fs, Fo).
    Effort,
    /// A viscous coefficient, N·m·s/rad or N·s/m (Fv).
    Viscous,
    /// A speed, rad/s or m/s, > 0 (vs).
    Speed,
    /// A dimensionless exponent, > 0 (delta).
    Exponent,
}

impl Law {
    /// Every law, simplest first.
    pub const ALL: [Law; 4] = [
        Law::Coulomb,
        Law::Stribeck,
        Law::CoulombAsymmetric,
        Law::StribeckAsymmetric,
    ];

    /// The law's name, as in JSON (`coulomb`, `stribeck_asymmetric`…).
    pub fn name(self) -> &'static str {
        match self {
            Law::Coulomb => "coulomb",
            Law::Stribeck => "stribeck",
            Law::CoulombAsymmetric => "coulomb_asymmetric",
            Law::StribeckAsymmetric => "stribeck_asymmetric",
        }
    }

    /// The law of a name ([`Law::name`]).
    pub fn from_name(name: &str) -> Option<Law> {
        Law::ALL.into_iter().find(|l| l.name() == name)
    }

    /// The parameters' names, in the order of the values.
    pub fn parameters(self) -> &'static [&'static str] {
        match self {
            Law::Coulomb => &["Fc", "Fv", "Fo"],
            Law::Stribeck => &["Fc", "Fs", "vs", "delta", "Fv", "Fo"],
            Law::CoulombAsymmetric => &["Fc_pos", "Fv_pos", "Fc_neg", "Fv_neg"],
            Law::StribeckAsymmetric => &[
                "Fc_pos", "Fs_pos", "vs_pos", "Fv_pos", "Fc_neg", "Fs_neg", "vs_neg", "Fv_neg",
                "delta",
            ],
        }
    }

    /// Whether the law is fitted by nonlinear least squares (and needs at least 3
    /// distinct speeds per direction).
    pub fn is_stribeck(self) -> bool {
        matches!(self, Law::Stribeck | Law::StribeckAsymmetric)
    }

    /// What each parameter is, in the order of the values.
    pub fn quantities(self) -> &'static [Quantity] {
        use Quantity::{Effort as E, Exponent as X, Speed as S, Viscous as V};
        match self {
            Law::Coulomb => &[E, V, E],
            Law::Stribeck => &[E, E, S, X, V, E],
            Law::CoulombAsymmetric => &[E, V, E, V],
            Law::StribeckAsymmetric => &[E, E, S, V, E, E, S, V, X],
        }
    }

    /// The effort at speed `v` (≠ 0) with `values` in the order of
    /// [`Law::parameters`]. Panics if `values` holds fewer.
    pub fn evaluate(self, values: &[f64], v: f64) -> f64 {
        let p = values;
        let s = v.signum();
        match self {
            Law::Coulomb => p[0] * s + p[1] * v + p[2],
            Law::Stribeck => s * curve(p[0], p[1], p[2], p[3], v.abs()).value + p[4] * v + p[5],
            Law::CoulombAsymmetric if v > 0.0 => p[0] + p[1] * v,
            Law::CoulombAsymmetric => -p[2] + p[3] * v,
            Law::StribeckAsymmetric if v > 0.0 => curve(p[0], p[1], p[2], p[8], v).value + p[3] * v,
            Law::StribeckAsymmetric => -curve(p[4], p[5], p[6], p[8], -v).value + p[7] * v,
        }
    }

    /// The derivatives of [`Law::evaluate`] at `v` with respect to each value, into
    /// `out` (as long as the values).
    pub fn gradient(self, values: &[f64], v: f64, out: &mut [f64]) {
        let p = values;
        let s = v.signum();
        out.fill(0.0);
        match self {
            Law::Coulomb => out.copy_from_slice(&[s, v, 1.0]),
            Law::Stribeck => {
                let c = curve(p[0], p[1], p[2], p[3], v.abs());
                out.copy_from_slice(&[s * c.fc, s * c.fs, s * c.vs, s * c.delta, v, 1.0]);
            }
            Law::CoulombAsymmetric if v > 0.0 => (out[0], out[1]) = (1.0, v),
            Law::CoulombAsymmetric => (out[2], out[3]) = (-1.0, v),
            Law::StribeckAsymmetric if v > 0.0 => {
                let c = curve(p[0], p[1], p[2], p[8], v);
                (out[0], out[1], out[2], out[3], out[8]) = (c.fc, c.fs, c.vs, v, c.delta);
            }
            Law::StribeckAsymmetric => {
                let c = curve(p[4], p[5], p[6], p[8], -v);
                (out[4], out[5], out[6], out[7], out[8]) = (-c.fc, -c.fs, -c.vs, v, -c.delta);
            }
        }
    }
}

impl fmt::Display for Law {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The Stribeck magnitude C = Fc + (Fs − Fc)·exp(−(u/vs)^delta) at a speed u > 0 and
/// its derivatives with respect to Fc, Fs, vs and delta.
pub(super) struct Curve {
    pub value: f64,
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub delta: f64,
}

/// [`Curve`] at u > 0. Where exp(−(u/vs)^delta) underflows to 0 the curve is flat in
/// vs and delta (their derivatives are 0, not 0·∞).
pub(super) fn curve(fc: f64, fs: f64, vs: f64, delta: f64, u: f64) -> Curve {
    let x = u / vs;
    let xd = x.powf(delta);
    let g = (-xd).exp();
    let rise = fs - fc;
    let (d_vs, d_delta) = if g > 0.0 && xd.is_finite() {
        (rise * g * delta * xd / vs, -rise * g * xd * x.ln())
    } else {
        (0.0, 0.0)
    };
    Curve {
        value: fc + rise * g,
        fc: 1.0 - g,
        fs: g,
        vs: d_vs,
        delta: d_delta,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(law: Law) -> Vec<f64> {
        match law {
            Law::Coulomb => vec![2e-3, 1e-4, 2e-4],
            Law::Stribeck => vec![2e-3, 3.5e-3, 1.5, 1.3, 1e-4, 2e-4],
            Law::CoulombAsymmetric => vec![2e-3, 1e-4, 1.5e-3, 1.2e-4],
            Law::StribeckAsymmetric => {
                vec![2e-3, 3e-3, 1.2, 1e-4, 1.5e-3, 3.5e-3, 2.0, 1.2e-4, 1.4]
            }
        }
    }

    /// The analytic gradient against central differences, at speeds either side.
    #[test]
    fn gradients_match_finite_differences() {
        for law in Law::ALL {
            let p = values(law);
            assert_eq!(p.len(), law.parameters().len());
            assert_eq!(p.len(), law.quantities().len());
            let mut g = vec![0.0; p.len()];
            for v in [-17.0, -1.3, -0.2, 0.25, 1.1, 20.0] {
                law.gradient(&p, v, &mut g);
                for j in 0..p.len() {
                    let h = 1e-6 * p[j].abs();
                    let (mut up, mut down) = (p.clone(), p.clone());
                    up[j] += h;
                    down[j] -= h;
                    let fd = (law.evaluate(&up, v) - law.evaluate(&down, v)) / (2.0 * h);
                    // Truncation error (relative) and rounding of the effort over h.
                    let rounding = 1e3 * f64::EPSILON * law.evaluate(&p, v).abs() / h;
                    assert!(
                        (fd - g[j]).abs() < 1e-6 * g[j].abs() + rounding,
                        "{law} {} at {v}: {} vs {fd}",
                        law.parameters()[j],
                        g[j]
                    );
                }
            }
        }
    }

    #[test]
    fn the_laws_meet_at_their_special_cases() {
        // Stribeck with Fs = Fc is Coulomb; the asymmetric laws with mirrored values
        // and an offset are the symmetric ones.
        let (fc, fv, fo) = (2e-3, 1e-4, 2e-4);
        for v in [-20.0, -0.3, 0.3, 20.0] {
            let coulomb = Law::Coulomb.evaluate(&[fc, fv, fo], v);
            let stribeck = Law::Stribeck.evaluate(&[fc, fc, 1.0, 2.0, fv, fo], v);
            let asym = Law::CoulombAsymmetric.evaluate(&[fc + fo, fv, fc - fo, fv], v);
            assert!((stribeck - coulomb).abs() < 1e-18 && (asym - coulomb).abs() < 1e-18);
            let s = Law::Stribeck.evaluate(&[fc, 3e-3, 1.5, 1.3, fv, fo], v);
            let sa = Law::StribeckAsymmetric.evaluate(
                &[
                    fc + fo,
                    3e-3 + fo,
                    1.5,
                    fv,
                    fc - fo,
                    3e-3 - fo,
                    1.5,
                    fv,
                    1.3,
                ],
                v,
            );
            assert!((s - sa).abs() < 1e-18, "{s} {sa}");
        }
    }

    #[test]
    fn far_beyond_the_rise_the_gradient_stays_finite() {
        let c = curve(2e-3, 3e-3, 1e-3, 50.0, 20.0);
        assert_eq!((c.value, c.vs, c.delta), (2e-3, 0.0, 0.0));
        assert_eq!(
            Law::from_name("stribeck_asymmetric"),
            Some(Law::StribeckAsymmetric)
        );
        assert_eq!(Law::from_name("viscous"), None);
    }
}
