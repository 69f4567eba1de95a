//! `--map ROLE=CHANNEL[*SCALE][:UNIT]`: which channel of a recording fills which role
//! of an experiment, multiplied by SCALE (a leading `-` flips the sign), in UNIT — the
//! unit of CHANNEL×SCALE, so that a computed role reads as what it is
//! (`effort=vir*35.15:N`: the controller output in volts times the drive gain in N/V
//! is a force in newtons). Without UNIT the channel's own unit label is used.
//!
//! Channel names are matched exactly as the file spells them, and may themselves hold
//! `*` or `:`: a map whose whole right-hand side names a channel takes it whole.

use crate::io::formats::units::{self, Unit, UnitError};
use crate::io::formats::{Channel, Recording};

/// One `--map` as written, split.
#[derive(Clone, Debug, PartialEq)]
pub struct MapSpec {
    /// As given on the command line.
    pub given: String,
    pub role: String,
    /// The right-hand side whole (a channel name may contain `*` and `:`).
    pub right: String,
    /// CHANNEL, SCALE and UNIT as split from the right-hand side.
    pub channel: String,
    pub scale: f64,
    pub unit: Option<String>,
}

/// Why a `--map` is not `ROLE=CHANNEL[*SCALE][:UNIT]`: each message quotes it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MapSpecError {
    #[error("`{text}`: write ROLE=CHANNEL[*SCALE][:UNIT]")]
    NoEquals { text: String },
    #[error("`{text}`: the role `{role}` is not a name (letters, digits, _)")]
    RoleNotAName { text: String, role: String },
    #[error("`{text}`: no channel named after `=`")]
    NoChannel { text: String },
    #[error("`{text}`: the scale must be a finite number other than 0")]
    BadScale { text: String },
}

/// Splits `ROLE=CHANNEL[*SCALE][:UNIT]`; the channel is looked up later ([`resolve`]).
pub fn parse(text: &str) -> Result<MapSpec, MapSpecError> {
    let (role, right) = text
        .split_once('=')
        .ok_or_else(|| MapSpecError::NoEquals { text: text.into() })?;
    let role = role.trim();
    if role.is_empty() || !role.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(MapSpecError::RoleNotAName {
            text: text.into(),
            role: role.into(),
        });
    }
    if right.trim().is_empty() {
        return Err(MapSpecError::NoChannel { text: text.into() });
    }
    let (rest, unit) = match right.rsplit_once(':') {
        Some((rest, unit)) if units::parse(unit).is_ok() || looks_like_unit(unit) => {
            (rest, Some(unit.trim().to_string()))
        }
        _ => (right, None),
    };
    let (channel, scale) = match rest.rsplit_once('*') {
        Some((channel, scale)) => match scale.trim().parse::<f64>() {
            Ok(s) if s.is_finite() && s != 0.0 => (channel, s),
            Ok(_) => return Err(MapSpecError::BadScale { text: text.into() }),
            Err(_) => (rest, 1.0),
        },
        None => (rest, 1.0),
    };
    Ok(MapSpec {
        given: text.to_string(),
        role: role.to_string(),
        right: right.to_string(),
        channel: channel.to_string(),
        scale,
        unit,
    })
}

/// A unit-shaped suffix (`%(…)`, `inc(…)`, a short word without spaces): taken as the
/// unit even when it is not a known one, so that the message names the unit rather
/// than a channel that does not exist.
fn looks_like_unit(text: &str) -> bool {
    let t = text.trim();
    t.starts_with("%(")
        || t.starts_with("inc(")
        || (!t.is_empty() && t.len() <= 8 && !t.contains(' '))
}

/// A map resolved against the recordings: the channel, its factor to SI and the unit.
#[derive(Clone, Debug)]
pub struct Resolved<'a> {
    pub spec: MapSpec,
    pub channel: &'a Channel,
    /// The file the channel came from (its index in the recordings).
    pub file: usize,
    pub unit: Unit,
    /// SI per sample value: scale × unit.
    pub factor: f64,
}

/// Why a map cannot be resolved against the recordings: each message starts with the
/// map as given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ResolveError {
    /// Neither CHANNEL nor the whole right-hand side is a channel; `present` lists the
    /// recordings' channels.
    #[error("{given}: no channel `{channel}`; the file has {}", listed(present))]
    NoChannel {
        given: String,
        channel: String,
        present: Vec<String>,
    },
    #[error(
        "{given}: `{channel}` is a channel of several of the files: import one file per experiment"
    )]
    SeveralFiles { given: String, channel: String },
    #[error("{given}: the channel `{channel}` has no unit in its file: add one, e.g. {role}={channel}:UNIT")]
    NoUnit {
        given: String,
        channel: String,
        role: String,
    },
    /// The unit (the map's, else the channel's label) is refused.
    #[error("{given}: {source}")]
    Unit { given: String, source: UnitError },
}

/// Looks the map's channel up in `recordings` (CHANNEL as split, else the whole
/// right-hand side), and its unit: the map's, else the channel's own label.
pub fn resolve<'a>(
    spec: &MapSpec,
    recordings: &[&'a Recording],
) -> Result<Resolved<'a>, ResolveError> {
    let (spec, (file, channel)) = match (
        find(recordings, &spec.channel),
        find(recordings, &spec.right),
    ) {
        (Some(found), _) => (spec.clone(), found),
        (None, Some(found)) => (
            MapSpec {
                channel: spec.right.clone(),
                scale: 1.0,
                unit: None,
                ..spec.clone()
            },
            found,
        ),
        (None, None) => return Err(missing(spec, recordings)),
    };
    if files_with(recordings, &spec.channel) > 1 {
        return Err(ResolveError::SeveralFiles {
            given: spec.given,
            channel: spec.channel,
        });
    }
    let unit_text = spec.unit.clone().unwrap_or_else(|| channel.unit.clone());
    if unit_text.trim().is_empty() {
        return Err(ResolveError::NoUnit {
            given: spec.given,
            channel: spec.channel,
            role: spec.role,
        });
    }
    let unit = units::parse(&unit_text).map_err(|source| ResolveError::Unit {
        given: spec.given.clone(),
        source,
    })?;
    let factor = spec.scale * unit.si;
    Ok(Resolved {
        spec,
        channel,
        file,
        unit,
        factor,
    })
}

/// How many of the recordings have a channel named `name`.
fn files_with(recordings: &[&Recording], name: &str) -> usize {
    recordings
        .iter()
        .filter(|r| r.channels.iter().any(|c| c.name == name))
        .count()
}

/// The channel named `name`, and its file's index: the first file that has one
/// ([`resolve`] refuses a name several files share).
fn find<'a>(recordings: &[&'a Recording], name: &str) -> Option<(usize, &'a Channel)> {
    recordings
        .iter()
        .enumerate()
        .find_map(|(i, r)| r.channels.iter().find(|c| c.name == name).map(|c| (i, c)))
}

/// The error for a channel not found: the ones there are.
fn missing(spec: &MapSpec, recordings: &[&Recording]) -> ResolveError {
    ResolveError::NoChannel {
        given: spec.given.clone(),
        channel: spec.channel.clone(),
        present: recordings
            .iter()
            .flat_map(|r| r.channels.iter().map(|c| c.name.clone()))
            .collect(),
    }
}

/// The channels' names quoted, for a message: `none` when there are none.
fn listed(names: &[String]) -> String {
    if names.is_empty() {
        "none".to_string()
    } else {
        names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::formats::{Abscissa, Samples};

    fn recording(names: &[(&str, &str)]) -> Recording {
        Recording {
            format: "test",
            channels: names
                .iter()
                .map(|(n, u)| Channel {
                    name: n.to_string(),
                    unit: u.to_string(),
                    abscissa: Abscissa::Index,
                    samples: Samples::Real(vec![1.0]),
                    first_line: None,
                })
                .collect(),
            notes: vec![],
        }
    }

    #[test]
    fn splits_channel_scale_and_unit() {
        let m = parse("effort=vir*35.15:N").unwrap();
        assert_eq!(
            (m.role.as_str(), m.channel.as_str(), m.scale),
            ("effort", "vir", 35.15)
        );
        assert_eq!(m.unit.as_deref(), Some("N"));
        let m = parse("effort=Torque actual value averaged*-1:%(9.84 mN·m)").unwrap();
        assert_eq!(m.channel, "Torque actual value averaged");
        assert_eq!(m.scale, -1.0);
        assert_eq!(m.unit.as_deref(), Some("%(9.84 mN·m)"));
        assert_eq!(parse("time=t").unwrap().unit, None);
    }

    #[test]
    fn refuses_what_is_not_a_map() {
        assert!(parse("vir")
            .unwrap_err()
            .to_string()
            .contains("ROLE=CHANNEL"));
        assert!(parse("=vir").is_err());
        assert!(parse("effort=").is_err());
        assert_eq!(
            parse("effort=vir*0:N"),
            Err(MapSpecError::BadScale {
                text: "effort=vir*0:N".into()
            })
        );
        assert!(parse("effort=vir*inf:N").is_err());
    }

    #[test]
    fn a_channel_named_with_star_and_colon_is_found_whole() {
        let recs = [recording(&[("a*b:c", "V"), ("q", "")])];
        let r = resolve(&parse("x=a*b:c").unwrap(), &recs.iter().collect::<Vec<_>>()).unwrap();
        assert_eq!(r.channel.name, "a*b:c");
        assert_eq!(r.factor, 1.0);
        let e = resolve(&parse("x=q").unwrap(), &recs.iter().collect::<Vec<_>>())
            .unwrap_err()
            .to_string();
        assert!(e.contains("no unit"), "{e}");
        let e = resolve(
            &parse("x=nope:m").unwrap(),
            &recs.iter().collect::<Vec<_>>(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("`a*b:c`") && e.contains("`q`"), "{e}");
    }

    #[test]
    fn a_name_several_files_share_is_refused() {
        let recs = [
            recording(&[("speed", "rpm")]),
            recording(&[("speed", "rpm")]),
        ];
        let e = resolve(&parse("x=speed").unwrap(), &recs.iter().collect::<Vec<_>>())
            .unwrap_err()
            .to_string();
        assert!(e.contains("several of the files"), "{e}");
    }

    #[test]
    fn the_unit_is_that_of_channel_times_scale() {
        let recs = [recording(&[("vir", "V"), ("w", "rpm")])];
        let r = resolve(
            &parse("effort=vir*35.15:N").unwrap(),
            &recs.iter().collect::<Vec<_>>(),
        )
        .unwrap();
        assert_eq!(r.factor, 35.15);
        let r = resolve(&parse("speed=w").unwrap(), &recs.iter().collect::<Vec<_>>()).unwrap();
        assert!((r.factor - std::f64::consts::PI / 30.0).abs() < 1e-15);
    }
}
