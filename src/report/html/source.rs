//! Which kind of file an input is, by its content (not its name: a result may be
//! called anything), and its section.

use std::path::Path;

use serde_json::Value;

use super::{identify, positioning, prediction, sweep, HtmlError, Loaded};
use crate::identify::IdentifyResult;

/// Acceptance tolerances of the bidirectional accuracy A, one per kind of axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tolerances {
    /// Rotary axes, arc-seconds.
    pub arcsec: Option<f64>,
    /// Linear axes, µm.
    pub um: Option<f64>,
}

/// What the sections need beside their file.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Options {
    pub tolerances: Tolerances,
}

/// The section of the file `path`, whatever its kind (with the result, for an
/// identification).
pub fn load(path: &Path, options: &Options) -> Result<Loaded, HtmlError> {
    // A regular file of bounded size: a device or a pipe named by mistake would be
    // read for ever.
    let text = crate::io::read_input(path).map_err(|source| HtmlError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let unrecognised = |reason: String| HtmlError::Unrecognised {
        path: path.to_path_buf(),
        reason,
    };
    let text = crate::io::without_bom(&text);
    if text.starts_with(crate::sweep::stream::MAGIC) {
        return sweep::section(path).map(Loaded::alone);
    }
    let value: Value = serde_json::from_str(text)
        .map_err(|e| unrecognised(format!("not a sweep file, and not JSON: {e}")))?;
    match recognise(&value) {
        Some(Recognised::Identification) => identification(path, value),
        Some(Recognised::Positioning) => {
            let (section, measured) = positioning::section(path, &options.tolerances)?;
            Ok(Loaded {
                measured: Some(measured),
                ..Loaded::alone(section)
            })
        }
        Some(Recognised::Prediction) => {
            let (section, p) = prediction::section(path, value)?;
            Ok(Loaded {
                prediction: Some(p),
                ..Loaded::alone(section)
            })
        }
        Some(Recognised::OtherExperiment(kind)) => Err(unrecognised(format!(
            "an experiment manifest of kind `{kind}`; only positioning experiments are reported"
        ))),
        None => Err(unrecognised(
            "JSON without the fields of any of them".into(),
        )),
    }
}

enum Recognised {
    Identification,
    Positioning,
    Prediction,
    OtherExperiment(String),
}

/// The kind of a JSON document: a manifest by its `kind`, a result by the fields
/// only a result has.
fn recognise(v: &Value) -> Option<Recognised> {
    let o = v.as_object()?;
    if let Some(kind) = o.get("kind").and_then(Value::as_str) {
        return Some(match kind {
            "positioning" => Recognised::Positioning,
            other => Recognised::OtherExperiment(other.to_string()),
        });
    }
    let has = |keys: &[&str]| keys.iter().all(|k| o.contains_key(*k));
    if has(&["cases", "drawn", "level", "completed"]) {
        return Some(Recognised::Prediction);
    }
    has(&["parameters", "residuals", "termination"]).then_some(Recognised::Identification)
}

/// The section of a result file's JSON.
fn identification(path: &Path, value: Value) -> Result<Loaded, HtmlError> {
    let result: IdentifyResult =
        serde_json::from_value(value).map_err(|e| HtmlError::Malformed {
            path: path.to_path_buf(),
            what: "identification result (`rtid identify --out`)",
            message: e.to_string(),
        })?;
    let section = identify::section(path, &result)?;
    Ok(Loaded {
        fit: Some(result),
        ..Loaded::alone(section)
    })
}
