//! Which reader reads a file: the one `--format` names, else the one whose signature
//! the file's first bytes carry, else delimited text.

use std::io::Read;
use std::path::Path;

use super::{delimited, epos_studio, mat, twincat_scope, uff, FormatError, Location, Recording};

/// A format rtid reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Mat,
    TwincatScope,
    EposStudio,
    Uff,
    Delimited,
}

impl Format {
    pub const ALL: [Format; 5] = [
        Format::Mat,
        Format::TwincatScope,
        Format::EposStudio,
        Format::Uff,
        Format::Delimited,
    ];

    /// As `--format` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Format::Mat => "mat",
            Format::TwincatScope => "twincat-scope",
            Format::EposStudio => "epos-studio",
            Format::Uff => "uff",
            Format::Delimited => "delimited",
        }
    }

    pub fn parse(name: &str) -> Option<Format> {
        Format::ALL.into_iter().find(|f| f.name() == name)
    }

    fn read(self, path: &Path) -> Result<Recording, FormatError> {
        match self {
            Format::Mat => mat::read(path),
            Format::TwincatScope => twincat_scope::read(path),
            Format::EposStudio => epos_studio::read(path),
            Format::Uff => uff::read(path),
            Format::Delimited => delimited::read(path),
        }
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
    Ok(if head.starts_with(b"MATLAB") {
        Format::Mat
    } else if twincat_scope::sniff(&first_line) {
        Format::TwincatScope
    } else if epos_studio::sniff(&first_line) {
        Format::EposStudio
    } else if uff::sniff(&head) {
        Format::Uff
    } else {
        Format::Delimited
    })
}
