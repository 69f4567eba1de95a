//! The Stribeck laws' starting values. Starts: the Coulomb law's fit (Fc, Fv, Fo —
//! per direction for the asymmetric law), Fs the Coulomb-corrected effort of the runs
//! at the lowest speed, vs the geometric mean of the lowest and highest speed,
//! delta = 1 and delta = 2; the better of the two fits is kept (`nonlinear.rs`).

use super::law::Law;
use super::linear;
use super::map::{distinct_speeds, Direction};

/// The starting values of delta.
pub const DELTA_STARTS: [f64; 2] = [1.0, 2.0];

/// The starts of a Stribeck `law` over the runs, one per [`DELTA_STARTS`]; none for
/// a linear law.
pub(super) fn starts(law: Law, speed: &[f64], effort: &[f64]) -> Vec<Vec<f64>> {
    if !law.is_stribeck() {
        return Vec::new();
    }
    DELTA_STARTS
        .iter()
        .map(|&delta| start(law, speed, effort, delta))
        .collect()
}

/// The starting values of `law` with `delta`.
fn start(law: Law, speed: &[f64], effort: &[f64], delta: f64) -> Vec<f64> {
    let runs = || speed.iter().zip(effort);
    // The runs in `direction` at its lowest speed, and the geometric mean of its
    // lowest and highest speed.
    let lowest = |direction: Direction| {
        let u = distinct_speeds(speed, direction);
        let (low, high) = (u[0], u[u.len() - 1]);
        let at_low =
            move |v: f64| Direction::of(v) == direction && (v.abs() - low).abs() <= 1e-9 * low;
        (at_low, (low * high).sqrt())
    };
    let (pos, vs_pos) = lowest(Direction::Positive);
    let (neg, vs_neg) = lowest(Direction::Negative);
    let mean = |values: Vec<f64>| values.iter().sum::<f64>() / values.len() as f64;
    match law {
        Law::Stribeck => {
            let c = linear::fit(&Law::Coulomb, speed, effort);
            let (fc, fv, fo) = (c[0], c[1], c[2]);
            let fs = mean(
                runs()
                    .filter(|(&v, _)| pos(v) || neg(v))
                    .map(|(&v, &e)| v.signum() * (e - fv * v - fo))
                    .collect(),
            );
            let u = speed.iter().map(|v| v.abs());
            let (low, high) = (
                u.clone().fold(f64::INFINITY, f64::min),
                u.fold(0.0, f64::max),
            );
            let vs = (low * high).sqrt();
            vec![fc, fs, vs, delta, fv, fo]
        }
        Law::StribeckAsymmetric => {
            let c = linear::fit(&Law::CoulombAsymmetric, speed, effort);
            let (fv_pos, fv_neg) = (c[1], c[3]);
            let fs_pos = mean(
                runs()
                    .filter(|(&v, _)| pos(v))
                    .map(|(&v, &e)| e - fv_pos * v)
                    .collect(),
            );
            let fs_neg = mean(
                runs()
                    .filter(|(&v, _)| neg(v))
                    .map(|(&v, &e)| fv_neg * v - e)
                    .collect(),
            );
            vec![
                c[0], fs_pos, vs_pos, fv_pos, c[2], fs_neg, vs_neg, fv_neg, delta,
            ]
        }
        Law::Coulomb | Law::CoulombAsymmetric => {
            unreachable!("starts() returns none for a linear law")
        }
    }
}
