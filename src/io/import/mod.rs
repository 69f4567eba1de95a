//! Records as labs export them, mapped onto rtid's experiment files: the channels of
//! a [`Recording`] (read by [`crate::io::formats`]) named to the roles of a kind
//! ([`kinds`]) by `--map ROLE=CHANNEL[*SCALE][:UNIT]` ([`mapping`]), converted to SI
//! ([`crate::io::formats::units`]), checked for glitches and gaps ([`glitches`]), and returned as the
//! experiment's [`Data`] with a manifest that records where they came from. A friction
//! map is made of constant-speed runs instead, one per file or one per plateau of a
//! stepped-speed record ([`runs`], [`plateaus`], `friction_map`).

mod auto_map;
pub mod drive_measurement;
mod friction_map;
pub mod glitches;
pub mod kinds;
pub mod mapping;
pub mod name_unit;
pub mod plateaus;
pub mod runs;
mod suggest;

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use crate::io::experiment_file::{
    check_uniform, Approaches, CommandUnit, Conditions, Data, Direction, Manifest, ServoTrace,
    Signal, MAX_MAGNITUDE,
};
use crate::io::formats::units::{self, Quantity};
use crate::io::formats::{Abscissa, Channel, Recording, Samples};
use crate::model::Axis;
use kinds::{ImportKind, Role};
use mapping::{MapSpec, Resolved};

/// A file read.
#[derive(Clone, Debug)]
pub struct Source {
    pub path: PathBuf,
    pub recording: Recording,
}

/// What to write.
#[derive(Clone, Debug)]
pub struct Request {
    pub kind: ImportKind,
    pub maps: Vec<MapSpec>,
    pub conditions: Conditions,
    /// `--condition` as given, for the provenance.
    pub conditions_given: Vec<String>,
    pub mechanism: Option<String>,
}

/// The experiment made of the sources.
#[derive(Clone, Debug)]
pub struct Imported {
    pub data: Data,
    pub manifest: Manifest,
    /// Glitches, gaps and the readers' notes, each naming file and line or sample.
    pub findings: Vec<String>,
}

/// Why a mapping could not make an experiment: one message naming the option, role,
/// channel or file.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ImportError(pub String);

/// One role's values in SI, and the channel they came from.
struct Filled<'a> {
    role: &'static Role,
    resolved: Resolved<'a>,
    /// The samples; a complex response's (`frf`) magnitudes.
    values: Vec<f64>,
    /// A complex response's phases, rad.
    phase: Option<Vec<f64>>,
}

/// Builds the experiment `request` asks for from `sources`.
pub fn build(sources: &[Source], request: &Request) -> Result<Imported, ImportError> {
    if request.kind == ImportKind::FrictionMap {
        return friction_map::build(sources, request);
    }
    let recordings: Vec<&Recording> = sources.iter().map(|s| &s.recording).collect();
    let mut chosen = None;
    let completed;
    let request = match auto_map::complete(request.kind, &recordings, &request.maps)? {
        Some((spec, note)) => {
            chosen = Some(note);
            let mut maps = request.maps.clone();
            maps.push(spec);
            completed = Request {
                maps,
                ..request.clone()
            };
            &completed
        }
        None => request,
    };
    let filled = fill(&recordings, request)?;
    check_magnitudes(&filled, |file| &sources[file].path)?;
    let data = if request.kind == ImportKind::Positioning {
        positioning(&filled)?
    } else {
        let axis_values = abscissa_of(&filled, request.kind)?;
        check_time_base(request.kind, &filled, &axis_values, |file| {
            &sources[file].path
        })?;
        assemble(request.kind, &filled, axis_values)?
    };
    let mut findings = findings(sources, &filled);
    findings.splice(0..0, chosen);
    let manifest = manifest(sources, request, &findings)?;
    Ok(Imported {
        data,
        manifest,
        findings,
    })
}

/// Every map resolved to its role and converted.
fn fill<'a>(
    recordings: &[&'a Recording],
    request: &Request,
) -> Result<Vec<Filled<'a>>, ImportError> {
    let kind = request.kind;
    let mut filled: Vec<Filled> = Vec::new();
    for spec in &request.maps {
        let role = kind
            .roles()
            .iter()
            .find(|r| r.name == spec.role)
            .ok_or_else(|| {
                ImportError(format!(
                    "--map {}: `{}` is not a role of {}; its roles: {}",
                    spec.given,
                    spec.role,
                    kind.name(),
                    kind.describe_roles()
                ))
            })?;
        if filled.iter().any(|f| f.role.name == role.name) {
            return Err(ImportError(format!(
                "--map: the role `{}` is mapped twice",
                role.name
            )));
        }
        let resolved = resolve(spec, role, recordings)?;
        let (values, phase) = if takes_abscissa(&resolved, role, &request.maps) {
            (abscissa_in_si(&resolved, role)?, None)
        } else {
            converted(&resolved, role)?
        };
        filled.push(Filled {
            role,
            resolved,
            values,
            phase,
        });
    }
    let missing: Vec<&str> = kind
        .roles()
        .iter()
        .filter(|r| r.required && !filled.iter().any(|f| f.role.name == r.name))
        .map(|r| r.name)
        .collect();
    if !missing.is_empty() {
        return Err(ImportError(format!(
            "{} needs --map for {} (its roles: {})",
            kind.name(),
            missing.join(", "),
            kind.describe_roles()
        )));
    }
    Ok(filled)
}

/// The map resolved, its unit checked against what the role measures. A complex
/// response (`frf`) is a ratio whatever the file calls its unit.
fn resolve<'a>(
    spec: &MapSpec,
    role: &Role,
    recordings: &[&'a Recording],
) -> Result<Resolved<'a>, ImportError> {
    let resolved = match mapping::resolve(spec, recordings) {
        Err(e)
            if role.quantities == [Quantity::Number]
                && !matches!(e, mapping::ResolveError::NoChannel { .. }) =>
        {
            // A ratio, as CHANNEL[*SCALE] or, for a name holding `:`, the whole
            // right-hand side.
            let bare = |channel: &str, scale: f64| MapSpec {
                unit: Some("1".into()),
                channel: channel.into(),
                scale,
                ..spec.clone()
            };
            mapping::resolve(&bare(&spec.channel, spec.scale), recordings)
                .or_else(|_| mapping::resolve(&bare(&spec.right, 1.0), recordings))
        }
        other => other,
    }
    .map_err(|e| ImportError(format!("--map {e}")))?;
    if !role.quantities.contains(&resolved.unit.quantity) {
        let wanted: Vec<&str> = role.quantities.iter().map(|q| q.name()).collect();
        return Err(ImportError(format!(
            "--map {}: {} is {} ({}), but `{}` takes {}",
            spec.given,
            resolved.channel.name,
            resolved.unit.quantity.name(),
            resolved.unit.symbol,
            role.name,
            wanted.join(" or ")
        )));
    }
    Ok(resolved)
}

/// Whether a `time` or `frequency` map takes its channel's abscissa rather than its
/// values: a complex channel (a frequency response's abscissa, its values not a
/// frequency), or one another map takes too (`frf=H`, `frequency=H:Hz`: the
/// abscissa of `H` in hertz, for a file whose units label says nothing).
fn takes_abscissa(r: &Resolved, role: &Role, maps: &[MapSpec]) -> bool {
    let name = &r.channel.name;
    matches!(role.name, "time" | "frequency")
        && !matches!(r.channel.abscissa, Abscissa::Index)
        && (matches!(r.channel.samples, Samples::Complex { .. })
            || maps
                .iter()
                .any(|m| m.role != role.name && (&m.channel == name || &m.right == name)))
}

/// The abscissa of the map's channel, in the map's unit, in SI.
fn abscissa_in_si(r: &Resolved, role: &Role) -> Result<Vec<f64>, ImportError> {
    let n = r.channel.samples.len();
    let raw = match &r.channel.abscissa {
        Abscissa::Uniform { start, step, .. } => (0..n).map(|i| start + i as f64 * step).collect(),
        Abscissa::Values { values, .. } => values.clone(),
        Abscissa::Index => {
            return Err(ImportError(format!(
                "--map {}: `{}` has no {} base in its file",
                r.spec.given, r.channel.name, role.name
            )))
        }
    };
    Ok(raw.into_iter().map(|v| v * r.factor).collect())
}

/// The channel's samples in SI; a complex channel (only for `frf`) as magnitudes and
/// phases.
fn converted(r: &Resolved, role: &Role) -> Result<(Vec<f64>, Option<Vec<f64>>), ImportError> {
    match (&r.channel.samples, role.name) {
        // `+ 0.0` writes a flipped zero as 0, not -0.
        (Samples::Real(v), _) => Ok((v.iter().map(|x| x * r.factor + 0.0).collect(), None)),
        (Samples::Complex { re, im }, "frf") => {
            let pairs = re.iter().zip(im);
            let magnitude = pairs.clone().map(|(a, b)| a.hypot(*b) * r.factor.abs());
            let phase = pairs.map(|(a, b)| crate::angle::wrap(b.atan2(*a) + sign_turn(r.factor)));
            Ok((magnitude.collect(), Some(phase.collect())))
        }
        (Samples::Complex { .. }, _) => Err(ImportError(format!(
            "--map {}: `{}` is complex; only `frf` takes a complex channel",
            r.spec.given, r.channel.name
        ))),
    }
}

/// A mapped value that is not finite, or beyond ±[`MAX_MAGNITUDE`] in SI, is not a
/// measurement (a recorder's NaN, a damaged cell, a unit slip): refused naming the
/// file, the line or sample, the channel and the map, here rather than by the reader of
/// what the import would write.
fn check_magnitudes<'p>(
    filled: &[Filled],
    path_of: impl Fn(usize) -> &'p Path,
) -> Result<(), ImportError> {
    for f in filled {
        let channel = f.resolved.channel;
        let Some((i, v)) = f
            .values
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite() || v.abs() > MAX_MAGNITUDE)
        else {
            continue;
        };
        let place = place(channel, i);
        let what = if v.is_finite() {
            format!("{v:e} in SI units, beyond ±1e15: not a measurement (a unit slip?)")
        } else {
            format!("{v} in SI units, not a finite number")
        };
        return Err(ImportError(format!(
            "{}, {place}: --map {}: `{}` is {what}",
            path_of(f.resolved.file).display(),
            f.resolved.spec.given,
            channel.name
        )));
    }
    Ok(())
}

/// The time base of a servo trace or a raw time record increases in uniform steps;
/// a step that does not (a gap, a skipped or repeated sample) is refused naming the
/// source's line, not the written file's row.
fn check_time_base<'p>(
    kind: ImportKind,
    filled: &[Filled],
    base: &[f64],
    path_of: impl Fn(usize) -> &'p Path,
) -> Result<(), ImportError> {
    if !matches!(
        kind,
        ImportKind::ServoTrace | ImportKind::FrequencyResponseTime
    ) {
        return Ok(());
    }
    let Some(source) = filled
        .iter()
        .find(|f| f.role.name == "time")
        .or(filled.first())
    else {
        return Ok(());
    };
    let (row, what) = match (
        base.windows(2).position(|w| w[1] <= w[0]),
        check_uniform(base),
    ) {
        (Some(i), _) => (
            i + 1,
            format!("the time {} s does not increase", base[i + 1]),
        ),
        (None, Err(e)) => (e.row, e.to_string()),
        (None, Ok(())) => return Ok(()),
    };
    let channel = source.resolved.channel;
    let place = place(channel, row);
    Err(ImportError(format!(
        "{}, {place}: the time base of `{}`: {what}",
        path_of(source.resolved.file).display(),
        channel.name
    )))
}

/// Whether `channel`'s abscissa is a frequency.
fn over_frequency(channel: &Channel) -> bool {
    let unit = match &channel.abscissa {
        Abscissa::Uniform { unit, .. } | Abscissa::Values { unit, .. } => unit,
        Abscissa::Index => return false,
    };
    units::parse(unit).is_ok_and(|u| u.quantity == Quantity::Frequency)
}

/// Where sample `index` of `channel` is: its line in a text file where each sample
/// is a line, else its 1-based number.
fn place(channel: &Channel, index: usize) -> String {
    match channel.first_line {
        Some(line) => format!("line {}", line + index),
        None => format!("sample {}", index + 1),
    }
}

/// A negative scale turns a complex response by half a turn.
fn sign_turn(factor: f64) -> f64 {
    if factor < 0.0 {
        std::f64::consts::PI
    } else {
        0.0
    }
}

/// The time (or frequency) base: the mapped `time`/`frequency` role, else the
/// abscissa every mapped channel shares, in SI.
fn abscissa_of(filled: &[Filled], kind: ImportKind) -> Result<Vec<f64>, ImportError> {
    let axis_role = if kind == ImportKind::FrequencyResponse {
        "frequency"
    } else {
        "time"
    };
    if let Some(f) = filled.iter().find(|f| f.role.name == axis_role) {
        return Ok(f.values.clone());
    }
    let first = filled
        .first()
        .ok_or_else(|| ImportError("no --map given".into()))?
        .resolved
        .channel;
    if let Some(other) = filled
        .iter()
        .find(|f| f.resolved.channel.abscissa != first.abscissa)
    {
        return Err(ImportError(format!(
            "`{}` and `{}` have different {axis_role} bases: map {axis_role}=CHANNEL",
            first.name, other.resolved.channel.name
        )));
    }
    abscissa_values(first, axis_role)
}

fn abscissa_values(channel: &Channel, axis_role: &str) -> Result<Vec<f64>, ImportError> {
    let n = channel.samples.len();
    let (unit, values) = match &channel.abscissa {
        Abscissa::Uniform { start, step, unit } => (
            unit,
            (0..n)
                .map(|i| start + i as f64 * step)
                .collect::<Vec<f64>>(),
        ),
        Abscissa::Values { values, unit } => (unit, values.clone()),
        Abscissa::Index => {
            return Err(ImportError(format!(
                "`{}` has no {axis_role} base in its file: map {axis_role}=CHANNEL:UNIT",
                channel.name
            )))
        }
    };
    let si = units::parse(unit)
        .ok()
        .filter(|u| matches!(u.quantity, Quantity::Time | Quantity::Frequency))
        .ok_or_else(|| {
            ImportError(format!(
                "`{}`: its abscissa's unit `{unit}` is not a time or frequency: give it, \
                 e.g. --map '{axis_role}={}:{}' (the abscissa of `{}` in that unit)",
                channel.name,
                channel.name,
                if axis_role == "time" { "s" } else { "Hz" },
                channel.name
            ))
        })?
        .si;
    Ok(values.into_iter().map(|v| v * si).collect())
}

/// The values of role `name`, if mapped.
fn role<'a>(filled: &'a [Filled], name: &str) -> Option<&'a Filled<'a>> {
    filled.iter().find(|f| f.role.name == name)
}

/// The experiment's data, every role the length of the time base.
fn assemble(kind: ImportKind, filled: &[Filled], base: Vec<f64>) -> Result<Data, ImportError> {
    for f in filled {
        let n = f.values.len();
        if n != base.len() {
            return Err(ImportError(format!(
                "`{}` ({}) has {n} samples but the {} base {}",
                f.resolved.channel.name,
                f.role.name,
                if kind == ImportKind::FrequencyResponse {
                    "frequency"
                } else {
                    "time"
                },
                base.len()
            )));
        }
    }
    match kind {
        ImportKind::ServoTrace => servo_trace(filled, base),
        ImportKind::TorqueCurve => torque_curve(filled, base),
        ImportKind::FrequencyResponse => frequency_response(filled, base),
        ImportKind::FrequencyResponseTime => frequency_response_time(filled, base),
        ImportKind::Positioning => positioning(filled),
        ImportKind::FrictionMap => Err(ImportError(
            "a friction map is made of runs, not of one time base".into(),
        )),
    }
}

/// The axis the positions (or a friction map's speed) say (all alike), and the effort
/// agreeing with it.
fn axis(filled: &[Filled]) -> Result<Axis, ImportError> {
    let mut found: Option<(Axis, &str)> = None;
    for f in filled {
        let positional = matches!(f.role.name, "effort" | "target" | "deviation" | "speed")
            || f.role.name.ends_with("position");
        let this = match f.resolved.unit.quantity {
            Quantity::Angle | Quantity::AngularVelocity | Quantity::Torque if positional => {
                Axis::Rotary
            }
            Quantity::Length | Quantity::Velocity | Quantity::Force if positional => Axis::Linear,
            _ => continue,
        };
        match found {
            Some((a, other)) if a != this => {
                return Err(ImportError(format!(
                    "`{}` is {} but `{other}` {}: one axis is rotary (rad, N·m) or linear (m, N)",
                    f.role.name,
                    f.resolved.unit.quantity.name(),
                    if a == Axis::Rotary {
                        "rotary"
                    } else {
                        "linear"
                    }
                )))
            }
            _ => found = Some((this, f.role.name)),
        }
    }
    Ok(found.map_or(Axis::Rotary, |(a, _)| a))
}

fn values(filled: &[Filled], name: &str) -> Option<Vec<f64>> {
    role(filled, name).map(|f| f.values.clone())
}

fn signal(filled: &[Filled], name: &str) -> Option<Signal> {
    role(filled, name).map(|f| Signal {
        unit: match f.resolved.unit.quantity {
            Quantity::Voltage => CommandUnit::Volt,
            Quantity::Current => CommandUnit::Ampere,
            Quantity::Torque => CommandUnit::NewtonMetre,
            _ => CommandUnit::Newton,
        },
        values: f.values.clone(),
    })
}

fn servo_trace(filled: &[Filled], time_s: Vec<f64>) -> Result<Data, ImportError> {
    let axis = axis(filled)?;
    let need =
        |name: &str| values(filled, name).ok_or_else(|| ImportError(format!("{name} not mapped")));
    Ok(Data::ServoTrace(ServoTrace {
        axis,
        time_s,
        reference_position: need("reference_position")?,
        position: need("position")?,
        table_position: values(filled, "table_position"),
        effort: need("effort")?,
        controller_output: signal(filled, "controller_output"),
        controller_added: signal(filled, "controller_added"),
        extra: Default::default(),
    }))
}

fn torque_curve(filled: &[Filled], time_s: Vec<f64>) -> Result<Data, ImportError> {
    let effort = values(filled, "effort").ok_or_else(|| ImportError("effort not mapped".into()))?;
    Ok(Data::effort_curve(
        axis(filled)?,
        time_s,
        effort,
        values(filled, "position"),
    ))
}

fn frequency_response(filled: &[Filled], frequency_hz: Vec<f64>) -> Result<Data, ImportError> {
    let (gain_db, phase_rad) =
        match (role(filled, "frf"), role(filled, "gain")) {
            (Some(_), Some(_)) => {
                return Err(ImportError(
                    "map either frf (complex) or gain (and phase), not both".into(),
                ))
            }
            (Some(f), None) => {
                if role(filled, "phase").is_some() {
                    return Err(ImportError(
                        "frf gives the phase: do not map phase too".into(),
                    ));
                }
                let gain = f.values.iter().map(|m| 20.0 * m.log10()).collect();
                (gain, f.phase.clone())
            }
            (None, Some(g)) => {
                let gain = match g.resolved.unit.quantity {
                    Quantity::Decibel => g.values.clone(),
                    _ => g.values.iter().map(|r| 20.0 * r.log10()).collect(),
                };
                (gain, values(filled, "phase"))
            }
            (None, None) => return Err(ImportError(
                "frequency-response needs --map frf=CHANNEL (a complex response) or gain=CHANNEL"
                    .into(),
            )),
        };
    Ok(Data::FrequencyResponse {
        frequency_hz,
        gain_db,
        phase_rad,
        extra: Default::default(),
    })
}

fn frequency_response_time(filled: &[Filled], time_s: Vec<f64>) -> Result<Data, ImportError> {
    let angle =
        |name: &str| values(filled, name).ok_or_else(|| ImportError(format!("{name} not mapped")));
    match (
        values(filled, "motor_torque"),
        values(filled, "motor_current"),
    ) {
        (Some(motor_torque_nm), None) => Ok(Data::FrequencyResponseTime {
            time_s,
            motor_torque_nm,
            motor_angle_rad: angle("motor_angle")?,
            table_angle_rad: angle("table_angle")?,
            extra: Default::default(),
        }),
        (None, Some(motor_current_a)) => Ok(Data::FrequencyResponseTimeCurrent {
            time_s,
            motor_current_a,
            motor_angle_rad: angle("motor_angle")?,
            table_angle_rad: angle("table_angle")?,
            extra: Default::default(),
        }),
        _ => Err(ImportError(
            "frequency-response-time needs exactly one of motor_torque and motor_current".into(),
        )),
    }
}

/// One row per approach: the four roles of equal length, directions by sign, runs
/// whole numbers from 1.
fn positioning(filled: &[Filled]) -> Result<Data, ImportError> {
    let get =
        |name: &str| role(filled, name).ok_or_else(|| ImportError(format!("{name} not mapped")));
    let (target, deviation) = (get("target")?, get("deviation")?);
    let (direction, run) = (get("direction")?, get("run")?);
    let n = target.values.len();
    if let Some(f) = [deviation, direction, run]
        .into_iter()
        .find(|f| f.values.len() != n)
    {
        return Err(ImportError(format!(
            "`{}` ({}) has {} rows but `{}` (target) {n}",
            f.resolved.channel.name,
            f.role.name,
            f.values.len(),
            target.resolved.channel.name
        )));
    }
    let directions = direction
        .values
        .iter()
        .enumerate()
        .map(|(i, &d)| match d {
            d if d > 0.0 => Ok(Direction::Up),
            d if d < 0.0 => Ok(Direction::Down),
            _ => Err(ImportError(format!(
                "`{}` row {}: direction {d}, neither positive nor negative",
                direction.resolved.channel.name,
                i + 1
            ))),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let runs = run
        .values
        .iter()
        .enumerate()
        .map(|(i, &r)| {
            (r >= 1.0 && r.fract() == 0.0 && r <= u32::MAX as f64)
                .then_some(r as u32)
                .ok_or_else(|| {
                    ImportError(format!(
                        "`{}` row {}: run {r} is not a whole number from 1",
                        run.resolved.channel.name,
                        i + 1
                    ))
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let approaches = Approaches {
        target: target.values.clone(),
        direction: directions,
        run: runs,
        deviation: deviation.values.clone(),
    };
    Ok(Data::positioning(axis(filled)?, approaches))
}

/// Glitches in every mapped real channel, gaps in the time base, and the readers'
/// notes, each naming the file and the line (or sample).
fn findings(sources: &[Source], filled: &[Filled]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for s in sources {
        for note in &s.recording.notes {
            out.push(format!("{}: {note}", s.path.display()));
        }
    }
    out.extend(filled.iter().filter_map(|f| f.resolved.note.clone()));
    for f in filled {
        let file = &sources[f.resolved.file].path;
        out.extend(channel_findings(
            file,
            f.resolved.channel,
            f.role.name == "time",
        ));
    }
    out
}

/// What [`glitches`] finds in one channel of `file`: gaps if it is a time base, else
/// its glitches; each naming the line (or the sample, in a binary file) and the value.
/// A spectrum (a channel over frequency) is not a signal's samples: its lines are not
/// checked.
pub fn channel_findings(file: &std::path::Path, channel: &Channel, is_time: bool) -> Vec<String> {
    let Samples::Real(raw) = &channel.samples else {
        return Vec::new();
    };
    if over_frequency(channel) {
        return Vec::new();
    }
    let place = |index: usize| format!("{}, {}", file.display(), place(channel, index));
    if is_time {
        return glitches::gaps(raw)
            .into_iter()
            .map(|index| {
                format!(
                    "{}: a gap in the time base `{}` ({} after {})",
                    place(index),
                    channel.name,
                    raw[index],
                    raw[index - 1]
                )
            })
            .collect();
    }
    glitches::glitches(raw)
        .into_iter()
        .map(|g| {
            format!(
                "{}: `{}` = {} is a glitch, {:.0} robust deviations from what its neighbours give ({}); kept, not smoothed",
                place(g.index),
                channel.name,
                g.value,
                g.deviations,
                crate::names::Num(g.neighbours)
            )
        })
        .collect()
}

/// The manifest: the kind, conditions and mechanism asked, and where the data came
/// from (files with their SHA-256 and format, the maps and conditions as given,
/// rtid's version, the findings).
fn manifest(
    sources: &[Source],
    request: &Request,
    findings: &[String],
) -> Result<Manifest, ImportError> {
    let mut m = Manifest::new(request.kind.kind());
    m.mechanism = request.mechanism.clone();
    m.conditions = request.conditions.clone();
    let files = sources
        .iter()
        .map(|s| {
            let sha256 = crate::io::provenance::sha256(&s.path).map_err(|e| {
                ImportError(format!("{}: cannot read to hash it: {e}", s.path.display()))
            })?;
            Ok(json!({
                "file": s.path.display().to_string(),
                "sha256": sha256,
                "format": s.recording.format,
            }))
        })
        .collect::<Result<Vec<Value>, ImportError>>()?;
    m.extra.insert(
        "import".into(),
        json!({
            "sources": files,
            "map": request.maps.iter().map(|m| m.given.clone()).collect::<Vec<_>>(),
            "conditions": request.conditions_given,
            "findings": findings,
            "rtid": crate::version::VERSION,
        }),
    );
    Ok(m)
}
