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
