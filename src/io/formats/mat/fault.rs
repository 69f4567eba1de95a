//! What the reader refuses, and where: a [`Problem`] at a byte of the file, or at a
//! byte of the data a compressed element inflates to (reported at that element's
//! tag, with the inner offset in the message).

use std::path::Path;

use crate::io::formats::{FormatError, Location};

/// Which buffer an offset is into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Origin {
    /// The file itself.
    File,
    /// The data inflated from the `miCOMPRESSED` element whose tag is at
    /// `element_at` in the file.
    Inflated { element_at: usize },
}

/// A problem at offset `at` of the buffer `origin` names.
#[derive(Debug)]
pub(super) struct Fault {
    pub origin: Origin,
    pub at: usize,
    pub problem: Problem,
}

impl Fault {
    /// The file's error: its path, a byte offset in the file, and the problem.
    pub(super) fn into_format_error(self, path: &Path) -> FormatError {
        match self.origin {
            Origin::File => FormatError::new(
                path,
                Location::Byte(self.at as u64),
                self.problem.to_string(),
            ),
            Origin::Inflated { element_at } => FormatError::new(
                path,
                Location::Byte(element_at as u64),
                format!(
                    "in the compressed element there, at byte {} of its inflated data: {}",
                    self.at, self.problem
                ),
            ),
        }
    }
}

/// What is wrong.
#[derive(Debug, thiserror::Error)]
pub(super) enum Problem {
    #[error("empty file: a MAT-file begins with a 128-byte header")]
    Empty,
    #[error("the file ends inside the 128-byte header of a MAT-file")]
    ShortHeader,
    #[error(
        "a MATLAB 7.3 MAT-file (an HDF5 file), which rtid does not read: save it as a \
         version 7 MAT-file, `save(FILE, '-v7')` in MATLAB (scipy.io.savemat writes \
         version 5, which rtid reads too)"
    )]
    Version73,
    #[error(
        "no byte-order indicator 'IM' or 'MI' at bytes 126-127 (found {0}): not a \
         level 5 MAT-file (MATLAB 5 to 7); a MATLAB 4 file (`save -v4`) is not read"
    )]
    NoByteOrder(String),
    #[error("MAT-file version {0:#06x} in the header, rtid reads 0x0100 (level 5)")]
    UnknownVersion(u16),
    #[error("{left} bytes left before {end}, too few for an 8-byte data element tag")]
    TagCut { left: usize, end: &'static str },
    #[error("a data element of {declared} bytes runs past {end} ({left} bytes left)")]
    RunsPast {
        declared: u64,
        left: usize,
        end: &'static str,
    },
    #[error("a small data element declares {0} bytes, at most 4 fit in one")]
    SmallTooLong(u32),
    #[error("unknown data type {0} in a data element tag")]
    UnknownType(u32),
    #[error("the {what} is an {found} element, expected {expected}")]
    UnexpectedType {
        what: &'static str,
        found: &'static str,
        expected: &'static str,
    },
    #[error("the {what} has {len} bytes, not a whole number of {size}-byte values")]
    Ragged {
        what: &'static str,
        len: usize,
        size: usize,
    },
    #[error("the array has no dimensions")]
    NoDimensions,
    #[error("the array dimensions {dims} include a negative one")]
    NegativeDimension { dims: String },
    #[error("the array dimensions {dims} declare more than 2^64 values")]
    DimensionsOverflow { dims: String },
    #[error("the array dimensions {dims} declare {declared} values, its {what} holds {held}")]
    CountMismatch {
        dims: String,
        declared: u64,
        what: &'static str,
        held: u64,
    },
    #[error("unknown array class {0}")]
    UnknownClass(u32),
    #[error("a struct's field names are {0} bytes each, which cannot be")]
    FieldNameLength(u32),
    #[error("the struct's field names take {len} bytes, not a whole number of {each}-byte names")]
    FieldNames { len: usize, each: usize },
    #[error(
        "the struct declares {elements} elements of {fields} fields, more than the {left} \
         bytes left can hold"
    )]
    StructTooLarge {
        elements: u64,
        fields: usize,
        left: usize,
    },
    #[error("structs nested more than {0} deep")]
    TooDeep(usize),
    #[error("a compressed element that does not inflate ({0})")]
    Inflate(String),
    #[error(
        "compressed elements that inflate to more than {limit} bytes in all (rtid reads \
         at most 4 GiB)"
    )]
    InflatedTooLarge { limit: u64 },
}
