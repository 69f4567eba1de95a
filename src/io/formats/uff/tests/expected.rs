//! Every fixture read and compared with what pyuff reads in it (`expected.json`,
//! written by `fixtures/formats/uff/make_expected.py`).
//!
//! Tolerances: names, units, counts and kinds exactly; values to 1e-12 relative, for
//! single-precision data too: pyuff and rtid read the same decimal text (`E13.5`) or
//! the same `f32` bits and round them to the nearest `f64` alike, so a float32
//! tolerance (2^-24) would hide differences the data do not excuse. Means, which
//! numpy sums pairwise, to 1e-12 of the largest magnitude.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::{fixture, real};
use crate::io::formats::uff::channel::direction;
use crate::io::formats::{Abscissa, Channel, Location, Recording, Samples};

const REL: f64 = 1e-12;

#[derive(Deserialize)]
struct Expected {
    files: BTreeMap<String, Vec<serde_json::Value>>,
}

#[derive(Deserialize, Debug)]
struct Stats {
    first: f64,
    mid: f64,
    last: f64,
    mean: f64,
}

#[derive(Deserialize, Debug)]
struct Function {
    binary: bool,
    name: String,
    func_type: i64,
    ord_data_type: i64,
    even: bool,
    num_pts: usize,
    n: usize,
    rsp_node: i64,
    rsp_dir: i64,
    ref_node: i64,
    ref_dir: i64,
    abscissa_unit: String,
    unit: String,
    complex: bool,
    abscissa: serde_json::Value,
    re: Stats,
    abs_max_re: f64,
    im: Option<Stats>,
    abs_max_im: Option<f64>,
}

fn expected() -> Expected {
    let text = std::fs::read_to_string(fixture("expected.json"))
        .expect("fixtures/formats/uff/expected.json");
    serde_json::from_str(&text).expect("expected.json as make_expected.py writes it")
}

fn close(got: f64, want: f64, scale: f64, what: &str) {
    let tol = REL * scale.max(got.abs()).max(want.abs());
    assert!(
        (got - want).abs() <= tol,
        "{what}: {got:e} read, pyuff {want:e}"
    );
}

/// Compensated (Neumaier) sum over n, so that rtid's side of a mean carries no
/// rounding worth the name.
fn mean(v: &[f64]) -> f64 {
    let (mut sum, mut c) = (0.0f64, 0.0f64);
    for &x in v {
        let t = sum + x;
        c += if sum.abs() >= x.abs() {
            (sum - t) + x
        } else {
            (x - t) + sum
        };
        sum = t;
    }
    (sum + c) / v.len() as f64
}

fn check_stats(v: &[f64], want: &Stats, abs_max: f64, what: &str) {
    close(v[0], want.first, 0.0, &format!("{what} first"));
    close(v[v.len() / 2], want.mid, 0.0, &format!("{what} middle"));
    close(v[v.len() - 1], want.last, 0.0, &format!("{what} last"));
    close(mean(v), want.mean, abs_max, &format!("{what} mean"));
}

/// pyuff's text with U+FFFD for each byte that is not UTF-8; rtid's has the Latin-1
/// character of that byte.
fn same_text(got: &str, pyuff: &str) -> bool {
    got.chars().count() == pyuff.chars().count()
        && got.chars().zip(pyuff.chars()).all(|(g, p)| {
            if p == '\u{fffd}' {
                ('\u{80}'..='\u{ff}').contains(&g)
            } else {
                g == p
            }
        })
}

fn check_abscissa(ch: &Channel, want: &Function) {
    match (&ch.abscissa, want.even) {
        (Abscissa::Uniform { start, step, unit }, true) => {
            close(
                *start,
                want.abscissa["start"].as_f64().unwrap(),
                0.0,
                "abscissa start",
            );
            close(
                *step,
                want.abscissa["step"].as_f64().unwrap(),
                0.0,
                "abscissa step",
            );
            assert_eq!(unit, &want.abscissa_unit);
        }
        (Abscissa::Values { values, unit }, false) => {
            let stats: Stats = serde_json::from_value(want.abscissa.clone()).unwrap();
            assert_eq!(values.len(), want.n);
            let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            check_stats(values, &stats, scale, "abscissa");
            assert_eq!(unit, &want.abscissa_unit);
        }
        (got, _) => panic!("{}: abscissa {got:?}, pyuff even = {}", ch.name, want.even),
    }
}

fn check_samples(ch: &Channel, want: &Function) {
    assert_eq!(ch.samples.len(), want.n, "{}", ch.name);
    match &ch.samples {
        Samples::Complex { re, im } => {
            assert!(want.complex, "{}: complex samples, pyuff real", ch.name);
            check_stats(re, &want.re, want.abs_max_re, "real part");
            check_stats(
                im,
                want.im.as_ref().unwrap(),
                want.abs_max_im.unwrap(),
                "imaginary part",
            );
        }
        samples @ Samples::Real(_) => {
            assert!(!want.complex, "{}: real samples, pyuff complex", ch.name);
            check_stats(real(samples), &want.re, want.abs_max_re, "samples");
        }
    }
}

fn check_note(recording: &Recording, want: &Function) {
    let head = format!(
        "{}: dataset 58{} at line ",
        want.name,
        if want.binary { "b" } else { "" }
    );
    let note = recording
        .notes
        .iter()
        .find(|n| n.starts_with(&head))
        .unwrap_or_else(|| panic!("no note '{head}…' in {:?}", recording.notes));
    let kind = match want.ord_data_type {
        2 => "real single-precision",
        4 => "real double-precision",
        5 => "complex single-precision",
        _ => "complex double-precision",
    };
    for part in [
        format!("function type {} (", want.func_type),
        format!("response {}:{}", want.rsp_node, direction(want.rsp_dir)),
        format!("reference {}:{}", want.ref_node, direction(want.ref_dir)),
        kind.to_string(),
    ] {
        assert!(note.contains(&part), "'{part}' not in '{note}'");
    }
}

fn check_function(recording: &Recording, ch: &Channel, want: &Function) {
    assert_eq!(ch.name, want.name);
    assert!(
        same_text(&ch.unit, &want.unit),
        "{}: unit '{}', pyuff '{}'",
        ch.name,
        ch.unit,
        want.unit
    );
    assert_eq!(want.n, want.num_pts, "pyuff's own count");
    check_abscissa(ch, want);
    check_samples(ch, want);
    check_note(recording, want);
}

fn check_file(file: &str, datasets: &[serde_json::Value]) {
    let result = crate::io::formats::uff::read(&fixture(file));
    let functions: Vec<Function> = datasets
        .iter()
        .filter(|d| d["type"] == 58)
        .map(|d| serde_json::from_value(d.clone()).unwrap())
        .collect();
    if functions.is_empty() {
        let err = result.expect_err(file);
        assert_eq!(err.location, Location::File);
        assert!(err.to_string().contains("no dataset 58"), "{err}");
        return;
    }
    let recording = result.unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(recording.format, "uff58");
    assert_eq!(recording.channels.len(), functions.len(), "{file}");
    for (ch, want) in recording.channels.iter().zip(&functions) {
        check_function(&recording, ch, want);
    }
    for other in datasets.iter().filter(|d| d["type"] != 58) {
        let head = format!("dataset {} at line ", other["type"]);
        assert!(
            recording
                .notes
                .iter()
                .any(|n| n.starts_with(&head) && n.contains("skipped")),
            "{file}: no note '{head}… skipped' in {:?}",
            recording.notes
        );
    }
}

#[test]
fn every_fixture_reads_as_pyuff_reads_it() {
    let expected = expected();
    let uff_files = std::fs::read_dir(fixture(""))
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "uff")
        })
        .count();
    assert_eq!(
        expected.files.len(),
        uff_files,
        "expected.json describes every .uff fixture"
    );
    assert!(expected.files.len() >= 10);
    for (file, datasets) in &expected.files {
        check_file(file, datasets);
    }
}

#[test]
fn the_fixtures_cover_the_eight_data_layouts_and_both_encodings() {
    let expected = expected();
    let functions: Vec<Function> = expected
        .files
        .values()
        .flatten()
        .filter(|d| d["type"] == 58)
        .map(|d| serde_json::from_value(d.clone()).unwrap())
        .collect();
    // all eight ASCII layouts; in 58b, what the published samples and pyuff (which
    // writes doubles only) give
    let ascii = [2, 4, 5, 6]
        .into_iter()
        .flat_map(|t| [(false, t, true), (false, t, false)]);
    let binary = [
        (true, 2, true),
        (true, 4, true),
        (true, 4, false),
        (true, 6, true),
        (true, 6, false),
    ];
    for (binary, data_type, even) in ascii.chain(binary) {
        assert!(
            functions
                .iter()
                .any(|f| f.binary == binary && f.ord_data_type == data_type && f.even == even),
            "binary {binary}, data type {data_type}, even {even}"
        );
    }
    for func_type in [1, 4, 9] {
        assert!(
            functions.iter().any(|f| f.func_type == func_type),
            "function type {func_type}"
        );
    }
}
