//! Modal analysis of the linearised drive (docs/model.md §2, §11): mass, damping and
//! stiffness matrices, natural frequencies and mode shapes with the motor held and
//! free, the fastest rate of the damped system (for the kernel's step size) and the
//! exact linear frequency response of the paper's test (docs/experiments.md (frequency response)).
//!
//! Linearisation: no backlash (θb = 0), no Coulomb friction, no gear fluctuation
//! (W = 0), no unbalance. Generalized coordinates q = [θm, θw, xw, θt] (spur gear,
//! rad, rad, m, rad), [θm, xw, θt] (direct: the shaft is part of the motor body,
//! θw ≡ θm), [θm, θt] (two_mass) or [θt] (direct_drive: motor and table one body). The
//! potential of docs/model.md §2,
//!
//! ```text
//! V = ½Kg·(Rg·θm − θw)² + ½Kw·(Rw·θw + xw/r − θt)² + ½Kb·xw²
//!   = ½ qᵀ·(Kg·a·aᵀ + Kw·b·bᵀ + Kb·c·cᵀ)·q
//! a = [Rg, −1, 0, 0]   b = [0, Rw, 1/r, −1]   c = [0, 0, 1, 0]     (spur gear)
//!                      b = [Rw, 1/r, −1]       c = [0, 1, 0]        (direct)
//! M = diag(Jm, Jw, Mw, Jt)                    (direct: diag(Jm + Jw, Mw, Jt))
//! C = diag(Cm, Cw, Cb, Ct) + Cig·a·aᵀ + Ciw·b·bᵀ
//!                                             (direct: diag(Cm + Cw, Cb, Ct) + Ciw·b·bᵀ)
//! two_mass:     b = [1, −1]   M = diag(Jm, Jt)   K = Kw·b·bᵀ   C = diag(Cm, Ct) + Ciw·b·bᵀ
//! direct_drive: M = [Jt]      K = [0]            C = [Ct]
//! ```
//!
//! The two-mass drive's modes are the textbook pair: motor free √(Kw·(1/Jm + 1/Jt)),
//! motor held √(Kw/Jt) (the antiresonance of the motor's response and the peak of
//! table over motor). The direct drive has only its rigid-body mode: no natural
//! frequency, motor held or free, and a table/motor ratio of exactly 1.
//!
//! gives M·q'' + C·q' + K·q = F, the equations the kernel integrates once the meshes
//! are in contact. "Clamped" below means the motor held (θm ≡ 0: its row and column
//! removed), the condition whose modes the table/motor amplitude ratio peaks at;
//! "free" means the motor free, which adds the rigid-body mode at 0 Hz.

use std::f64::consts::PI;

use nalgebra::{Complex, DMatrix, DVector, SymmetricEigen};
use serde::Serialize;

use super::params::{ParamError, Params, Topology};

/// The linearised drive M·q'' + C·q' + K·q = F in generalized coordinates `dofs`.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearModel {
    /// Mass matrix (diagonal): kg·m² on angles, kg on xw.
    pub m: DMatrix<f64>,
    /// Damping matrix: N·m·s/rad on angles, N·s/m on xw (mixed entries N·s/rad).
    pub c: DMatrix<f64>,
    /// Stiffness matrix: N·m/rad on angles, N/m on xw (mixed entries N/rad).
    pub k: DMatrix<f64>,
    /// Name of each coordinate: `theta_m`, `theta_w`, `x_w`, `theta_t` (rad or m).
    pub dofs: Vec<&'static str>,
    /// Number of rigid-body (0 Hz) modes: 1 with the motor free (the whole drive
    /// turning, q ∝ [1, Rg, 0, Rg·Rw]; direct: [1, 0, Rw]), 0 with it held. Known from the structure of K
    /// (a, b, c are independent and every stiffness is positive), not guessed from the
    /// size of an eigenvalue: a very stiff mesh (Kg = 1e12) puts round-off of order
    /// ε·λmax on the zero eigenvalue, above any fixed fraction of λmax one could pick.
    pub rigid_modes: usize,
}

/// The fastest rate, rad/s, a model may have (≈ 16 MHz): a drive's modes lie below
/// 100 kHz; beyond this the parameters are a typo or a unit slip, and the integration
/// step would be below 1 ns.
pub const MAX_RATE: f64 = 1e8;

impl LinearModel {
    /// Validates `p` and builds the matrices of the module docs (motor free).
    pub fn new(p: &Params) -> Result<Self, ParamError> {
        p.validate()?;
        let inv_r = 1.0 / p.r;
        let outer = |v: &[f64]| {
            let v = DVector::from_column_slice(v);
            &v * v.transpose()
        };
        let diag = |v: &[f64]| DMatrix::from_diagonal(&DVector::from_column_slice(v));
        let model = match p.topology {
            Topology::SpurGear => {
                // validate() has checked that the spur-gear fields are present.
                let (rg, kg, cig) = (
                    p.rg.unwrap_or(1.0),
                    p.kg.unwrap_or(0.0),
                    p.cig.unwrap_or(0.0),
                );
                let a = outer(&[rg, -1.0, 0.0, 0.0]);
                let b = outer(&[0.0, p.rw, inv_r, -1.0]);
                let c = outer(&[0.0, 0.0, 1.0, 0.0]);
                LinearModel {
                    m: diag(&[p.jm, p.jw, p.mw, p.jt]),
                    c: diag(&[p.cm, p.cw, p.cb, p.ct]) + cig * &a + p.ciw * &b,
                    k: kg * a + p.kw * b + p.kb * c,
                    dofs: vec!["theta_m", "theta_w", "x_w", "theta_t"],
                    rigid_modes: 1,
                }
            }
            Topology::TwoMass => {
                let b = outer(&[1.0, -1.0]);
                LinearModel {
                    m: diag(&[p.jm, p.jt]),
                    c: diag(&[p.cm, p.ct]) + p.ciw * &b,
                    k: p.kw * b,
                    dofs: vec!["theta_m", "theta_t"],
                    rigid_modes: 1,
                }
            }
            Topology::DirectDrive => LinearModel {
                m: diag(&[p.jt]),
                c: diag(&[p.ct]),
                k: DMatrix::zeros(1, 1),
                dofs: vec!["theta_t"],
                rigid_modes: 1,
            },
            Topology::Direct => {
                let b = outer(&[p.rw, inv_r, -1.0]);
                let c = outer(&[0.0, 1.0, 0.0]);
                LinearModel {
                    m: diag(&[p.jm + p.jw, p.mw, p.jt]),
                    c: diag(&[p.cm + p.cw, p.cb, p.ct]) + p.ciw * &b,
                    k: p.kw * b + p.kb * c,
                    dofs: vec!["theta_m", "x_w", "theta_t"],
                    rigid_modes: 1,
                }
            }
        };
        model.check_rates()?;
        Ok(model)
    }

    /// Refuses a model whose stiffness or damping over inertia, at any coordinate,
    /// exceeds [`MAX_RATE`]: a bound on the fastest eigenvalue (Gershgorin's, cheap and
    /// always finite or infinite — never the eigen-solver's endless iteration on
    /// entries of 1e300), which no drive reaches and no integration step could follow.
    fn check_rates(&self) -> Result<(), ParamError> {
        for (i, dof) in self.dofs.iter().enumerate() {
            let m = self.m[(i, i)];
            let row = |a: &DMatrix<f64>| a.row(i).iter().map(|x| x.abs()).sum::<f64>() / m;
            let rate = row(&self.k).sqrt() + row(&self.c);
            if rate.is_nan() || rate > MAX_RATE {
                return Err(ParamError::TooFast {
                    coordinate: dof,
                    rate,
                    limit: MAX_RATE,
                });
            }
        }
        Ok(())
    }

    /// Number of degrees of freedom.
    pub fn n_dof(&self) -> usize {
        self.dofs.len()
    }

    /// Index of the coordinate named `name` (`theta_m`, `theta_w`, `x_w`, `theta_t`).
    pub fn index(&self, name: &str) -> Option<usize> {
        self.dofs.iter().position(|d| *d == name)
    }

    /// The model with the motor held (θm ≡ 0): row and column of θm removed. For the
    /// direct drive, whose table is the motor, nothing is left to move: an empty model.
    pub fn motor_held(&self) -> LinearModel {
        let Some(i) = self.index("theta_m") else {
            return LinearModel {
                m: DMatrix::zeros(0, 0),
                c: DMatrix::zeros(0, 0),
                k: DMatrix::zeros(0, 0),
                dofs: Vec::new(),
                rigid_modes: 0,
            };
        };
        LinearModel {
            m: self.m.clone().remove_row(i).remove_column(i),
            c: self.c.clone().remove_row(i).remove_column(i),
            k: self.k.clone().remove_row(i).remove_column(i),
            dofs: self
                .dofs
                .iter()
                .copied()
                .filter(|d| *d != "theta_m")
                .collect(),
            rigid_modes: 0,
        }
    }

    /// Undamped natural frequencies, Hz (ascending, the [`rigid_modes`](Self::rigid_modes)
    /// lowest omitted), and their mode shapes over [`dofs`](Self::dofs), each scaled so
    /// that its largest component is +1 (components in rad, `x_w` in m, compared as
    /// plain numbers).
    ///
    /// Solves K·φ = ω²·M·φ as the symmetric problem (L⁻¹·K·L⁻¹)·v = ω²·v with
    /// L = M^½ (M is diagonal), φ = L⁻¹·v.
    pub fn natural_modes(&self) -> (Vec<f64>, Vec<Vec<f64>>) {
        if self.n_dof() == 0 {
            return (Vec::new(), Vec::new());
        }
        let inv_sqrt_m = self.m.diagonal().map(|m| 1.0 / m.sqrt());
        let l_inv = DMatrix::from_diagonal(&inv_sqrt_m);
        let a = &l_inv * &self.k * &l_inv;
        // Symmetrise against round-off: the solver reads only one triangle.
        let a = 0.5 * (&a + a.transpose());
        let eig = SymmetricEigen::new(a);
        let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
        order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
        order
            .into_iter()
            .skip(self.rigid_modes)
            .map(|j| {
                let phi = &l_inv * eig.eigenvectors.column(j);
                let peak = phi
                    .iter()
                    .fold(0.0_f64, |p, &x| if x.abs() > p.abs() { x } else { p });
                let hz = eig.eigenvalues[j].max(0.0).sqrt() / (2.0 * PI);
                (hz, phi.iter().map(|x| x / peak).collect::<Vec<f64>>())
            })
            .unzip()
    }

    /// The first-order system matrix [[0, I], [−M⁻¹·K, −M⁻¹·C]] of the state [q, q'].
    pub fn state_matrix(&self) -> DMatrix<f64> {
        let n = self.n_dof();
        let m_inv = DMatrix::from_diagonal(&self.m.diagonal().map(|m| 1.0 / m));
        let mut s = DMatrix::zeros(2 * n, 2 * n);
        s.view_mut((0, n), (n, n)).fill_with_identity();
        s.view_mut((n, 0), (n, n)).copy_from(&(-&m_inv * &self.k));
        s.view_mut((n, n), (n, n)).copy_from(&(-&m_inv * &self.c));
        s
    }

    /// Complex amplitudes X of the steady response to the force amplitudes `f` at
    /// `omega` rad/s: (K − ω²·M + iω·C)·X = F, solved by LU. `None` if singular
    /// (ω = 0 on the free model).
    pub fn response(&self, omega: f64, f: &DVector<Complex<f64>>) -> Option<DVector<Complex<f64>>> {
        let z = self.k.map(|x| Complex::new(x, 0.0))
            - self.m.map(|x| Complex::new(omega * omega * x, 0.0))
            + self.c.map(|x| Complex::new(0.0, omega * x));
        z.lu().solve(f)
    }
}

/// Natural frequencies and mode shapes of the linearised drive, motor held and free.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Modes {
    /// Motor held: natural frequencies, Hz, ascending.
    pub clamped_hz: Vec<f64>,
    /// Motor free: natural frequencies, Hz, ascending, the 0 Hz rigid-body mode omitted.
    pub free_hz: Vec<f64>,
    /// Motor held: mode shape of each frequency over `clamped_dofs`, largest component +1.
    pub clamped_shapes: Vec<Vec<f64>>,
    /// Motor free: mode shape of each frequency over `free_dofs`, largest component +1.
    pub free_shapes: Vec<Vec<f64>>,
    /// Coordinates of the clamped shapes (rad, `x_w` in m).
    pub clamped_dofs: Vec<&'static str>,
    /// Coordinates of the free shapes (rad, `x_w` in m).
    pub free_dofs: Vec<&'static str>,
}

/// Undamped natural frequencies and mode shapes of `p`, motor held and free.
pub fn modes(p: &Params) -> Result<Modes, ParamError> {
    let free = LinearModel::new(p)?;
    let clamped = free.motor_held();
    let (clamped_hz, clamped_shapes) = clamped.natural_modes();
    let (free_hz, free_shapes) = free.natural_modes();
    Ok(Modes {
        clamped_hz,
        free_hz,
        clamped_shapes,
        free_shapes,
        clamped_dofs: clamped.dofs,
        free_dofs: free.dofs,
    })
}

/// The largest |λ|, rad/s, of the eigenvalues of the damped first-order system of the
/// free linear model ([`LinearModel::state_matrix`]). RK4 is stable for |λ|·dt ≲ 2.8;
/// accuracy wants it well below 1.
///
/// The Schur iteration is capped ([`SCHUR_ITERATIONS`]): nalgebra's uncapped
/// `complex_eigenvalues` never returns on some lightly damped state matrices (met on
/// a two-mass fit whose coupling damping sat at its bound). Where the cap is reached
/// the rate is bounded by the matrix's largest absolute row sum, which no eigenvalue
/// exceeds: a shorter step than needed, never an unstable one.
pub fn max_rate(p: &Params) -> Result<f64, ParamError> {
    let s = LinearModel::new(p)?.state_matrix();
    let bound = s
        .row_iter()
        .map(|r| r.iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    Ok(match s.try_schur(f64::EPSILON, SCHUR_ITERATIONS) {
        Some(schur) => schur
            .complex_eigenvalues()
            .iter()
            .fold(0.0, |m: f64, l| m.max(l.norm())),
        None => bound,
    })
}

/// Most iterations of the Schur decomposition in [`max_rate`] (a 10-state matrix
/// converges in tens).
pub const SCHUR_ITERATIONS: usize = 10_000;

/// The linear frequency response of the paper's test (docs/experiments.md (frequency response)): for a unit motor
/// torque at each frequency of `freqs_hz` (Hz, > 0), the complex ratio
/// X_θt / (X_θm·Rg·Rw) of table to motor amplitude; its gain is 20·log10|·| dB. It
/// tends to 1 at low frequency and peaks near the clamped (motor-held) modes. A
/// frequency where the system is singular (0 Hz: the free drive has no static
/// stiffness) gives NaN.
pub fn frequency_response(p: &Params, freqs_hz: &[f64]) -> Result<Vec<Complex<f64>>, ParamError> {
    let model = LinearModel::new(p)?;
    let n = model.n_dof();
    // The direct drive's one coordinate is both motor and table angle.
    let it = model.index("theta_t").expect("every topology has theta_t");
    let im = model.index("theta_m").unwrap_or(it);
    let mut f = DVector::from_element(n, Complex::new(0.0, 0.0));
    f[im] = Complex::new(1.0, 0.0);
    let ratio = p.ratio();
    Ok(freqs_hz
        .iter()
        .map(|&hz| match model.response(2.0 * PI * hz, &f) {
            Some(x) => x[it] / (x[im] * ratio),
            None => Complex::new(f64::NAN, f64::NAN),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn preset(name: &str) -> Params {
        presets::load(name).unwrap()
    }

    fn assert_hz(got: &[f64], want: &[f64], tol: f64, what: &str) {
        assert_eq!(got.len(), want.len(), "{what}: {got:?} vs {want:?}");
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() <= tol, "{what}: {got:?} vs {want:?} (±{tol})");
        }
    }

    /// Eigenvalues ω² of a 2-DOF system diag(m1, m2), [[k11, k12], [k12, k22]], in Hz.
    fn two_dof_hz(m1: f64, m2: f64, k11: f64, k12: f64, k22: f64) -> [f64; 2] {
        let (p, q) = (k11 / m1, k22 / m2);
        let root = ((p - q).powi(2) + 4.0 * k12 * k12 / (m1 * m2)).sqrt();
        [(p + q - root) / 2.0, (p + q + root) / 2.0].map(|l| l.sqrt() / (2.0 * PI))
    }

    fn gain_db(p: &Params, freqs: &[f64]) -> Vec<f64> {
        frequency_response(p, freqs)
            .unwrap()
            .iter()
            .map(|h| 20.0 * h.norm().log10())
            .collect()
    }

    fn scale_damping(p: &mut Params, s: f64) {
        p.cm *= s;
        p.cw *= s;
        p.cb *= s;
        p.ct *= s;
        p.ciw *= s;
        p.cig = p.cig.map(|c| c * s);
    }

    #[test]
    fn worm_preset_matches_the_reference_modes_of_model_md() {
        let m = modes(&preset("worm-gear")).unwrap();
        assert_hz(&m.clamped_hz, &[186.5, 236.9, 1510.7], 0.1, "clamped");
        assert_hz(&m.free_hz, &[192.0, 253.0, 1510.7], 0.1, "free");
        assert_eq!(m.clamped_dofs, ["theta_w", "x_w", "theta_t"]);
        assert_eq!(m.free_dofs, ["theta_m", "theta_w", "x_w", "theta_t"]);
        let json = serde_json::to_value(&m).unwrap();
        assert_eq!(json["free_dofs"][3], "theta_t");
        assert_eq!(json["clamped_shapes"].as_array().unwrap().len(), 3);
    }

    #[test]
    fn roller_preset_matches_the_reference_modes_of_model_md() {
        let m = modes(&preset("roller-gear-cam")).unwrap();
        assert_hz(&m.clamped_hz, &[166.9, 932.0], 0.1, "clamped");
        assert_eq!(m.free_hz.len(), 2, "{:?}", m.free_hz);
        assert_eq!(m.free_dofs, ["theta_m", "x_w", "theta_t"]);
    }

    #[test]
    fn direct_drive_held_is_the_closed_form_two_mass_system() {
        // Motor held: xw and θt, K = [[Kw/r² + Kb, −Kw/r], [−Kw/r, Kw]].
        let p = preset("roller-gear-cam");
        let want = two_dof_hz(p.mw, p.jt, p.kw / (p.r * p.r) + p.kb, -p.kw / p.r, p.kw);
        let got = modes(&p).unwrap().clamped_hz;
        assert_hz(&got, &want, 1e-9 * want[1], "roller held");
    }

    #[test]
    fn spur_drive_held_with_a_rigid_bearing_is_the_closed_form_shaft_table_pair() {
        // Kb → ∞ pins xw; motor held leaves θw and θt:
        // K = [[Kg + Kw·Rw², −Kw·Rw], [−Kw·Rw, Kw]], M = diag(Jw, Jt).
        let mut p = preset("worm-gear");
        p.kb = 1e14;
        let (kg, rw) = (p.kg.unwrap(), p.rw);
        let want = two_dof_hz(p.jw, p.jt, kg + p.kw * rw * rw, -p.kw * rw, p.kw);
        let got = modes(&p).unwrap().clamped_hz;
        assert_eq!(got.len(), 3);
        assert_hz(&got[..2], &want, 1e-5 * want[0], "worm held, rigid bearing");
        assert!(got[2] > 1e5, "the axial mode goes to infinity: {got:?}");
    }

    #[test]
    fn mode_shapes_are_mass_and_stiffness_orthogonal_and_solve_the_eigenproblem() {
        for name in ["worm-gear", "roller-gear-cam"] {
            let free = LinearModel::new(&preset(name)).unwrap();
            let clamped = free.motor_held();
            for model in [&free, &clamped] {
                let (hz, shapes) = model.natural_modes();
                let phi: Vec<DVector<f64>> = shapes
                    .iter()
                    .map(|s| DVector::from_column_slice(s))
                    .collect();
                for (i, (fi, pi)) in hz.iter().zip(&phi).enumerate() {
                    assert!((pi.amax() - 1.0).abs() < 1e-12, "{name}: unit max-abs");
                    let w2 = (2.0 * PI * fi).powi(2);
                    let residual = &model.k * pi - w2 * (&model.m * pi);
                    assert!(residual.norm() <= 1e-9 * (&model.k * pi).norm(), "{name}");
                    let mi = pi.dot(&(&model.m * pi));
                    for pj in &phi[i + 1..] {
                        let mj = pj.dot(&(&model.m * pj));
                        let mij = pi.dot(&(&model.m * pj));
                        assert!(mij.abs() <= 1e-9 * (mi * mj).sqrt(), "{name}: {mij}");
                    }
                }
            }
            // The elastic free modes carry no momentum of the omitted rigid-body mode
            // r = [1, Rg, 0, Rg·Rw] (direct: [1, 0, Rw]), for which K·r = 0.
            let p = preset(name);
            let r = match p.topology {
                Topology::SpurGear => {
                    let rg = p.rg.unwrap();
                    DVector::from_vec(vec![1.0, rg, 0.0, rg * p.rw])
                }
                Topology::Direct => DVector::from_vec(vec![1.0, 0.0, p.rw]),
                Topology::TwoMass => DVector::from_vec(vec![1.0, 1.0]),
                Topology::DirectDrive => DVector::from_vec(vec![1.0]),
            };
            assert!((&free.k * &r).norm() < 1e-9 * free.k.norm());
            let mr = r.dot(&(&free.m * &r));
            for s in free.natural_modes().1 {
                let s = DVector::from_vec(s);
                let ms = s.dot(&(&free.m * &s));
                assert!(s.dot(&(&free.m * &r)).abs() <= 1e-9 * (mr * ms).sqrt());
            }
        }
    }

    #[test]
    fn direct_drive_is_the_limit_of_a_rigid_one_to_one_spur_stage() {
        let mut spur = preset("worm-gear");
        spur.rg = Some(1.0);
        spur.kg = Some(1e12);
        let mut direct = spur.clone();
        direct.topology = Topology::Direct;
        (direct.kg, direct.rg, direct.cig, direct.theta_bg) = (None, None, None, None);
        direct.ranges.remove("theta_bg");

        let s = modes(&spur).unwrap();
        let d = modes(&direct).unwrap();
        assert_eq!(d.free_hz.len(), 2);
        assert_eq!(s.free_hz.len(), 3);
        assert!(
            s.free_hz[2] > 1e5,
            "the spur mesh mode is pushed out: {s:?}"
        );
        assert_hz(&s.free_hz[..2], &d.free_hz, 1e-6 * d.free_hz[1], "free");
        // Shapes: the spur model's θw moves with θm and drops out.
        for (ss, ds) in s.free_shapes.iter().zip(&d.free_shapes) {
            assert!((ss[0] - ss[1]).abs() < 1e-6, "θw ≡ θm: {ss:?}");
            let reduced = [ss[0], ss[2], ss[3]];
            for (a, b) in reduced.iter().zip(ds) {
                assert!((a - b).abs() < 1e-6, "{reduced:?} vs {ds:?}");
            }
        }
    }

    #[test]
    fn response_peaks_at_the_motor_held_modes_not_the_free_ones() {
        for name in ["worm-gear", "roller-gear-cam"] {
            let mut p = preset(name);
            scale_damping(&mut p, 0.01);
            let freqs: Vec<f64> = (0..=4000).map(|i| 100.0 + 0.05 * i as f64).collect();
            let g = gain_db(&p, &freqs);
            let peaks: Vec<f64> = (1..g.len() - 1)
                .filter(|&i| g[i] > g[i - 1] && g[i] > g[i + 1])
                .map(|i| freqs[i])
                .collect();
            let m = modes(&p).unwrap();
            let in_scan: Vec<f64> = m
                .clamped_hz
                .iter()
                .copied()
                .filter(|f| (100.0..=300.0).contains(f))
                .collect();
            assert!(!in_scan.is_empty());
            assert_eq!(peaks.len(), in_scan.len(), "{name}: peaks {peaks:?}");
            for (peak, mode) in peaks.iter().zip(&in_scan) {
                assert!(
                    (peak - mode).abs() < 1.0,
                    "{name}: {peaks:?} vs {in_scan:?}"
                );
            }
        }
    }

    #[test]
    fn response_is_rigid_at_low_frequency() {
        for name in ["worm-gear", "roller-gear-cam"] {
            let g = gain_db(&preset(name), &[1.0])[0];
            assert!(g.abs() < 0.1, "{name}: {g} dB at 1 Hz");
        }
    }

    #[test]
    fn max_rate_is_the_top_mode_when_undamped_and_the_system_is_stable() {
        for name in ["worm-gear", "roller-gear-cam"] {
            let mut p = preset(name);
            let top = 2.0 * PI * modes(&p).unwrap().free_hz.last().unwrap();
            let damped = max_rate(&p).unwrap();
            assert!(
                (damped - top).abs() < 1e-3 * top,
                "{name}: {damped} vs {top}"
            );
            let s = LinearModel::new(&p).unwrap().state_matrix();
            for l in s.complex_eigenvalues().iter() {
                assert!(l.re <= 1e-9 * damped, "{name}: unstable eigenvalue {l}");
            }
            scale_damping(&mut p, 0.0);
            let undamped = max_rate(&p).unwrap();
            assert!(
                (undamped - top).abs() < 1e-9 * top,
                "{name}: {undamped} vs {top}"
            );
        }
    }

    #[test]
    fn max_rate_returns_on_the_two_mass_fit_that_stalled_the_uncapped_schur() {
        // The linear fit of a two-mass response with an unstated 2 ms delay (coupling
        // damping at its lower bound): nalgebra's uncapped iteration never returned.
        let mut p = preset("two-mass");
        p.kw = 22.810538169381644;
        p.ciw = 0.00014000017705474352;
        let rate = max_rate(&p).unwrap();
        let free = (p.kw * (1.0 / p.jm + 1.0 / p.jt)).sqrt();
        assert!(
            rate >= free * (1.0 - 1e-6) && rate.is_finite(),
            "{rate} vs {free}"
        );
    }

    #[test]
    fn invalid_parameters_are_reported_not_analysed() {
        let mut p = preset("worm-gear");
        p.kw = 0.0;
        assert!(matches!(
            modes(&p),
            Err(ParamError::NotPositive { name: "Kw", .. })
        ));
        assert!(max_rate(&p).is_err());
        assert!(frequency_response(&p, &[100.0]).is_err());
    }

    #[test]
    fn two_mass_modes_are_the_textbook_pair() {
        let p = preset("two-mass");
        let m = modes(&p).unwrap();
        let held = (p.kw / p.jt).sqrt() / (2.0 * PI);
        let free = (p.kw * (1.0 / p.jm + 1.0 / p.jt)).sqrt() / (2.0 * PI);
        assert_hz(&m.clamped_hz, &[held], 1e-9 * held, "held");
        assert_hz(&m.free_hz, &[free], 1e-9 * free, "free");
        // The FdiTools bench: 53.5–53.9 Hz and 76.2 Hz.
        assert!((held - 53.97).abs() < 0.01 && (free - 76.33).abs() < 0.01);
        // Motor free: motor and table swing against each other, momentum zero.
        let shape = &m.free_shapes[0];
        assert!((p.jm * shape[0] + p.jt * shape[1]).abs() < 1e-9);
        // The linear gain of table over motor peaks at the held mode.
        let mut light = p.clone();
        scale_damping(&mut light, 0.01);
        let freqs: Vec<f64> = (0..=2000).map(|i| 40.0 + 0.01 * i as f64).collect();
        let g = gain_db(&light, &freqs);
        let peak = (1..g.len() - 1)
            .filter(|&i| g[i] > g[i - 1] && g[i] > g[i + 1])
            .map(|i| freqs[i])
            .collect::<Vec<_>>();
        assert_eq!(peak.len(), 1, "{peak:?}");
        assert!((peak[0] - held).abs() < 0.02, "{peak:?} vs {held}");
    }

    #[test]
    fn the_direct_drive_has_only_its_rigid_body_mode() {
        let p = preset("direct-drive");
        let m = modes(&p).unwrap();
        assert!(m.clamped_hz.is_empty() && m.free_hz.is_empty(), "{m:?}");
        assert_eq!(m.free_dofs, ["theta_t"]);
        // Table and motor are one: the gain is 0 dB at every frequency.
        for h in frequency_response(&p, &[1.0, 100.0, 1000.0]).unwrap() {
            assert!((h.norm() - 1.0).abs() < 1e-12 && h.im.abs() < 1e-12, "{h}");
        }
        // The only rate is the viscous decay Ct/Jt.
        let rate = max_rate(&p).unwrap();
        assert!((rate - p.ct / p.jt).abs() < 1e-12 * rate, "{rate}");
    }
}
