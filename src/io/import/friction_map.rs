//! `rtid import --kind friction-map`: constant-speed runs reduced to a friction map,
//! one row per run ([`super::runs`]). Each file is one run, the maps applied to each
//! file alike (the same channel names in every file); one file whose speed holds
//! several plateaus in turn — a stepped-speed record — gives one run per plateau
//! ([`super::plateaus`]). The findings say, per run, the file, the samples averaged,
//! the glitches dropped (each with its line) and the transient left out.
//!
//! A run at rest is not on the map: a run whose median speed is at most [`REST`]
//! (a thousandth) of the fastest median speed among the map's candidate runs (its
//! files, or the plateaus of its one file) — what a drive holding its position reads
//! (the robot axis of `fixtures/formats/matlab/kuka/`, row 1 creeps at 0.04 to 0.07 % of its top
//! speed before it starts; the slowest runs of the shared EPOS drives are at 0.5 to
//! 1 % of their fastest). When no candidate of a stepped-speed record is a run, one
//! error says why, counting the candidates refused for each reason.

use std::ops::Range;

use serde_json::{json, Value};

use super::glitches::median;
use super::plateaus::{plateaus, Segments};
use super::runs::{self, short, Run, RunError};
use super::{axis, channel_findings, check_magnitudes, fill, manifest, role, Filled};
use super::{ImportError, Imported, Request, Source};
use crate::io::experiment_file::{Data, FrictionMap};
use crate::io::formats::{Channel, Samples};
use crate::model::Axis;

/// One file's channels mapped onto the roles, in SI.
struct Record<'a> {
    source: &'a Source,
    filled: Vec<Filled<'a>>,
    axis: Axis,
}

impl Record<'_> {
    fn role(&self, name: &str) -> &Filled<'_> {
        role(&self.filled, name).expect("speed and effort are required roles")
    }

    fn file(&self) -> String {
        self.source.path.display().to_string()
    }

    /// "FILE: message".
    fn error(&self, message: impl std::fmt::Display) -> ImportError {
        ImportError(format!("{}: {message}", self.file()))
    }
}

/// A run taken into the map: its record, the samples it was computed over, and its
/// statistics (indices relative to `range.start`).
struct Taken<'r, 'a> {
    record: &'r Record<'a>,
    range: Range<usize>,
    run: Run,
}

/// A run's median speed at most this fraction of the fastest candidate's is at rest.
pub const REST: f64 = 1e-3;

/// Why a candidate is not a run.
#[derive(Clone, Debug, PartialEq)]
enum Refusal {
    /// Its statistics say it has not settled or is not steady.
    Run(RunError),
    /// Its median speed is at most [`REST`] of the fastest candidate's.
    Rest { median: f64, fastest: f64 },
}

impl Refusal {
    /// The message, speeds in `unit`.
    fn message(&self, unit: &str) -> String {
        match self {
            Refusal::Run(e @ RunError::Drifting { .. }) => format!("{e} (speeds in {unit})"),
            Refusal::Run(e) => e.to_string(),
            Refusal::Rest { median, fastest } => format!(
                "at rest: median speed {} {unit}, at most {} of the fastest candidate's {} {unit} \
                 (a run at rest is not on a friction map)",
                short(*median),
                REST,
                short(*fastest)
            ),
        }
    }

    /// What the refused candidates of one kind share, for the summary.
    fn kind(&self) -> &'static str {
        match self {
            Refusal::Run(RunError::SpeedChanges { .. }) => "change their speed within the run",
            Refusal::Run(RunError::EffortDrifts { .. }) => {
                "have an effort that drifts within the run"
            }
            Refusal::Run(RunError::Drifting { .. }) => "drift between their halves",
            Refusal::Run(RunError::TooFew { .. }) => "have fewer than 10 samples once settled",
            Refusal::Run(_) => "are not runs",
            Refusal::Rest { .. } => "are at rest",
        }
    }
}

/// The friction map of `sources` (`request.kind` is `friction-map`).
pub(super) fn build(sources: &[Source], request: &Request) -> Result<Imported, ImportError> {
    let records = sources
        .iter()
        .map(|s| record(s, request))
        .collect::<Result<Vec<_>, _>>()?;
    let first = records
        .first()
        .ok_or_else(|| ImportError("no file given".into()))?;
    if let Some(other) = records.iter().find(|r| r.axis != first.axis) {
        return Err(ImportError(format!(
            "{} is {} but {} {}: the runs of one map are all rotary (rad/s, N·m) or all linear (m/s, N)",
            other.file(),
            other.axis.name(),
            first.file(),
            first.axis.name()
        )));
    }
    let mut findings = source_findings(&records);
    let mut taken = Vec::new();
    match records.as_slice() {
        [only] => match plateaus(&only.role("speed").values) {
            s if s.plateaus.len() >= 2 => stepped(only, &s, &mut taken, &mut findings)?,
            _ => taken.push(whole(only, 0.0)?),
        },
        _ => {
            let whole_range = |r: &Record| 0..r.role("speed").values.len();
            let fastest = fastest(records.iter().map(|r| (r, whole_range(r))));
            for r in &records {
                taken.push(whole(r, fastest)?);
            }
        }
    }
    for t in &taken {
        findings.extend(run_findings(t));
    }
    taken.sort_by(|a, b| a.run.speed.total_cmp(&b.run.speed));
    if let Some(w) = taken.windows(2).find(|w| w[0].run.speed == w[1].run.speed) {
        return Err(ImportError(format!(
            "{} ({}) and {} ({}) have the same mean speed {}: one row per speed",
            w[0].record.file(),
            span(w[0].record, w[0].range.clone()),
            w[1].record.file(),
            span(w[1].record, w[1].range.clone()),
            w[0].run.speed
        )));
    }
    let data = Data::FrictionMap(map(first.axis, &taken));
    let mut manifest = manifest(sources, request, &findings)?;
    let runs: Vec<Value> = taken
        .iter()
        .map(|t| {
            let averaged = t.range.start + t.run.averaged.start..t.range.end;
            json!({"file": t.record.file(), "averaged": span(t.record, averaged)})
        })
        .collect();
    if let Some(import) = manifest.extra.get_mut("import") {
        import["runs"] = Value::Array(runs);
    }
    Ok(Imported {
        data,
        manifest,
        findings,
    })
}

/// The maps resolved against one file, speed and effort of equal length (and the time
/// base too, when mapped), on one axis.
fn record<'a>(source: &'a Source, request: &Request) -> Result<Record<'a>, ImportError> {
    let in_file = |e: ImportError| ImportError(format!("{}: {}", source.path.display(), e.0));
    let filled = fill(&[&source.recording], request).map_err(in_file)?;
    check_magnitudes(&filled, |_| &source.path)?;
    let axis = axis(&filled).map_err(in_file)?;
    let r = Record {
        source,
        filled,
        axis,
    };
    let speed = r.role("speed");
    let n = speed.values.len();
    if let Some(f) = r.filled.iter().find(|f| f.values.len() != n) {
        return Err(r.error(format!(
            "`{}` ({}) has {} samples but `{}` (speed) {n}",
            f.resolved.channel.name,
            f.role.name,
            f.values.len(),
            speed.resolved.channel.name
        )));
    }
    Ok(r)
}

/// The whole record as one run, the fastest candidate's median speed `fastest`.
fn whole<'r, 'a>(r: &'r Record<'a>, fastest: f64) -> Result<Taken<'r, 'a>, ImportError> {
    let range = 0..r.role("speed").values.len();
    let run = statistics(r, range.clone(), fastest)
        .map_err(|e| r.error(e.message(speed_unit(r.axis))))?;
    Ok(Taken {
        record: r,
        range,
        run,
    })
}

/// The largest |median speed| of the candidates (record, range).
fn fastest<'r, 'a: 'r>(candidates: impl Iterator<Item = (&'r Record<'a>, Range<usize>)>) -> f64 {
    candidates
        .map(|(r, range)| median_speed(r, range).abs())
        .fold(0.0, f64::max)
}

fn median_speed(r: &Record, range: Range<usize>) -> f64 {
    median(&mut r.role("speed").values[range].to_vec())
}

/// The run over `range`, refused when it is at rest ([`REST`] of `fastest`) or has
/// not settled or is not steady ([`runs::statistics`]).
fn statistics(r: &Record, range: Range<usize>, fastest: f64) -> Result<Run, Refusal> {
    let median = median_speed(r, range.clone());
    if median.abs() <= REST * fastest || median == 0.0 {
        return Err(Refusal::Rest { median, fastest });
    }
    let speed = &r.role("speed").values[range.clone()];
    let effort = &r.role("effort").values[range];
    let run = runs::statistics(speed, effort).map_err(Refusal::Run)?;
    if run.speed == 0.0 {
        return Err(Refusal::Rest { median, fastest });
    }
    Ok(run)
}

/// One run per plateau of a stepped-speed record; plateaus that have not settled, or
/// hold the drive at rest, are said and left out.
fn stepped<'r, 'a>(
    r: &'r Record<'a>,
    segments: &Segments,
    taken: &mut Vec<Taken<'r, 'a>>,
    findings: &mut Vec<String>,
) -> Result<(), ImportError> {
    let mut refused = Vec::new();
    let mut reasons = Vec::new();
    let fastest = fastest(segments.plateaus.iter().map(|p| (r, p.clone())));
    let unit = speed_unit(r.axis);
    for p in &segments.plateaus {
        match statistics(r, p.clone(), fastest) {
            Ok(run) => taken.push(Taken {
                record: r,
                range: p.clone(),
                run,
            }),
            Err(e) => {
                refused.push(format!(
                    "{}, {}: a plateau not taken as a run: {}",
                    r.file(),
                    span(r, p.clone()),
                    e.message(unit)
                ));
                reasons.push(e);
            }
        }
    }
    let spans = |ranges: &mut dyn Iterator<Item = Range<usize>>| {
        let all: Vec<String> = ranges.map(|x| span(r, x)).collect();
        if all.is_empty() {
            "none".to_string()
        } else {
            all.join(", ")
        }
    };
    findings.push(format!(
        "{}: a stepped-speed record, its plateaus taken as runs: {}; left out as transitions: {}",
        r.file(),
        spans(&mut taken.iter().map(|t| t.range.clone())),
        spans(&mut segments.transitions.iter().cloned()),
    ));
    if taken.is_empty() {
        return Err(r.error(none_taken(&reasons)));
    }
    let positive = taken.iter().filter(|t| t.run.speed > 0.0).count();
    if !reasons.is_empty() && (positive == 0 || positive == taken.len()) {
        // A few stretches that pass among many that do not, all one way: not a map.
        return Err(r.error(format!(
            "{} of its {} candidate plateaus hold their speed, all in the {} direction \
             (at {}): a friction map needs runs both ways; of the other {}, {}",
            taken.len(),
            taken.len() + reasons.len(),
            if positive == 0 {
                "negative"
            } else {
                "positive"
            },
            spans(&mut taken.iter().map(|t| t.range.clone())),
            reasons.len(),
            refusals(&reasons)
        )));
    }
    findings.extend(refused);
    Ok(())
}

/// Why none of the candidates `reasons` (one each) of a stepped-speed record is a run:
/// how many were refused for each reason, with the range of the figure that refused
/// them.
fn none_taken(reasons: &[Refusal]) -> String {
    format!(
        "no constant-speed run: of its {} candidate plateaus (at least {} samples within 5 % of \
         one speed), {}; a friction map is made of runs that hold their speed",
        reasons.len(),
        runs::MIN_SAMPLES,
        refusals(reasons)
    )
}

/// How many candidates were refused for each reason, with the range of the figure
/// that refused them.
fn refusals(reasons: &[Refusal]) -> String {
    let mut kinds: Vec<&'static str> = reasons.iter().map(Refusal::kind).collect();
    kinds.sort_unstable();
    kinds.dedup();
    let parts: Vec<String> = kinds
        .iter()
        .map(|&kind| {
            let of_kind: Vec<&Refusal> = reasons.iter().filter(|x| x.kind() == kind).collect();
            let figures: Vec<f64> = of_kind.iter().filter_map(|x| figure(x)).collect();
            let range = match (
                figures.iter().copied().reduce(f64::min),
                figures.iter().copied().reduce(f64::max),
            ) {
                (Some(lo), Some(hi)) if lo == hi => format!(" ({})", short(lo)),
                (Some(lo), Some(hi)) => format!(" ({} to {})", short(lo), short(hi)),
                _ => String::new(),
            };
            let what = match of_kind[0] {
                Refusal::Run(RunError::SpeedChanges { .. }) => " % of its mean",
                Refusal::Run(RunError::EffortDrifts { .. }) => " times its scatter",
                Refusal::Rest { .. } => " of the fastest candidate's speed",
                _ => "",
            };
            let range = range.replace(')', &format!("{what})"));
            format!("{} {kind}{range}", of_kind.len())
        })
        .collect();
    parts.join(", ")
}

/// The figure of a refusal the summary ranges over: the speed's change in % of its
/// mean, the effort's drift in scatters, the median speed in fractions of the
/// fastest.
fn figure(refusal: &Refusal) -> Option<f64> {
    match *refusal {
        Refusal::Run(RunError::SpeedChanges { change, mean, .. }) => {
            Some(100.0 * change / mean.abs())
        }
        Refusal::Run(RunError::EffortDrifts { change, scatter }) => Some(change / scatter),
        Refusal::Rest { median, fastest } if fastest > 0.0 => Some(median.abs() / fastest),
        _ => None,
    }
}

/// The readers' notes and the gaps of mapped time bases, each naming its file.
fn source_findings(records: &[Record]) -> Vec<String> {
    let mut out = Vec::new();
    for r in records {
        for note in &r.source.recording.notes {
            out.push(format!("{}: {note}", r.file()));
        }
        if let Some(time) = role(&r.filled, "time") {
            out.extend(channel_findings(
                &r.source.path,
                time.resolved.channel,
                true,
            ));
        }
    }
    out
}

/// What one run's findings say: where it is, what it averaged, what it dropped as
/// glitches (each with its line and value as the file has it) and the transient it
/// left out.
fn run_findings(t: &Taken) -> Vec<String> {
    let (r, run, at) = (t.record, &t.run, t.range.start);
    let speed = r.role("speed");
    let unit = speed.resolved.unit;
    let si = speed_unit(r.axis);
    let transient = match (run.transient.first(), run.transient.last()) {
        (Some(&a), Some(&b)) => format!(" ({})", span(r, at + a..at + b + 1)),
        _ => String::new(),
    };
    let mut out = vec![format!(
        "{}: a run at {} {si} ({} {} as mapped), effort {} {}: {} samples averaged ({}), \
         {} dropped as glitches, {} left out as the transient{transient}",
        r.file(),
        short(run.speed),
        short(run.speed / unit.si),
        unit.symbol,
        short(run.effort),
        r.axis.effort_unit(),
        run.samples,
        span(r, at + run.averaged.start..t.range.end),
        run.dropped.len(),
        run.transient.len(),
    )];
    let glitches = [
        (r.role("speed"), &run.speed_glitches),
        (r.role("effort"), &run.effort_glitches),
    ];
    for (f, found) in glitches {
        for g in found.iter() {
            let index = at + g.index;
            let raw = match &f.resolved.channel.samples {
                Samples::Real(v) => v[index],
                Samples::Complex { .. } => g.value,
            };
            let factor = f.resolved.factor;
            out.push(format!(
                "{}: `{}` = {raw} is a glitch, {:.0} robust deviations from what its neighbours give ({}); dropped from the run's means",
                place(f.resolved.channel, &r.file(), index),
                f.resolved.channel.name,
                g.deviations,
                crate::names::Num(g.neighbours / factor)
            ));
        }
    }
    out
}

/// The SI unit of a speed on `axis`.
fn speed_unit(axis: Axis) -> &'static str {
    match axis {
        Axis::Rotary => "rad/s",
        Axis::Linear => "m/s",
    }
}

/// "FILE, line L" (or "FILE, sample S" in a file without lines) of sample `index`.
fn place(channel: &Channel, file: &str, index: usize) -> String {
    match channel.first_line {
        Some(line) => format!("{file}, line {}", line + index),
        None => format!("{file}, sample {}", index + 1),
    }
}

/// "lines A–B" (or "samples A–B") of the speed channel's samples in `range`.
fn span(r: &Record, range: Range<usize>) -> String {
    let (first, last) = (range.start, range.end.saturating_sub(1).max(range.start));
    let (what, offset) = match r.role("speed").resolved.channel.first_line {
        Some(line) => ("line", line),
        None => ("sample", 1),
    };
    if first == last {
        format!("{what} {}", first + offset)
    } else {
        format!("{what}s {}–{}", first + offset, last + offset)
    }
}

/// The rows of the runs taken, in the order given (by speed).
fn map(axis: Axis, taken: &[Taken]) -> FrictionMap {
    let column = |f: fn(&Run) -> f64| taken.iter().map(|t| f(&t.run)).collect::<Vec<f64>>();
    let mut m = FrictionMap::new(axis, column(|r| r.speed), column(|r| r.effort));
    m.speed_std = Some(column(|r| r.speed_std));
    m.effort_std = Some(column(|r| r.effort_std));
    m.samples = Some(column(|r| r.samples as f64));
    m.dropped = Some(column(|r| r.dropped.len() as f64));
    m.transient = Some(column(|r| r.transient.len() as f64));
    m
}
