//! One self-contained HTML page of identifications, ISO 230-2 positioning tests and
//! sweeps (`rtid report`): a section per input file, recognised by content. The page
//! fetches nothing (inline CSS and SVG), so it can be archived beside a machine's
//! acceptance record and printed to A4 years later exactly as it was written.
//!
//! Each section module turns an already computed result into HTML; the computations
//! stay in their own modules (ISO 230-2 in `experiments::positioning::iso230`, indices in
//! `sweep::analysis`), so the page and the command line never disagree.

pub mod correlation;
pub mod identify;
pub mod markup;
pub mod page;
pub mod positioning;
pub mod prediction;
pub mod selection;
pub mod source;
pub mod sweep;

use std::path::PathBuf;

pub use markup::{escape, sci};
pub use page::page;
pub use source::{load, Options, Tolerances};

/// What a section reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    Identification,
    Positioning,
    Sweep,
    /// The comparison of the page's identifications (AIC, BIC, F-tests).
    Selection,
    /// A prediction (`rtid predict -o`), or the predictions beside the records.
    Prediction,
}

impl Kind {
    /// The name in `--json` output and section headings.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Identification => "identification",
            Kind::Positioning => "positioning",
            Kind::Sweep => "sweep",
            Kind::Selection => "model selection",
            Kind::Prediction => "prediction",
        }
    }
}

/// One input file's part of the page.
#[derive(Clone, Debug)]
pub struct Section {
    pub kind: Kind,
    /// The input file as given.
    pub file: PathBuf,
    /// Heading text (not escaped).
    pub title: String,
    /// The section's HTML, without its heading.
    pub body: String,
}

/// A file's section, with what the page's own sections need of it: an
/// identification's result (model selection), a positioning record's axis values and
/// a prediction (the predictions beside the records).
pub struct Loaded {
    pub section: Section,
    pub fit: Option<crate::identify::IdentifyResult>,
    pub measured: Option<prediction::Measured>,
    pub prediction: Option<crate::prediction::Prediction>,
}

impl Loaded {
    /// A section the page needs nothing else of.
    pub fn alone(section: Section) -> Loaded {
        Loaded {
            section,
            fit: None,
            measured: None,
            prediction: None,
        }
    }
}

/// Why a section cannot be written; each names its file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HtmlError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a report input ({reason}); expected an identification result (`rtid identify --out`), an ISO 230-2 positioning experiment manifest (`\"kind\": \"positioning\"`), a prediction (`rtid predict -o`) or a sweep file (`rtid sweep --out`)")]
    Unrecognised { path: PathBuf, reason: String },
    #[error("{path}: malformed {what}: {message}")]
    Malformed {
        path: PathBuf,
        what: &'static str,
        message: String,
    },
    #[error("{path}: {given} is for {given_axis} axes, but this positioning test is of a {axis} axis: give {wanted} instead")]
    WrongTolerance {
        path: PathBuf,
        given: &'static str,
        given_axis: &'static str,
        axis: &'static str,
        wanted: &'static str,
    },
}
