//! The periodic estimate on a synthetic two-mass drive with a weak cubic nonlinearity:
//! a random-odd, random-phase multisine current i (5–200 Hz, 1 Hz lines, 9 periods of
//! 1 s at 1 kHz, 1 A rms) drives a torque T = i + a·i³ (a torque constant that stiffens
//! slightly: a Hammerstein system), the motor angle is θm = G·T with G the two-mass
//! motor response (docs/model.md §1; antiresonance 54 Hz, resonance 76 Hz), plus noise.
//!
//! The truth is the best linear approximation (Pintelon & Schoukens 2012, ch. 3): for
//! a multisine of line amplitude A and power σ² = mean(i²), the part of i³ coherent with
//! the line itself is (3σ² − 3A²/4)·i at that line, so BLA = G·(1 + 3a·(σ² − A²/4)). The
//! rest of the distortion falls on the odd lines, excited or not, at random from line to
//! line but the same every period; no even line gets any (an odd multisine through an
//! odd nonlinearity).
//!
//! Noise: a torque disturbance seen through G, complex Gaussian at every line, new in
//! every period, 0.3 % of the line amplitude (made in the frequency domain period by
//! period, so that the test is about the estimator, not about leakage).

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rtid::estimation::periodic::estimate::{h1, FrfEstimate};
use rtid::estimation::periodic::multisine::{
    generate, Level, LineSet, Multisine, MultisineSpec, PhaseRule,
};
use rtid::estimation::periodic::record::{PeriodicOptions, PeriodicRecord};
use rustfft::{num_complex::Complex, FftPlanner};
use std::f64::consts::TAU;

const FS: f64 = 1000.0;
const N: usize = 1000;
const PERIODS: usize = 9;
/// The cubic coefficient, 1/A².
const CUBIC: f64 = 0.005;
const NOISE_REL: f64 = 3e-3;

/// θm/T of the two-mass drive, rad/(N·m).
fn motor(f: f64) -> Complex<f64> {
    let (jm, jl, k, c) = (1.0e-3, 1.0e-3, 115.0, 0.0136);
    let s = Complex::new(0.0, TAU * f);
    (jl * s * s + c * s + k) / (s * s * (jm * jl * s * s + c * (jm + jl) * s + k * (jm + jl)))
}

fn excitation(seed: u64) -> Multisine {
    generate(&MultisineSpec {
        sample_rate_hz: FS,
        samples_per_period: N,
        periods: PERIODS,
        min_frequency_hz: 5.0,
        max_frequency_hz: 200.0,
        lines: LineSet::RandomOdd { group: 3, seed },
        phases: PhaseRule::Random { seed: seed + 10 },
        level: Level::Rms(1.0),
    })
    .unwrap()
}

/// The motor angle over the whole record (module docs).
fn response(ms: &Multisine, seed: u64) -> Vec<f64> {
    let mut planner = FftPlanner::new();
    let (fwd, inv) = (planner.plan_fft_forward(N), planner.plan_fft_inverse(N));
    let mut torque: Vec<Complex<f64>> = ms
        .period
        .iter()
        .map(|&i| Complex::new(i + CUBIC * i * i * i, 0.0))
        .collect();
    fwd.process(&mut torque);
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed + 20);
    let white = Normal::new(0.0, 1.0).unwrap();
    // Per line and part (re, im): NOISE_REL of the line amplitude, in DFT units.
    let scale = NOISE_REL * ms.amplitude * N as f64 / 2.0 / 2f64.sqrt();
    let mut y = Vec::with_capacity(N * PERIODS);
    for _ in 0..PERIODS {
        let mut spectrum = vec![Complex::new(0.0, 0.0); N];
        for k in 1..N / 2 {
            let e = Complex::new(white.sample(&mut rng), white.sample(&mut rng)) * scale;
            spectrum[k] = motor(k as f64 * FS / N as f64) * (torque[k] + e);
            spectrum[N - k] = spectrum[k].conj();
        }
        inv.process(&mut spectrum);
        y.extend(spectrum.iter().map(|c| c.re / N as f64));
    }
    y
}

fn estimate(seed: u64) -> (Multisine, PeriodicRecord, FrfEstimate) {
    let ms = excitation(seed);
    let u = ms.record();
    let rec = PeriodicRecord::new(&u, FS, &PeriodicOptions::default()).unwrap();
    let est = h1(&rec, &u, &response(&ms, seed)).unwrap();
    (ms, rec, est)
}

/// Mean square of |H − BLA| over its standard deviation (complex), with the noise's
/// σ alone and with the nonlinear σ added; and the largest with both.
fn normalised_errors(ms: &Multisine, est: &FrfEstimate) -> (f64, f64, f64) {
    let power = ms.period.iter().map(|x| x * x).sum::<f64>() / N as f64;
    let gain = 1.0 + 3.0 * CUBIC * (power - ms.amplitude * ms.amplitude / 4.0);
    let (mut noise, mut total, mut worst) = (0.0, 0.0, 0.0f64);
    for l in &est.lines {
        let truth = motor(l.frequency_hz) * gain;
        let err = (l.h() - truth).norm() / truth.norm();
        let nl = l
            .nonlinear_sigma_rel
            .expect("random odd: nonlinear σ known");
        let both = l.noise_sigma_rel.hypot(nl);
        noise += (err / l.noise_sigma_rel).powi(2) / est.lines.len() as f64;
        total += (err / both).powi(2) / est.lines.len() as f64;
        worst = worst.max(err / both);
    }
    (noise, total, worst)
}

#[test]
fn the_estimate_is_the_best_linear_approximation_within_its_stated_sigma() {
    for seed in 1..=4 {
        let (ms, rec, est) = estimate(seed);
        assert_eq!(
            (rec.samples_per_period, rec.periods_used()),
            (N, PERIODS - 1)
        );
        assert_eq!(rec.excited, ms.lines, "seed {seed}");
        let (noise, total, worst) = normalised_errors(&ms, &est);
        // With noise and nonlinear distortion: mean square ≈ 1 (the nonlinear level is
        // read at 4 neighbouring lines, itself uncertain) and no line beyond 4.5 σ —
        // a complex error of 4.5 σ has probability e^(−4.5²) ≈ 2e-9.
        assert!((0.5..1.6).contains(&total), "seed {seed}: {total}");
        assert!(worst < 4.5, "seed {seed}: {worst}");
        // The periods alone see only the noise; the distortion, periodic, is ≫ it.
        assert!(noise > 10.0, "seed {seed}: {noise}");
    }
}

#[test]
fn distortion_is_detected_at_the_left_out_odd_lines_and_not_at_the_even_ones() {
    for seed in 1..=4 {
        let (_, _, est) = estimate(seed);
        assert!(
            est.output_distortion.len() >= 5,
            "{:?}",
            est.output_distortion
        );
        for band in &est.output_distortion {
            assert!(band.odd.lines > 0 && band.even.lines > 0, "{band:?}");
            assert!(band.odd.detected, "seed {seed}: {band:?}");
            assert!(!band.even.detected, "seed {seed}: {band:?}");
        }
        // The excitation itself has no distortion anywhere.
        assert!(
            est.input_distortion
                .iter()
                .all(|b| !b.odd.detected && !b.even.detected),
            "{:?}",
            est.input_distortion
        );
    }
}
