//! The torque-setpoint filters as the controller runs them: each
//! [`SetpointFilter`] discretised by the bilinear (Tustin) transform prewarped at its
//! frequency ω₀ (the filter's gain at ω₀ is the continuous one exactly),
//!
//! ```text
//! s = K·(z − 1)/(z + 1),   K = ω₀ / tan(ω₀·Tc/2)
//! ```
//!
//! and run in direct form II transposed, up to [`MAX_FILTERS`] in series. A filter's
//! state starts at rest at the first sample's input (no step at switch-on).

use crate::model::setpoint_filter::{SetpointFilter, MAX_FILTERS};

/// One discretised second-order section: y = (b0 + b1·z⁻¹ + b2·z⁻²)/(1 + a1·z⁻¹ +
/// a2·z⁻²)·x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

impl Biquad {
    /// The section of `filter` at control period `tc` (checked: below Nyquist).
    pub fn new(filter: &SetpointFilter, tc: f64) -> Biquad {
        // H(s) = (n2·s² + n1·s + n0)/(d2·s² + d1·s + d0), in s/ω₀.
        let (w0, num, den) = match *filter {
            SetpointFilter::LowPass {
                frequency_hz,
                damping,
            } => {
                let w = std::f64::consts::TAU * frequency_hz;
                (w, [0.0, 0.0, 1.0], [1.0, 2.0 * damping, 1.0])
            }
            SetpointFilter::Notch {
                centre_hz,
                width_hz,
                depth_db,
            } => {
                let w = std::f64::consts::TAU * centre_hz;
                let d = width_hz / (2.0 * centre_hz);
                let g = depth_db.map_or(0.0, |db| 10f64.powf(db / 20.0));
                (w, [1.0, 2.0 * d * g, 1.0], [1.0, 2.0 * d, 1.0])
            }
        };
        // With s/ω₀ = c·(z − 1)/(z + 1), c = K/ω₀ = 1/tan(ω₀·Tc/2).
        let c = 1.0 / (0.5 * w0 * tc).tan();
        let z = |p: [f64; 3]| {
            let (q2, q1, q0) = (p[0] * c * c, p[1] * c, p[2]);
            [q2 + q1 + q0, 2.0 * (q0 - q2), q2 - q1 + q0]
        };
        let (n, d) = (z(num), z(den));
        Biquad {
            b: [n[0] / d[0], n[1] / d[0], n[2] / d[0]],
            a: [d[1] / d[0], d[2] / d[0]],
        }
    }

    /// The coefficients: numerator b0, b1, b2 and denominator a1, a2 (a0 = 1).
    pub fn coefficients(&self) -> ([f64; 3], [f64; 2]) {
        (self.b, self.a)
    }

    /// The gain at DC, Σb/(1 + Σa).
    fn dc_gain(&self) -> f64 {
        (self.b[0] + self.b[1] + self.b[2]) / (1.0 + self.a[0] + self.a[1])
    }

    /// The complex gain at `f` Hz for control period `tc`: (re, im).
    pub fn response(&self, f: f64, tc: f64) -> (f64, f64) {
        let w = std::f64::consts::TAU * f * tc;
        // z⁻¹ = e^{−jw}
        let (c1, s1, c2, s2) = (w.cos(), -w.sin(), (2.0 * w).cos(), -(2.0 * w).sin());
        let num = (
            self.b[0] + self.b[1] * c1 + self.b[2] * c2,
            self.b[1] * s1 + self.b[2] * s2,
        );
        let den = (
            1.0 + self.a[0] * c1 + self.a[1] * c2,
            self.a[0] * s1 + self.a[1] * s2,
        );
        let m = den.0 * den.0 + den.1 * den.1;
        (
            (num.0 * den.0 + num.1 * den.1) / m,
            (num.1 * den.0 - num.0 * den.1) / m,
        )
    }
}

/// Up to [`MAX_FILTERS`] sections in series with their states.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterChain {
    sections: [Biquad; MAX_FILTERS],
    state: [[f64; 2]; MAX_FILTERS],
    count: usize,
    started: bool,
}

impl FilterChain {
    /// The chain of `filters` (checked: at most [`MAX_FILTERS`], below Nyquist) at
    /// control period `tc`.
    pub fn new(filters: &[SetpointFilter], tc: f64) -> FilterChain {
        let pass = Biquad {
            b: [1.0, 0.0, 0.0],
            a: [0.0, 0.0],
        };
        let mut sections = [pass; MAX_FILTERS];
        for (s, f) in sections.iter_mut().zip(filters) {
            *s = Biquad::new(f, tc);
        }
        FilterChain {
            sections,
            state: [[0.0; 2]; MAX_FILTERS],
            count: filters.len().min(MAX_FILTERS),
            started: false,
        }
    }

    /// Whether the chain has no filter (the input passes untouched).
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The sections, in series order.
    pub fn sections(&self) -> &[Biquad] {
        &self.sections[..self.count]
    }

    /// The filtered value of the next input sample `x`.
    pub fn filter(&mut self, x: f64) -> f64 {
        if !self.started {
            self.settle(x);
        }
        let mut y = x;
        for (s, z) in self.sections[..self.count].iter().zip(&mut self.state) {
            let out = s.b[0] * y + z[0];
            z[0] = s.b[1] * y - s.a[0] * out + z[1];
            z[1] = s.b[2] * y - s.a[1] * out;
            y = out;
        }
        y
    }

    /// Sets every section's state to its steady state under a constant input `x`.
    fn settle(&mut self, x: f64) {
        self.started = true;
        let mut u = x;
        for (s, z) in self.sections[..self.count].iter().zip(&mut self.state) {
            let y = s.dc_gain() * u;
            z[1] = s.b[2] * u - s.a[1] * y;
            z[0] = s.b[1] * u - s.a[0] * y + z[1];
            u = y;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TC: f64 = 1.25e-4;

    fn gain_db(b: &Biquad, f: f64) -> f64 {
        let (re, im) = b.response(f, TC);
        20.0 * (re * re + im * im).sqrt().log10()
    }

    #[test]
    fn a_notch_has_its_depth_at_its_centre_and_its_width_at_minus_3_db() {
        let notch = SetpointFilter::Notch {
            centre_hz: 600.0,
            width_hz: 200.0,
            depth_db: Some(-20.0),
        };
        let b = Biquad::new(&notch, TC);
        assert!(
            (gain_db(&b, 600.0) + 20.0).abs() < 1e-9,
            "{}",
            gain_db(&b, 600.0)
        );
        assert!(gain_db(&b, 1.0).abs() < 1e-3 && gain_db(&b, 3000.0).abs() < 0.2);
        // A full notch: −3 dB at the edges of its width, ω₁·ω₂ = ω₀², ω₂ − ω₁ = 2π·B
        // in the continuous filter; the prewarped discrete filter has at f the
        // continuous gain at Ω = K·tan(π·f·Tc), so its edges lie where Ω is theirs.
        let full = Biquad::new(
            &SetpointFilter::Notch {
                centre_hz: 600.0,
                width_hz: 200.0,
                depth_db: None,
            },
            TC,
        );
        let w0 = std::f64::consts::TAU * 600.0;
        let k = w0 / (0.5 * w0 * TC).tan();
        let lower = -100.0 + (100.0f64 * 100.0 + 600.0 * 600.0).sqrt();
        for edge_hz in [lower, lower + 200.0] {
            let f = (std::f64::consts::TAU * edge_hz / k).atan() / (std::f64::consts::PI * TC);
            assert!(
                (gain_db(&full, f) + 3.0103).abs() < 1e-4,
                "{f}: {}",
                gain_db(&full, f)
            );
        }
        assert!(gain_db(&full, 600.0) < -100.0);
    }

    #[test]
    fn a_low_pass_passes_dc_and_has_its_damping_at_its_frequency() {
        let lp = SetpointFilter::LowPass {
            frequency_hz: 1000.0,
            damping: 0.5,
        };
        let b = Biquad::new(&lp, TC);
        assert!((b.dc_gain() - 1.0).abs() < 1e-12);
        // |H(jω₀)| = 1/(2D) = 1: 0 dB with D = 0.5.
        assert!(gain_db(&b, 1000.0).abs() < 1e-9);
    }

    #[test]
    fn the_chain_starts_settled_and_filters_in_series() {
        let filters = [
            SetpointFilter::LowPass {
                frequency_hz: 800.0,
                damping: 0.7,
            },
            SetpointFilter::Notch {
                centre_hz: 300.0,
                width_hz: 50.0,
                depth_db: Some(-12.0),
            },
        ];
        let mut chain = FilterChain::new(&filters, TC);
        for _ in 0..5 {
            assert!((chain.filter(2.5) - 2.5).abs() < 1e-12);
        }
        // A sine at the notch's centre, after the transient: its gain times the
        // low-pass's.
        let mut chain = FilterChain::new(&filters, TC);
        let expected = {
            let (a, b) = (chain.sections()[0], chain.sections()[1]);
            10f64.powf((gain_db(&a, 300.0) + gain_db(&b, 300.0)) / 20.0)
        };
        let n = 40_000;
        let peak = (0..n)
            .map(|k| chain.filter((std::f64::consts::TAU * 300.0 * k as f64 * TC).sin()))
            .skip(n / 2)
            .fold(0.0f64, |m, y| m.max(y.abs()));
        assert!((peak / expected - 1.0).abs() < 2e-3, "{peak} vs {expected}");
        assert!(FilterChain::new(&[], TC).is_empty());
    }
}
