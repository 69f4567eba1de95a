//! The map a kind makes itself when `--map` does not give it: a kind made of one role
//! (a frequency response of its complex `frf`, a torque curve of its `effort`) takes
//! the one channel of the files that fits it, and says so in a note. Anything less
//! clear — no channel that fits, or several — is left to the maps given, or, with no
//! map at all, is an error listing the roles.

use super::kinds::ImportKind;
use super::mapping::MapSpec;
use super::ImportError;
use crate::io::formats::units::{self, Quantity};
use crate::io::formats::{Channel, Recording, Samples};

/// A role that stands in for the sole role (a frequency response's `gain`).
fn alternatives(role: &str) -> &'static [&'static str] {
    match role {
        "frf" => &["gain", "phase"],
        _ => &[],
    }
}

/// Whether a channel can fill a role alone.
type Fits = fn(&Channel) -> bool;

/// The one role `kind` can be made of alone, and whether a channel fits it.
fn sole_role(kind: ImportKind) -> Option<(&'static str, Fits)> {
    match kind {
        ImportKind::FrequencyResponse => {
            Some(("frf", |c| matches!(c.samples, Samples::Complex { .. })))
        }
        ImportKind::TorqueCurve => Some(("effort", |c| {
            matches!(c.samples, Samples::Real(_))
                && units::parse(&c.unit)
                    .is_ok_and(|u| matches!(u.quantity, Quantity::Torque | Quantity::Force))
        })),
        _ => None,
    }
}

/// The map of the kind's sole role when `given` lacks it and one channel fits, with
/// the note saying what was chosen.
pub fn complete(
    kind: ImportKind,
    recordings: &[&Recording],
    given: &[MapSpec],
) -> Result<Option<(MapSpec, String)>, ImportError> {
    let refuse = |why: String| {
        ImportError(format!(
            "--map: no channel mapped{why}; {} takes {} (rtid import FILE --list shows the channels)",
            kind.name(),
            kind.describe_roles()
        ))
    };
    let Some((role, fits)) = sole_role(kind) else {
        return match given {
            [] => Err(refuse(String::new())),
            _ => Ok(None),
        };
    };
    if given
        .iter()
        .any(|m| m.role == role || alternatives(role).contains(&m.role.as_str()))
    {
        return Ok(None);
    }
    let fitting: Vec<&Channel> = recordings
        .iter()
        .flat_map(|r| &r.channels)
        .filter(|c| fits(c))
        .collect();
    let channel = match (fitting.as_slice(), given) {
        ([one], _) => one,
        (_, [_, ..]) => return Ok(None),
        ([], []) => return Err(refuse(format!(", and no channel fits `{role}` alone"))),
        (several, []) => {
            return Err(refuse(format!(
                ", and {} channels fit `{role}`: name one",
                several.len()
            )))
        }
    };
    let spec = MapSpec {
        given: format!("{role}={}", channel.name),
        role: role.to_string(),
        right: channel.name.clone(),
        channel: channel.name.clone(),
        scale: 1.0,
        unit: None,
    };
    let note = format!(
        "no --map for {role}: `{}`, the one channel that fits it, is mapped to it",
        channel.name
    );
    Ok(Some((spec, note)))
}
