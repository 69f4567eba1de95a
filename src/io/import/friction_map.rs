//! `rtid import --kind friction-map`: constant-speed runs reduced to a friction map,
//! one row per run ([`super::runs`]). Each file is one run, the maps applied to each
//! file alike (the same channel names in every file); one file whose speed holds
//! several plateaus in turn — a stepped-speed record — gives one run per plateau
//! ([`super::plateaus`]). The findings say, per run, the file, the samples averaged,
//! the glitches dropped (each with its line) and the transient left out.

use std::ops::Range;

use serde_json::{json, Value};

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
            _ => taken.push(whole(only)?),
        },
        _ => {
            for r in &records {
                taken.push(whole(r)?);
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

/// The whole record as one run.
fn whole<'r, 'a>(r: &'r Record<'a>) -> Result<Taken<'r, 'a>, ImportError> {
    let range = 0..r.role("speed").values.len();
    let run = statistics(r, range.clone()).map_err(|e| r.error(e))?;
    Ok(Taken {
        record: r,
        range,
        run,
    })
}

/// The run over `range`, refused when it has not settled or is at rest.
fn statistics(r: &Record, range: Range<usize>) -> Result<Run, String> {
    let speed = &r.role("speed").values[range.clone()];
    let effort = &r.role("effort").values[range];
    let unit = speed_unit(r.axis);
    let run = runs::statistics(speed, effort).map_err(|e| match e {
        RunError::Drifting { .. } => format!("{e} (speeds in {unit})"),
        _ => e.to_string(),
    })?;
    if run.reference == 0.0 || run.speed == 0.0 {
        return Err("at rest (median speed 0): a run at rest is not on a friction map".to_string());
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
    for p in &segments.plateaus {
        match statistics(r, p.clone()) {
            Ok(run) => taken.push(Taken {
                record: r,
                range: p.clone(),
                run,
            }),
            Err(e) => refused.push(format!(
                "{}, {}: a plateau not taken as a run: {e}",
                r.file(),
                span(r, p.clone())
            )),
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
        return Err(ImportError(format!(
            "{}: none of its {} plateaus is a run: {}",
            r.file(),
            segments.plateaus.len(),
            refused.join("; ")
        )));
    }
    findings.extend(refused);
    Ok(())
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
