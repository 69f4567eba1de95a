//! What a format declares about itself — its [`Definition`]: the name `--format`
//! spells, the signature its first bytes carry, and its reader. The list of
//! definitions, in the order their signatures are tried, is
//! [`super::detect::FORMATS`]; this file knows none of them.

use std::fmt;
use std::path::Path;

use super::{FormatError, Recording};

/// The start of a file, as a signature is recognised by: its first bytes (at most
/// 4 KiB) and its first line as text.
pub struct Head<'a> {
    pub bytes: &'a [u8],
    pub first_line: &'a str,
}

/// A format rtid reads: one module in `io/formats/` with its `pub static DEFINITION`.
pub struct Definition {
    /// As `--format` spells it (`twincat-scope`).
    pub name: &'static str,
    /// Whether a file's start carries the format's signature.
    pub sniff: fn(&Head<'_>) -> bool,
    /// The reader: the file as named channels, naming file and line (or byte) on
    /// every error.
    pub read: fn(&Path) -> Result<Recording, FormatError>,
}

/// A format by name: a handle on its [`Definition`] in the list.
#[derive(Clone, Copy)]
pub struct Format(pub(super) &'static Definition);

impl Format {
    /// As `--format` spells it.
    pub fn name(self) -> &'static str {
        self.0.name
    }

    /// Reads `path` with this format's reader.
    pub fn read(self, path: &Path) -> Result<Recording, FormatError> {
        (self.0.read)(path)
    }
}

impl PartialEq for Format {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.0, other.0)
    }
}

impl Eq for Format {}

impl fmt::Debug for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
