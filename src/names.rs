//! Errors of text that names something: an unknown name among known ones, or a value
//! not of the expected form. They name the value and what was expected; the command
//! line adds which option it came from.

/// A name that is not one of the known ones (an output, a loop mode, a method…).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{given}`: expected {expected}")]
pub struct UnknownName {
    /// What kind of name (`loop`, `output`…).
    pub what: &'static str,
    pub given: String,
    /// The known names, or a description of them.
    pub expected: String,
}

/// A value that does not have the expected form.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{given}`: expected {expected}")]
pub struct BadForm {
    pub given: String,
    /// The form, with an example.
    pub expected: &'static str,
}

/// A number as a message shows it: plain in the usual range, in scientific notation
/// when very large or very small (`1e-300`, not three hundred zeros).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e9).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// The known name `name` most likely misspells, if any: the same but for case, a
/// missing unit suffix (`preload` for `preload_nm`), or an edit distance of at most one
/// in five characters, a swap counted as one (`phase_degs` for `phase_deg`). A name far from every known one
/// is no misspelling: files may carry names of their own (docs/experiment-files.md).
pub fn misspelling_of<'a>(name: &str, known: &[&'a str]) -> Option<&'a str> {
    let lower = name.to_ascii_lowercase();
    let close = |k: &str| {
        let k = k.to_ascii_lowercase();
        let suffix_dropped = k
            .strip_prefix(lower.as_str())
            .is_some_and(|r| r.starts_with('_'));
        suffix_dropped || strsim::osa_distance(&lower, &k) <= (k.len() / 5).max(1)
    };
    known
        .iter()
        .filter(|k| **k != name && close(k))
        .min_by_key(|k| strsim::osa_distance(&lower, &k.to_ascii_lowercase()))
        .copied()
}

#[cfg(test)]
mod misspelling_tests {
    use super::misspelling_of;

    const KNOWN: [&str; 5] = ["preload_nm", "phase_deg", "ratio", "mass_kg", "period_s"];

    #[test]
    fn near_names_are_misspellings() {
        assert_eq!(misspelling_of("preload", &KNOWN), Some("preload_nm"));
        assert_eq!(misspelling_of("phase_degs", &KNOWN), Some("phase_deg"));
        assert_eq!(misspelling_of("Ratio", &KNOWN), Some("ratio"));
        assert_eq!(misspelling_of("mass_gk", &KNOWN), Some("mass_kg"));
    }

    #[test]
    fn names_of_their_own_are_not() {
        for name in [
            "preload_nm",
            "output_limit_v",
            "velocity_gain_v_s_per_m",
            "operator",
            "loop_period_s",
            "run_id",
        ] {
            assert_eq!(misspelling_of(name, &KNOWN), None, "{name}");
        }
    }
}

#[cfg(test)]
mod num_tests {
    use super::Num;

    #[test]
    fn extreme_numbers_are_short() {
        assert_eq!(Num(1e-300).to_string(), "1e-300");
        assert_eq!(Num(-1.5e308).to_string(), "-1.5e308");
        assert_eq!(Num(3600.0).to_string(), "3600");
        assert_eq!(Num(0.05).to_string(), "0.05");
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
    }
}
