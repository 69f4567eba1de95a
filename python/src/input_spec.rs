//! The command line's `--input` specifications (`rtid simulate --help`), parsed as
//! `src/cli/model/simulate.rs` parses them, with the same messages.

use rtid::model::LoopMode;

/// A parsed input specification.
#[derive(Debug, Clone, PartialEq)]
pub enum InputSpec {
    Sine {
        freq_hz: f64,
        amp_nm: f64,
        offset_nm: f64,
    },
    Step {
        torque_nm: f64,
        at_s: f64,
    },
    File(std::path::PathBuf),
    Move {
        target_deg: f64,
        speed_deg_per_min: Option<f64>,
        loop_mode: Option<LoopMode>,
    },
    None,
}

/// Why a specification does not parse (the CLI's message).
#[derive(Debug)]
pub struct SpecError(pub String);

impl std::fmt::Display for SpecError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SpecError {}

/// Parses `sine:freq_hz=100,amp_nm=5`, `step:…`, `file:PATH`, `move:…` or `none`.
pub fn parse(s: &str) -> Result<InputSpec, SpecError> {
    let (kind, rest) = s.split_once(':').unwrap_or((s, ""));
    if kind == "file" {
        return if rest.is_empty() {
            Err(SpecError("file: needs a path, e.g. file:torque.csv".into()))
        } else {
            Ok(InputSpec::File(rest.into()))
        };
    }
    let mut fields = Fields::parse(kind, rest)?;
    let spec = match kind {
        "sine" => InputSpec::Sine {
            freq_hz: fields.number("freq_hz")?,
            amp_nm: fields.number("amp_nm")?,
            offset_nm: fields.optional("offset_nm")?.unwrap_or(0.0),
        },
        "step" => InputSpec::Step {
            torque_nm: fields.number("torque_nm")?,
            at_s: fields.optional("at_s")?.unwrap_or(0.0),
        },
        "move" => InputSpec::Move {
            target_deg: fields.number("target_deg")?,
            speed_deg_per_min: fields.optional("speed_deg_per_min")?,
            loop_mode: fields
                .take("loop")
                .map(|v| v.parse())
                .transpose()
                .map_err(|e: rtid::names::UnknownName| SpecError(e.to_string()))?,
        },
        "none" => InputSpec::None,
        other => {
            return Err(SpecError(format!(
                "unknown input `{other}`: expected sine:, step:, file:, move: or none"
            )))
        }
    };
    fields.finish()?;
    Ok(spec)
}

/// `key=value,…` fields of a specification.
struct Fields {
    kind: String,
    pairs: Vec<(String, String)>,
}

impl Fields {
    fn parse(kind: &str, rest: &str) -> Result<Self, SpecError> {
        let mut pairs = Vec::new();
        for part in rest.split(',').filter(|p| !p.trim().is_empty()) {
            let (k, v) = part
                .split_once('=')
                .ok_or_else(|| SpecError(format!("{kind}: `{part}` is not KEY=VALUE")))?;
            pairs.push((k.trim().to_string(), v.trim().to_string()));
        }
        Ok(Fields {
            kind: kind.into(),
            pairs,
        })
    }

    fn take(&mut self, key: &str) -> Option<String> {
        let i = self.pairs.iter().position(|(k, _)| k == key)?;
        Some(self.pairs.remove(i).1)
    }

    fn optional(&mut self, key: &str) -> Result<Option<f64>, SpecError> {
        let Some(v) = self.take(key) else {
            return Ok(None);
        };
        match v.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Some(x)),
            _ => Err(SpecError(format!(
                "{}: {key}=`{v}` is not a finite number",
                self.kind
            ))),
        }
    }

    fn number(&mut self, key: &str) -> Result<f64, SpecError> {
        self.optional(key)?
            .ok_or_else(|| SpecError(format!("{}: missing {key}=VALUE", self.kind)))
    }

    fn finish(self) -> Result<(), SpecError> {
        match self.pairs.first() {
            None => Ok(()),
            Some((k, _)) => Err(SpecError(format!("{}: unknown field `{k}`", self.kind))),
        }
    }
}
