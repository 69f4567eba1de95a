//! Readers of the files labs export, one module per format, each turning a foreign
//! file into a [`Recording`]: named channels with the units, abscissae, scale factors
//! and offsets the file itself declares. `rtid import` maps them onto rtid's
//! experiment files (`crate::io::experiment_file`). Nothing here knows the tests; the
//! tests know nothing of these formats.
//!
//! Every reader names the file and the line (text formats) or byte offset (binary
//! formats) of what it cannot read ([`FormatError`]) and refuses a declared size it
//! cannot hold before allocating it. Text formats are streamed line by line; binary
//! ones (MAT-files, a UFF 58b block) are read whole, as their layout needs.

pub mod delimited;
pub mod detect;
pub mod epos_studio;
pub mod format;
pub mod mat;
pub mod sinumerik_trace;
mod text;
pub mod twincat_scope;
pub mod uff;
pub mod units;

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file a problem is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// A 1-based line of a text file.
    Line(usize),
    /// A 0-based byte offset of a binary file (or of a binary block in a text file).
    Byte(u64),
    /// The file as a whole (empty, or a property of all of it).
    File,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, ", line {n}"),
            Location::Byte(b) => write!(f, ", byte {b}"),
            Location::File => Ok(()),
        }
    }
}

/// A file a reader cannot read: which file, where, and what is wrong there.
#[derive(Debug, thiserror::Error)]
#[error("{}{location}: {message}", path.display())]
pub struct FormatError {
    pub path: PathBuf,
    pub location: Location,
    pub message: String,
}

impl FormatError {
    pub fn new(path: &Path, location: Location, message: impl Into<String>) -> FormatError {
        FormatError {
            path: path.to_path_buf(),
            location,
            message: message.into(),
        }
    }
}

/// The abscissa of a channel's samples.
#[derive(Clone, Debug, PartialEq)]
pub enum Abscissa {
    /// Evenly spaced: the first value and the step, in `unit` as the file spells it
    /// (`s` for a time record, `Hz` for a spectrum or frequency response).
    Uniform { start: f64, step: f64, unit: String },
    /// One value per sample (a time column, an uneven frequency axis), in `unit`.
    Values { values: Vec<f64>, unit: String },
    /// None in the file: the samples are numbered only (a MAT-file's arrays; the time
    /// is then another channel the user names).
    Index,
}

/// A channel's samples after the file's own scale factor and offset.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    Real(Vec<f64>),
    /// Real and imaginary parts (a frequency response, a cross spectrum).
    Complex {
        re: Vec<f64>,
        im: Vec<f64>,
    },
}

impl Samples {
    pub fn len(&self) -> usize {
        match self {
            Samples::Real(v) => v.len(),
            Samples::Complex { re, .. } => re.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// One channel of a recording.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// The name as the file spells it (spaces and special characters kept; a MAT-file
    /// struct's field as `rec.qm`).
    pub name: String,
    /// The unit as the file spells it (`rpm`, `%`, `mN·m`…); empty when it gives none.
    pub unit: String,
    pub abscissa: Abscissa,
    pub samples: Samples,
    /// The 1-based line of the first sample in a text file where each sample is a
    /// line, so that sample i is on line `first_line + i` (for glitch reports); `None`
    /// otherwise.
    pub first_line: Option<usize>,
}

/// What a reader found in one file.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    /// The format's name (`matlab-v5`, `twincat-scope`, `epos-studio`, `uff58`,
    /// `delimited`).
    pub format: &'static str,
    pub channels: Vec<Channel>,
    /// What the reader noticed and did not refuse (a skipped stray cell, a header
    /// property it does not use).
    pub notes: Vec<String>,
    /// The arrays cut into several channels (a MAT-file's matrices), so that a
    /// listing can show each once; empty for the other formats.
    pub groups: Vec<Group>,
}

/// Channels cut from one array: a matrix's rows `name(i,:)` or columns `name(:,j)`
/// (`name(:,j,k)` for an N-d array), 1-based as in MATLAB.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// The array's name (`rec.act_pos_mot_deg`).
    pub name: String,
    /// Its dimensions (`[6, 2501]`).
    pub shape: Vec<usize>,
    /// True when each row is a signal (samples along the second dimension).
    pub signals_in_rows: bool,
    /// Its channels' indices in [`Recording::channels`].
    pub channels: std::ops::Range<usize>,
}

impl Group {
    /// How its channels are spelled: `rec.q(i,:), i = 1…6` or `M(:,j), j = 1…3`.
    pub fn spelling(&self) -> String {
        let n = self.channels.len();
        match (self.signals_in_rows, self.shape.len()) {
            (true, _) => format!("{}(i,:), i = 1…{n}", self.name),
            (false, 2) => format!("{}(:,j), j = 1…{n}", self.name),
            (false, _) => format!("{}(:,j,…)", self.name),
        }
    }

    /// Its shape as MATLAB prints it (`6×2501`).
    pub fn shape_text(&self) -> String {
        let sizes: Vec<String> = self.shape.iter().map(|d| d.to_string()).collect();
        sizes.join("×")
    }
}
