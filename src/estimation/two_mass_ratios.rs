//! What the resonance and antiresonance of a two-mass drive's motor response determine
//! (docs/model.md §1, two-mass topology), in closed form.
//!
//! Motor Jm and load Jl joined by a spring k (damper c), torque T on the motor:
//!
//! ```text
//! θm/T = (Jl·s² + c·s + k) / (s²·(Jm·Jl·s² + c·(Jm + Jl)·s + k·(Jm + Jl)))
//! θl/θm = (c·s + k) / (Jl·s² + c·s + k)
//! ```
//!
//! The motor response has its antiresonance (zeros) at ωa² = k/Jl — the load on the
//! spring with the motor held, also the peak of θl/θm — and its resonance (poles) at
//! ωr² = k·(1/Jm + 1/Jl). Hence
//!
//! ```text
//! Jl/Jm = (ωr/ωa)² − 1      k/Jl = ωa²      k/Jm = ωa²·Jl/Jm = ωr² − ωa²
//! ```
//!
//! These are undamped frequencies; a peak or notch of damping ratio ζ lies within ~ζ²
//! of them (0.04 % at ζ = 0.02). Without the torque constant (current → torque) only
//! these ratios are determined, never Jm, Jl or k themselves. The transfer functions
//! are the Laplace transforms of docs/model.md §1's two-mass equations (Rw = 1, no
//! backlash, no friction).

use serde::Serialize;

/// Ratios of a two-mass drive.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TwoMassRatios {
    /// Jl/Jm, load over motor inertia.
    pub inertia_ratio: f64,
    /// k/Jl, rad²/s².
    pub k_over_jl: f64,
    /// k/Jm, rad²/s².
    pub k_over_jm: f64,
}

/// Why the ratios cannot be formed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TwoMassError {
    #[error("{field} = {value} Hz must be positive and finite")]
    BadFrequency { field: &'static str, value: f64 },
    #[error("the resonance {resonance_hz} Hz must lie above the antiresonance {antiresonance_hz} Hz (motor over torque of a two-mass drive)")]
    Order {
        resonance_hz: f64,
        antiresonance_hz: f64,
    },
}

/// The ratios from the motor response's resonance and antiresonance, Hz.
pub fn from_frequencies(
    resonance_hz: f64,
    antiresonance_hz: f64,
) -> Result<TwoMassRatios, TwoMassError> {
    for (field, value) in [
        ("resonance_hz", resonance_hz),
        ("antiresonance_hz", antiresonance_hz),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(TwoMassError::BadFrequency { field, value });
        }
    }
    if resonance_hz <= antiresonance_hz {
        return Err(TwoMassError::Order {
            resonance_hz,
            antiresonance_hz,
        });
    }
    let (wr, wa) = (
        std::f64::consts::TAU * resonance_hz,
        std::f64::consts::TAU * antiresonance_hz,
    );
    Ok(TwoMassRatios {
        inertia_ratio: (wr / wa).powi(2) - 1.0,
        k_over_jl: wa * wa,
        k_over_jm: wr * wr - wa * wa,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_known_drive_comes_back() {
        let (jm, jl, k): (f64, f64, f64) = (2e-3, 5e-3, 800.0);
        let wa = (k / jl).sqrt();
        let wr = (k * (1.0 / jm + 1.0 / jl)).sqrt();
        let tau = std::f64::consts::TAU;
        let r = from_frequencies(wr / tau, wa / tau).unwrap();
        assert!((r.inertia_ratio - jl / jm).abs() < 1e-12);
        assert!((r.k_over_jl - k / jl).abs() < 1e-9 * k / jl);
        assert!((r.k_over_jm - k / jm).abs() < 1e-9 * k / jm);
        assert!(matches!(
            from_frequencies(50.0, 60.0),
            Err(TwoMassError::Order { .. })
        ));
        assert!(matches!(
            from_frequencies(f64::NAN, 60.0),
            Err(TwoMassError::BadFrequency {
                field: "resonance_hz",
                ..
            })
        ));
    }
}
