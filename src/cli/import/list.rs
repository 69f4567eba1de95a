//! `rtid import --list`: what each file holds, each channel as the file spells it,
//! a matrix's signals once (its shape and orientation), narrowed by `--filter`.

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use serde_json::{json, Value};

use rtid::io::experiment_file;
use rtid::io::formats::{Abscissa, Channel, Group, Recording, Samples};
use rtid::io::import::name_unit::unit_in_name;
use rtid::io::import::{self, Source};

/// With a filter, matrices are listed signal by signal when the listing stays this
/// short.
const EXPAND_UP_TO: usize = 60;

/// One line of a listing: a channel, or a matrix cut into channels, shown once.
enum Entry<'a> {
    Channel(&'a Channel),
    Matrix(&'a Group),
}

/// `--list`: each file's channels, those whose names contain `filter` (any case).
pub fn list(sources: &[Source], filter: Option<&str>, json: bool) -> anyhow::Result<()> {
    if json {
        let all: Vec<Value> = sources.iter().map(|s| list_json(s, filter)).collect();
        let out = if all.len() == 1 {
            all[0].clone()
        } else {
            Value::Array(all)
        };
        println!("{}", rtid::io::json::pretty(&out)?);
        return Ok(());
    }
    for s in sources {
        let entries = entries(&s.recording, filter);
        println!("{}", title(s, filter, &entries));
        println!("{}", table(&s.recording, &entries));
        if entries.iter().any(|e| offered_unit(e).is_some()) {
            println!(
                "(UNIT): no unit in the file; its name ends in UNIT, which a map without :UNIT takes"
            );
        }
        let channels = channels_of(&s.recording, &entries);
        for note in s.recording.notes.iter().chain(&glitch_notes(s, &channels)) {
            println!("note: {note}");
        }
    }
    Ok(())
}

/// `FILE (format, N channels[, M of them in K matrices][; L lines match `TEXT`])`.
fn title(s: &Source, filter: Option<&str>, entries: &[Entry]) -> String {
    let r = &s.recording;
    let mut text = format!(
        "{} ({}, {} channels",
        s.path.display(),
        r.format,
        r.channels.len()
    );
    if !r.groups.is_empty() {
        let cut: usize = r.groups.iter().map(|g| g.channels.len()).sum();
        text += &format!(", {cut} of them in {} matrices", r.groups.len());
    }
    if let Some(f) = filter {
        text += &format!("; {} lines match `{f}`", entries.len());
    }
    text + ")"
}

/// Whether `name` contains `filter`, ignoring case (no filter: every name).
fn matches(name: &str, filter: Option<&str>) -> bool {
    filter.map_or(true, |f| name.to_lowercase().contains(&f.to_lowercase()))
}

/// The lines of a listing in file order: each channel not cut from a matrix, each
/// matrix once; with a filter, those matching it, the matrices signal by signal if
/// that keeps the listing within [`EXPAND_UP_TO`] lines.
fn entries<'a>(r: &'a Recording, filter: Option<&str>) -> Vec<Entry<'a>> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < r.channels.len() {
        if let Some(g) = r.groups.iter().find(|g| g.channels.start == i) {
            if matches(&g.name, filter) {
                out.push(Entry::Matrix(g));
            }
            i = g.channels.end.max(i + 1);
            continue;
        }
        if matches(&r.channels[i].name, filter) {
            out.push(Entry::Channel(&r.channels[i]));
        }
        i += 1;
    }
    let expanded = channels_of(r, &out);
    if filter.is_some() && expanded.len() <= EXPAND_UP_TO {
        return expanded.into_iter().map(Entry::Channel).collect();
    }
    out
}

/// The channels the entries stand for, a matrix's all.
fn channels_of<'a>(r: &'a Recording, entries: &[Entry<'a>]) -> Vec<&'a Channel> {
    entries
        .iter()
        .flat_map(|e| match e {
            Entry::Channel(c) => std::slice::from_ref(*c).iter().collect::<Vec<_>>(),
            Entry::Matrix(g) => r.channels[g.channels.clone()].iter().collect(),
        })
        .collect()
}

/// The unit an entry's name ends in, where the file gives it none.
fn offered_unit(e: &Entry) -> Option<&'static str> {
    match e {
        Entry::Channel(c) if c.unit.trim().is_empty() => unit_in_name(&c.name),
        Entry::Matrix(g) => unit_in_name(&g.name),
        Entry::Channel(_) => None,
    }
}

/// The glitches (and gaps, in a channel in seconds) of `channels`, as `--list` says
/// them.
fn glitch_notes(s: &Source, channels: &[&Channel]) -> Vec<String> {
    channels
        .iter()
        .flat_map(|c| {
            let is_time = rtid::io::formats::units::lookup(&c.unit)
                .is_some_and(|u| u.quantity == rtid::io::formats::units::Quantity::Time);
            import::channel_findings(&s.path, c, is_time)
        })
        .collect()
}

/// (first, last, mean) of a channel's samples (the magnitude of a complex one).
fn stats(c: &Channel) -> (f64, f64, f64) {
    fn of(mut v: impl ExactSizeIterator<Item = f64> + Clone) -> (f64, f64, f64) {
        let n = v.len().max(1) as f64;
        let mean = v.clone().sum::<f64>() / n;
        let first = v.next().unwrap_or(f64::NAN);
        (first, v.last().unwrap_or(first), mean)
    }
    match &c.samples {
        Samples::Real(v) => of(v.iter().copied()),
        Samples::Complex { re, im } => of(re.iter().zip(im).map(|(a, b)| a.hypot(*b))),
    }
}

/// The sample period in s, where the abscissa is a time evenly spaced.
fn sample_period_s(c: &Channel) -> Option<f64> {
    use rtid::io::formats::units::{self, Quantity};
    let time = |unit: &str| {
        units::parse(unit)
            .ok()
            .filter(|u| u.quantity == Quantity::Time)
    };
    match &c.abscissa {
        Abscissa::Uniform { step, unit, .. } => time(unit).map(|u| step * u.si),
        Abscissa::Values { values, unit } => {
            let u = time(unit)?;
            let times: Vec<f64> = values.iter().map(|v| v * u.si).collect();
            experiment_file::sample_period(&times)
        }
        Abscissa::Index => None,
    }
}

/// The abscissa in words, given the sample period [`sample_period_s`] found.
fn abscissa_text(c: &Channel, period: Option<f64>) -> String {
    match (&c.abscissa, period) {
        (_, Some(p)) => format!("{} s", rtid::names::Num(p)),
        (Abscissa::Uniform { start, step, unit }, None) => format!("{start} + k·{step} {unit}"),
        (Abscissa::Values { values, unit }, None) => match (values.first(), values.last()) {
            (Some(a), Some(b)) => format!("{a} … {b} {unit}"),
            _ => "—".into(),
        },
        (Abscissa::Index, None) => "sample index".into(),
    }
}

fn list_json(s: &Source, filter: Option<&str>) -> Value {
    let r = &s.recording;
    let entries = entries(r, filter);
    let chosen = channels_of(r, &entries);
    let channels: Vec<Value> = chosen.iter().map(|c| channel_json(c)).collect();
    let matrices: Vec<Value> = r
        .groups
        .iter()
        .filter(|g| matches(&g.name, filter))
        .map(|g| {
            json!({
                "name": g.name,
                "shape": g.shape,
                "signals_in": if g.signals_in_rows { "rows" } else { "columns" },
                "channels": g.spelling(),
            })
        })
        .collect();
    let mut out = json!({
        "file": s.path.display().to_string(),
        "format": r.format,
        "channels": channels,
        "notes": r.notes.iter().chain(&glitch_notes(s, &chosen)).collect::<Vec<_>>(),
    });
    if !matrices.is_empty() {
        out["matrices"] = json!(matrices);
    }
    out
}

fn channel_json(c: &Channel) -> Value {
    let (first, last, mean) = stats(c);
    let mut o = json!({
        "name": c.name,
        "unit": c.unit,
        "samples": c.samples.len(),
    });
    // An empty channel has no first, last or mean: left out, never null.
    for (key, v) in [("first", first), ("last", last), ("mean", mean)] {
        if v.is_finite() {
            o[key] = json!(v);
        }
    }
    if matches!(c.samples, Samples::Complex { .. }) {
        o["complex"] = json!(true);
    }
    if let Some(unit) = offered_unit(&Entry::Channel(c)) {
        o["unit_in_name"] = json!(unit);
    }
    match sample_period_s(c) {
        // A period is finite (a time base's step); said as text otherwise, never null.
        Some(p) if p.is_finite() => o["sample_period_s"] = json!(p),
        _ => o["abscissa"] = json!(abscissa_text(c, None)),
    }
    o
}

fn table(r: &Recording, entries: &[Entry]) -> Table {
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header([
        "channel",
        "unit",
        "samples",
        "sample period / abscissa",
        "first",
        "last",
        "mean",
    ]);
    for e in entries {
        let unit = |file_unit: &str| match offered_unit(e) {
            Some(u) => format!("({u})"),
            None => file_unit.to_string(),
        };
        let row = match e {
            Entry::Channel(c) => {
                let (first, last, mean) = stats(c);
                let num = |v: f64| rtid::names::Num(v).to_string();
                [
                    c.name.clone(),
                    unit(&c.unit),
                    c.samples.len().to_string(),
                    abscissa_text(c, sample_period_s(c)),
                    num(first),
                    num(last),
                    num(mean),
                ]
            }
            Entry::Matrix(g) => matrix_row(r, g, unit("")),
        };
        t.add_row(row);
    }
    t
}

/// A matrix in one line: how its signals are spelled, their length, its shape and
/// orientation (`--filter NAME` lists its signals with their values).
fn matrix_row(r: &Recording, g: &Group, unit: String) -> [String; 7] {
    let samples = r
        .channels
        .get(g.channels.start)
        .map_or(0, |c| c.samples.len());
    let per = if g.signals_in_rows { "row" } else { "column" };
    [
        g.spelling(),
        unit,
        samples.to_string(),
        format!("{} matrix, a signal per {per}", g.shape_text()),
        "…".into(),
        "…".into(),
        "…".into(),
    ]
}
