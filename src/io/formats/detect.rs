//! Which reader reads a file: the one `--format` names, else the first whose
//! signature the file's first bytes carry, else delimited text. Adding a format is
//! one module with its `DEFINITION` ([`Definition`]) and one line in [`FORMATS`].

use std::io::Read;
use std::path::Path;

pub use super::format::{Definition, Format, Head};
use super::{
    delimited, epos_studio, mat, sinumerik_trace, twincat_scope, uff, FormatError, Location,
    Recording,
};

/// Every format, in the order their signatures are tried; delimited text, which
/// takes any file, last.
pub static FORMATS: &[&Definition] = &[
    &mat::DEFINITION,
    &twincat_scope::DEFINITION,
    &epos_studio::DEFINITION,
    &uff::DEFINITION,
    &sinumerik_trace::DEFINITION,
    &delimited::DEFINITION,
];

impl Format {
    /// Every format, in [`FORMATS`]' order.
    pub fn all() -> impl Iterator<Item = Format> {
        FORMATS.iter().map(|d| Format(d))
    }

    /// The format `--format` names `name`.
    pub fn parse(name: &str) -> Option<Format> {
        Format::all().find(|f| f.name() == name)
    }
}

/// Reads `path` with the reader of `format`, or of the format its first bytes show.
pub fn read(path: &Path, format: Option<Format>) -> Result<Recording, FormatError> {
    match format {
        Some(f) => f.read(path),
        None => sniff(path)?.read(path),
    }
}

/// The format of the file's first bytes.
pub fn sniff(path: &Path) -> Result<Format, FormatError> {
    let mut head = Vec::with_capacity(4096);
    crate::io::open_input(path)
        .and_then(|f| f.take(4096).read_to_end(&mut head))
        .map_err(|e| FormatError::new(path, Location::File, format!("cannot read: {e}")))?;
    let first_line = String::from_utf8_lossy(head.split(|&b| b == b'\n').next().unwrap_or(&[]));
    let head = Head {
        bytes: &head,
        first_line: &first_line,
    };
    Ok(Format::all()
        .find(|f| (f.0.sniff)(&head))
        .unwrap_or(Format(&delimited::DEFINITION)))
}
