//! The `--input` specifications of a simulation (`rtid simulate --help`):
//! `sine:freq_hz=100,amp_nm=5`, `step:torque_nm=T[,at_s=S]`, `file:PATH`,
//! `move:target_deg=D[,speed_deg_per_min=V][,loop=…]` or `none`, parsed into an
//! [`InputSpec`] — one parser for the command line and the Python module.

use std::str::FromStr;

use crate::input::{Move, NoTorque, Samples, Sine, Step};
use crate::model::{LoopMode, Params};
use crate::recorder::Recorder;
use crate::sim::{SimError, Simulation};

/// A parsed input specification (units in the field names).
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

/// Why a specification does not parse: the message names the kind and the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SpecError(String);

impl InputSpec {
    /// The commanded table trajectory of a `move:` specification (from 0, rad).
    pub fn reference(&self) -> Option<Move> {
        match *self {
            InputSpec::Move {
                target_deg,
                speed_deg_per_min,
                ..
            } => Some(move_to(target_deg, speed_deg_per_min)),
            _ => None,
        }
    }

    /// Runs `duration` s of this input on `sim` (the model `p`) into `rec`. `torques`,
    /// when given, drive it open loop: the samples a `file:` specification names
    /// (read by the caller, which reports the file's errors), or an array's; a
    /// `file:` specification without them runs free. A move's reference is
    /// [`InputSpec::reference`].
    pub fn run<R: Recorder>(
        &self,
        sim: &mut Simulation,
        p: &Params,
        torques: Option<Samples>,
        duration: f64,
        rec: &mut R,
    ) -> Result<(), SimError> {
        if let Some(mut samples) = torques {
            return sim.run_open_loop(&mut samples, duration, rec);
        }
        match *self {
            InputSpec::Sine {
                freq_hz,
                amp_nm,
                offset_nm,
            } => {
                if freq_hz > 0.5 / sim.dt() {
                    return Err(SimError::AboveNyquist {
                        freq_hz,
                        dt: sim.dt(),
                    });
                }
                sim.run_open_loop(&mut Sine::new(freq_hz, amp_nm, offset_nm), duration, rec)
            }
            InputSpec::Step { torque_nm, at_s } => {
                sim.run_open_loop(&mut Step { torque_nm, at_s }, duration, rec)
            }
            InputSpec::File(_) | InputSpec::None => sim.run_open_loop(&mut NoTorque, duration, rec),
            InputSpec::Move {
                target_deg,
                speed_deg_per_min,
                loop_mode,
            } => {
                let mut q = p.clone();
                if let Some(m) = loop_mode {
                    q.controller.loop_mode = m;
                }
                let mut controller = sim.controller(&q)?;
                let reference = move_to(target_deg, speed_deg_per_min);
                sim.run_closed_loop(&mut controller, &reference, duration, rec)
            }
        }
    }
}

/// The move of the table from 0 to `target_deg`: a step command, or a ramp.
fn move_to(target_deg: f64, speed_deg_per_min: Option<f64>) -> Move {
    Move {
        from: 0.0,
        to: target_deg.to_radians(),
        speed: speed_deg_per_min.map(|v| v.to_radians() / 60.0),
    }
}

impl FromStr for InputSpec {
    type Err = SpecError;

    fn from_str(s: &str) -> Result<Self, SpecError> {
        parse(s)
    }
}

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
                .map_err(|e: crate::names::UnknownName| SpecError(e.to_string()))?,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn input_specs_parse() {
        assert_eq!(
            "sine:freq_hz=100,amp_nm=5".parse::<InputSpec>().unwrap(),
            InputSpec::Sine {
                freq_hz: 100.0,
                amp_nm: 5.0,
                offset_nm: 0.0
            }
        );
        assert_eq!(
            "move:target_deg=30,loop=full_closed"
                .parse::<InputSpec>()
                .unwrap(),
            InputSpec::Move {
                target_deg: 30.0,
                speed_deg_per_min: None,
                loop_mode: Some(LoopMode::FullClosed)
            }
        );
        assert_eq!(
            "file:a/b.csv".parse::<InputSpec>().unwrap(),
            InputSpec::File("a/b.csv".into())
        );
        assert_eq!("none".parse::<InputSpec>().unwrap(), InputSpec::None);
    }

    #[test]
    fn bad_input_specs_say_what_is_wrong() {
        for (spec, expect) in [
            ("sine:freq_hz=100", "missing amp_nm"),
            (
                "sine:freq_hz=abc,amp_nm=5",
                "freq_hz=`abc` is not a finite number",
            ),
            ("sine:freq_hz=1,amp_nm=5,phase=3", "unknown field `phase`"),
            ("chirp:f=1", "unknown input `chirp`"),
            ("move:target_deg=30,loop=open", "unknown loop `open`"),
            ("step:torque_nm", "`torque_nm` is not KEY=VALUE"),
        ] {
            let err = spec.parse::<InputSpec>().unwrap_err().to_string();
            assert!(err.contains(expect), "{spec}: {err}");
        }
    }
}
