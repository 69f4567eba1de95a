//! `--map ROLE=CHANNEL[*SCALE][:UNIT]`: which channel of a recording fills which role
//! of an experiment, multiplied by SCALE (a leading `-` flips the sign), in UNIT — the
//! unit of CHANNEL×SCALE, so that a computed role reads as what it is
//! (`effort=vir*35.15:N`: the controller output in volts times the drive gain in N/V
//! is a force in newtons). Without UNIT the channel's own unit label is used.
//!
//! Channel names are matched exactly as the file spells them (blanks inside a
//! matrix's index aside: `rec.q(1, :)` is `rec.q(1,:)`), and may themselves hold `*`
//! or `:`: a map whose whole right-hand side names a channel takes it whole. A channel
//! without a unit label takes the unit its name ends in (`_deg`, `_nm`:
//! [`super::name_unit`]), with a note.

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
        Some((rest, unit))
            if balanced(unit) && (units::parse(unit).is_ok() || looks_like_unit(unit)) =>
        {
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

/// Whether every `(` in `text` is closed and every `)` opened: `%(9.84 mN·m)` is,
/// the `)*-1` after the `:` of `rec.q(1,:)*-1` is not (it is not a unit).
fn balanced(text: &str) -> bool {
    let mut depth = 0i32;
    for c in text.chars() {
        depth += match c {
            '(' => 1,
            ')' => -1,
            _ => 0,
        };
        if depth < 0 {
            return false;
        }
    }
    depth == 0
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
    /// Said of the resolution (a unit taken from the channel's name).
    pub note: Option<String>,
}

/// Why a map cannot be resolved against the recordings: each message starts with the
/// map as given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ResolveError {
    /// Neither CHANNEL nor the whole right-hand side is a channel; `suggestion` gives
    /// the closest names ([`super::suggest`]), starting with `; `.
    #[error("{given}: no channel `{channel}`{suggestion}")]
    NoChannel {
        given: String,
        channel: String,
        suggestion: String,
    },
    #[error(
        "{given}: `{channel}` is a channel of several of the files: import one file per experiment"
    )]
    SeveralFiles { given: String, channel: String },
    #[error("{given}: the channel `{channel}` has no unit in its file or its name: add one, e.g. {role}={channel}:UNIT")]
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
    let (unit_text, note) = unit_of(&spec, channel)?;
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
        note,
    })
}

/// The unit of a map: the map's, else the channel's label, else the unit the
/// channel's name ends in (with a note saying so).
fn unit_of(spec: &MapSpec, channel: &Channel) -> Result<(String, Option<String>), ResolveError> {
    if let Some(unit) = &spec.unit {
        return Ok((unit.clone(), None));
    }
    if !channel.unit.trim().is_empty() {
        return Ok((channel.unit.clone(), None));
    }
    match super::name_unit::unit_in_name(&channel.name) {
        Some(unit) => Ok((
            unit.to_string(),
            Some(format!(
                "--map {}: `{}` has no unit in its file; its name says {unit}, taken \
                 (give :UNIT in the map if it is not)",
                spec.given, channel.name
            )),
        )),
        None => Err(ResolveError::NoUnit {
            given: spec.given.clone(),
            channel: spec.channel.clone(),
            role: spec.role.clone(),
        }),
    }
}

/// How many of the recordings have a channel named `name`.
fn files_with(recordings: &[&Recording], name: &str) -> usize {
    recordings
        .iter()
        .filter(|r| r.channels.iter().any(|c| c.name == name))
        .count()
}

/// The channel named `name` (blanks in a trailing index ignored), and its file's
/// index: the first file that has one ([`resolve`] refuses a name several files
/// share).
fn find<'a>(recordings: &[&'a Recording], name: &str) -> Option<(usize, &'a Channel)> {
    let exact = |wanted: &str| {
        recordings
            .iter()
            .enumerate()
            .find_map(|(i, r)| r.channels.iter().find(|c| c.name == wanted).map(|c| (i, c)))
    };
    exact(name).or_else(|| {
        let squeezed = squeeze_index(name)?;
        exact(&squeezed)
    })
}

/// `rec.q( 1 , : )` as `rec.q(1,:)`: a trailing index without its blanks, if it had
/// any.
fn squeeze_index(name: &str) -> Option<String> {
    let name = name.trim();
    let base = super::suggest::base_name(name);
    let index = &name[base.len()..];
    if index.is_empty() || !index.contains(char::is_whitespace) {
        return None;
    }
    let index: String = index.chars().filter(|c| !c.is_whitespace()).collect();
    Some(format!("{base}{index}"))
}

/// The error for a channel not found: the closest there are.
fn missing(spec: &MapSpec, recordings: &[&Recording]) -> ResolveError {
    ResolveError::NoChannel {
        given: spec.given.clone(),
        channel: spec.channel.clone(),
        suggestion: super::suggest::suggestion(spec.channel.trim(), recordings),
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
            groups: vec![],
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
    fn a_matrix_row_with_a_scale_keeps_its_index() {
        let m = parse("position=rec.q(1,:)*-1").unwrap();
        assert_eq!(
            (m.channel.as_str(), m.scale, m.unit),
            ("rec.q(1,:)", -1.0, None)
        );
        let m = parse("position=rec.q(:,2)*2:deg").unwrap();
        assert_eq!((m.channel.as_str(), m.scale), ("rec.q(:,2)", 2.0));
        assert_eq!(m.unit.as_deref(), Some("deg"));
    }

    #[test]
    fn blanks_in_an_index_and_a_unit_in_the_name_are_understood() {
        let recs = [recording(&[("rec.act_pos_mot_deg(1,:)", ""), ("t", "")])];
        let recs: Vec<&Recording> = recs.iter().collect();
        let r = resolve(
            &parse("position=rec.act_pos_mot_deg( 1, : )").unwrap(),
            &recs,
        )
        .unwrap();
        assert_eq!(r.channel.name, "rec.act_pos_mot_deg(1,:)");
        assert!((r.factor - std::f64::consts::PI / 180.0).abs() < 1e-18);
        let note = r.note.expect("a note on the unit taken from the name");
        assert!(note.contains("its name says deg"), "{note}");
        let r = resolve(
            &parse("position=rec.act_pos_mot_deg(1,:):rad").unwrap(),
            &recs,
        )
        .unwrap();
        assert_eq!((r.factor, r.note), (1.0, None));
    }

    #[test]
    fn a_missing_channel_names_the_closest_few_not_thousands() {
        let names: Vec<String> = (0..5000).map(|k| format!("sig_{k}")).collect();
        let pairs: Vec<(&str, &str)> = names.iter().map(|n| (n.as_str(), "V")).collect();
        let recs = [recording(&pairs)];
        let e = resolve(
            &parse("x=sig_12x").unwrap(),
            &recs.iter().collect::<Vec<_>>(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.len() < 300, "{} bytes: {e}", e.len());
        assert!(e.contains("`sig_12`") && e.contains("and 4995 more"), "{e}");
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
