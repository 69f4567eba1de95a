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
