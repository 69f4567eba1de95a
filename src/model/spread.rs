//! How far the machine may be from a parameter set: a parameter's value times a
//! ratio from `low` to `high`, and where that comes from — a held range (a preset's
//! uncertain value, a parameter file's `ranges`, the ones a fit carried) or a fit's
//! interval. `rtid tune` varies the machine over them.

use serde::Serialize;

/// A parameter the machine may differ in: its value times `low` to `high`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spread {
    pub name: String,
    pub low: f64,
    pub high: f64,
    /// `held range 25 % (assumed)`, `the fit's interval (bootstrap, 12 replicates)`.
    pub from: String,
}

impl Spread {
    /// A held range of ±`percent` % (0 < percent < 100), and why.
    pub fn held(name: &str, percent: f64, reason: &str) -> Spread {
        Spread {
            name: name.into(),
            low: 1.0 - percent / 100.0,
            high: 1.0 + percent / 100.0,
            from: format!("held range {} % ({reason})", crate::names::Num(percent)),
        }
    }

    /// A fit's interval `lower … upper` of `value` as ratios (`None` where it does not
    /// bracket a positive value with a positive lower end).
    pub fn fitted(name: &str, value: f64, lower: f64, upper: f64, from: &str) -> Option<Spread> {
        let (low, high) = (lower / value, upper / value);
        let ok = value > 0.0 && low > 0.0 && low <= 1.0 && high >= 1.0 && high.is_finite();
        ok.then(|| Spread {
            name: name.into(),
            low,
            high,
            from: format!("the fit's interval ({from})"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_range_and_a_fits_interval_are_ratios_of_the_value() {
        let h = Spread::held("Jt", 25.0, "assumed");
        assert_eq!((h.low, h.high), (0.75, 1.25));
        assert_eq!(h.from, "held range 25 % (assumed)");
        let f = Spread::fitted("Kw", 2.0, 1.5, 3.0, "bootstrap, 12 replicates").unwrap();
        assert_eq!((f.low, f.high), (0.75, 1.5));
        // An interval reaching 0, or missing the value, is no ratio.
        assert!(Spread::fitted("Kw", 1.0, -0.1, 2.0, "x").is_none());
        assert!(Spread::fitted("Kw", 1.0, 1.1, 2.0, "x").is_none());
        assert!(Spread::fitted("Kw", -1.0, -2.0, -0.5, "x").is_none());
    }
}
