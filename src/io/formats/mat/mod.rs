//! MATLAB MAT-files, level 5 (what MATLAB 5 to 7 writes, `save -v6` and `save -v7`,
//! and what `scipy.io.savemat` writes): format `matlab-v5`.
//!
//! The layout follows MathWorks, "MAT-File Format", Version 7 (the level 5 format
//! description, `matfile_format.pdf`): a 128-byte header (`header.rs`), then data
//! elements (`element.rs`), each top-level one an `miMATRIX` (one variable,
//! `matrix.rs`) or an `miCOMPRESSED` zlib stream holding one (`inflate.rs`). Both byte
//! orders are read. scipy's reader (`scipy/io/matlab/_mio5.py`) was the second
//! reference where the description is terse (small data elements, empty arrays,
//! the nameless subsystem variable); the fixtures' expected values come from it.
//!
//! What becomes a channel (all with [`Abscissa::Index`](super::Abscissa::Index), no
//! unit, since a MAT-file has neither):
//! - a numeric array of any class (double, single, int8 … uint64, logical), its
//!   values as `f64` (64-bit integers beyond ±2^53 are rounded, with a note): a
//!   vector (N×1 or 1×N) or scalar (a drive constant) is one channel named as the
//!   variable; an N×M matrix with both above 1 is one channel per signal along its
//!   samples' dimension — the one that is the length of a time base of the file (an
//!   increasing vector) when just one is, else the longer (columns when square): a
//!   robot's 6×2501 `rec.q` gives rows `rec.q(1,:)` … `rec.q(6,:)`, a 2501×6 matrix
//!   columns `name(:,j)`, 1-based (`name(:,j,k)` for an N-d array); each array is a
//!   [`Group`](super::Group) of the recording, so that a listing shows it once;
//! - a complex array: [`Samples::Complex`](super::Samples::Complex);
//! - a struct's fields, named `rec.qm`, nested `a.b.c`, element k (1-based, column
//!   major) of a struct array `s(k).qm`.
//!
//! Char arrays, cells, sparse matrices, objects, function handles and empty arrays are
//! skipped with a note naming the variable. A MATLAB 7.3 file (HDF5) is refused with
//! how to save it as version 7.
//!
//! Robustness: the file is read once into memory ([`crate::io::open_input`] refuses
//! devices and files over 4 GiB); every declared length is checked against the bytes
//! its file or parent element has left, and every array's dimensions against the
//! values its data element holds, before anything is allocated for them; compressed
//! elements inflate in steps up to 4 GiB in all; structs nest at most 32
//! deep. A file that breaks any of this gives one
//! [`FormatError`] naming the file and the byte offset (for a problem inside a
//! compressed element, the element's offset, and the offset inside its inflated data
//! in the message).
//!
//! Why no crate (checked November 2026, sources and a probe program run against these
//! fixtures; crates.io download counts could not be fetched):
//! - `matrw` 0.1.4 (MIT/Apache-2.0; five releases, 0.1.0 to 0.1.2 yanked; "the public
//!   API isn't fully stable yet"): it reads structs, cells, sparse and compressed
//!   elements, and loads DATA_EMPS.mat. But it refuses every file scipy writes (its
//!   header parser wants the text to begin "MATLAB 5.0 MAT-file, " with the comma;
//!   scipy writes "MATLAB 5.0 MAT-file Platform: …"); it panics on a truncated or
//!   corrupt compressed element (`read_to_end(..).unwrap()` in
//!   `compressed_array.rs`, which also leaves the inflated size unbounded), as the
//!   probe showed on DATA_EMPS.mat cut at byte 400 000 or with 16 bytes flipped; its
//!   variable loop stops on any end-of-file error; and it needs Rust 2024 (1.85,
//!   rtid builds with 1.80).
//! - `matfile` 0.5.0 (MIT): numeric arrays only; a struct is skipped, so a robot's
//!   nested struct record cannot be read.
//!
//! The format is small enough to read directly, with `flate2` (1.1, the pure-Rust
//! miniz_oxide backend) for zlib, and to own every bound and message.

mod element;
mod fault;
mod found;
mod header;
mod inflate;
mod matrix;
#[cfg(test)]
mod tests;

use std::io::Read;
use std::path::Path;

use element::{Cursor, DataType, Element};
use fault::{Fault, Origin, Problem};
use found::{Finished, Found};

use super::{FormatError, Location, Recording};

/// The format's name in a [`Recording`].
pub const FORMAT: &str = "matlab-v5";

/// The format as `--format` names it and [`super::detect`] recognises it.
pub static DEFINITION: super::format::Definition = super::format::Definition {
    name: "mat",
    sniff: |head| head.bytes.starts_with(b"MATLAB"),
    read,
};

/// Reads a level 5 MAT-file (compressed or not, either byte order).
pub fn read(path: &Path) -> Result<Recording, FormatError> {
    let bytes = read_bytes(path)?;
    parse(path, &bytes, crate::io::MAX_INPUT_BYTES)
}

/// The whole file, opened with [`crate::io::open_input`].
fn read_bytes(path: &Path) -> Result<Vec<u8>, FormatError> {
    let cannot = |e: std::io::Error| FormatError::new(path, Location::File, e.to_string());
    let mut file = crate::io::open_input(path).map_err(cannot)?;
    let len = file.metadata().map_err(cannot)?.len();
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.read_to_end(&mut bytes).map_err(cannot)?;
    Ok(bytes)
}

/// The recording in `bytes`, the contents of `path`; compressed elements may inflate
/// to `inflate_limit` bytes in all.
fn parse(path: &Path, bytes: &[u8], inflate_limit: u64) -> Result<Recording, FormatError> {
    let found = variables(bytes, inflate_limit).map_err(|f| f.into_format_error(path))?;
    Ok(Recording {
        format: FORMAT,
        channels: found.channels,
        notes: found.notes,
        groups: found.groups,
    })
}

/// Every variable after the header, in file order.
fn variables(bytes: &[u8], inflate_limit: u64) -> Result<Finished, Fault> {
    let order = header::byte_order(bytes)?;
    let mut cursor = Cursor::new(
        bytes,
        header::HEADER_LEN,
        order,
        Origin::File,
        "the end of the file",
    );
    let mut found = Found::default();
    let mut budget = inflate_limit;
    while !cursor.is_at_end() {
        if cursor.rest().len() < 8 {
            return end_padding(&cursor).map(|()| found.finish());
        }
        let element = cursor.next_element()?;
        match element.data_type {
            DataType::Matrix => matrix::read_variable(&element, &mut found)?,
            DataType::Compressed => read_compressed(&element, &mut budget, &mut found)?,
            other => found.note(format!(
                "an {} element at byte {} outside any variable: skipped",
                other.name(),
                element.at
            )),
        }
    }
    Ok(found.finish())
}

/// Accepts fewer than 8 bytes at the end if they are zeros (padding).
fn end_padding(cursor: &Cursor) -> Result<(), Fault> {
    let rest = cursor.rest();
    if rest.iter().all(|&b| b == 0) {
        Ok(())
    } else {
        let problem = Problem::TagCut {
            left: rest.len(),
            end: "the end of the file",
        };
        Err(cursor.fault(cursor.position(), problem))
    }
}

/// An `miCOMPRESSED` element: inflated (within what is left of `budget`), it must
/// hold one `miMATRIX`.
fn read_compressed(element: &Element, budget: &mut u64, found: &mut Found) -> Result<(), Fault> {
    let inflated = inflate::inflate(element.data(), *budget)
        .map_err(|problem| element.body.fault(element.at, problem))?;
    *budget = budget.saturating_sub(inflated.len() as u64);
    let origin = Origin::Inflated {
        element_at: element.at,
    };
    let order = element.body.order();
    let mut inner = Cursor::new(&inflated, 0, order, origin, "the end of the inflated data");
    let variable = inner.next_element()?;
    variable.expect("compressed variable", &[DataType::Matrix], "miMATRIX")?;
    matrix::read_variable(&variable, found)?;
    if inner.rest().iter().any(|&b| b != 0) {
        found.note(format!(
            "{} bytes after the variable in the compressed element at byte {}: ignored",
            inner.rest().len(),
            element.at
        ));
    }
    Ok(())
}
