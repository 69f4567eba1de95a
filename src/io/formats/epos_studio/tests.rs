//! The EPOS Studio reader against an independent Python reading of the same exports
//! (`fixtures/formats/epos/expected.json`, written by `make_expected.py`), against
//! copies of them as a spreadsheet saves them (stray `,,`, hand notes, a glitch
//! sample), and against broken files made from them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::{read, sniff};
use crate::io::formats::{Abscissa, Location, Recording, Samples};

#[derive(Deserialize)]
struct Expected {
    files: BTreeMap<String, FileExpected>,
}

#[derive(Deserialize)]
struct FileExpected {
    time_unit: String,
    rows: usize,
    first_line: usize,
    time_first: f64,
    time_last: f64,
    stray_lines: usize,
    hand_notes: Vec<HandNote>,
    channels: Vec<ChannelExpected>,
}

#[derive(Deserialize)]
struct HandNote {
    line: usize,
    text: String,
}

#[derive(Deserialize)]
struct ChannelExpected {
    name: String,
    unit: String,
    count: usize,
    first: f64,
    last: f64,
    mean: f64,
}

const PLAIN: &str = "driveNo1/steady_state/10.csv";
/// Negative speed, a header without `Scale:` lines (data from line 13).
const NO_SCALE: &str = "driveNo1/steady_state/n2.csv";
/// Start/stop exports whose `Trigger:` line (11) a spreadsheet quoted whole.
const QUOTED: [&str; 2] = ["driveNo1/start_stop/200.csv", "driveNo2/start_stop/50.csv"];

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/formats/epos")
}

fn expected() -> Expected {
    let text = std::fs::read_to_string(dir().join("expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn assert_close(got: f64, want: f64, scale: f64, what: &str) {
    assert!(
        (got - want).abs() <= 1e-12 * scale,
        "{what}: {got} vs {want}"
    );
}

fn check(rec: &Recording, want: &FileExpected, file: &str) {
    assert_eq!(rec.format, "epos-studio");
    assert_eq!(want.time_unit, "ms", "{file}: the test converts ms");
    let names: Vec<&str> = rec.channels.iter().map(|c| c.name.as_str()).collect();
    let want_names: Vec<&str> = want.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, want_names, "{file}");
    for (c, w) in rec.channels.iter().zip(&want.channels) {
        let what = format!("{file} {}", c.name);
        assert_eq!(c.unit, w.unit, "{what}");
        assert_eq!(c.first_line, Some(want.first_line), "{what}");
        let Samples::Real(v) = &c.samples else {
            panic!("{what}: not real")
        };
        let Abscissa::Values { values: t, unit } = &c.abscissa else {
            panic!("{what}")
        };
        assert_eq!(unit, "s");
        assert_eq!((v.len(), t.len()), (w.count, want.rows), "{what}");
        assert_close(v[0], w.first, w.first.abs(), &what);
        assert_close(v[v.len() - 1], w.last, w.last.abs(), &what);
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let scale = v.iter().map(|x| x.abs()).sum::<f64>() / v.len() as f64;
        assert_close(mean, w.mean, scale, &what);
        assert_close(t[0], want.time_first / 1000.0, t[0].abs(), &what);
        assert_close(
            t[t.len() - 1],
            want.time_last / 1000.0,
            t[t.len() - 1].abs(),
            &what,
        );
    }
}

#[test]
fn every_export_reads_as_the_python_reader_reads_it() {
    let expected = expected();
    assert_eq!(expected.files.len(), 5);
    for (file, want) in &expected.files {
        let rec = read(&dir().join(file)).unwrap_or_else(|e| panic!("{e}"));
        check(&rec, want, file);
        let stray = rec
            .notes
            .iter()
            .find(|n| n.contains("stray spreadsheet cells"));
        match want.stray_lines {
            0 => assert!(stray.is_none(), "{file}"),
            n => assert!(stray.unwrap().starts_with(&format!("{n} lines")), "{file}"),
        }
        for hand in &want.hand_notes {
            let note = format!(
                "line {}: text after the last value, not read: `{}`",
                hand.line, hand.text
            );
            assert!(
                rec.notes.contains(&note),
                "{file}: {note} in {:?}",
                rec.notes
            );
        }
        let period = rec.notes.iter().find(|n| n.contains("sampling period"));
        assert!(
            period.is_none(),
            "{file}: the header's period (ms) fits: {period:?}"
        );
    }
}

fn fixture_lines(file: &str) -> Vec<String> {
    let text = std::fs::read_to_string(dir().join(file)).unwrap();
    text.split_inclusive('\n').map(str::to_string).collect()
}

/// `lines` as a spreadsheet saves them after reading each as the first cell of a
/// comma-separated row: `,,` before every line end, and on the lines of `edits`
/// (1-based) the EPOS text replaced and a hand note written after the `,,`.
fn through_a_spreadsheet(lines: &[String], edits: &[(usize, &str, &str)]) -> String {
    lines
        .iter()
        .enumerate()
        .map(|(i, line)| {
            let text = line.strip_suffix("\r\n").expect("CR LF line ends");
            match edits.iter().find(|&&(n, ..)| n == i + 1) {
                Some((_, edited, note)) => format!("{edited},,{note}\r\n"),
                None => format!("{text},,\r\n"),
            }
        })
        .collect()
}

fn stray_note(lines: usize) -> String {
    format!("{lines} lines (1–{lines}) end with stray spreadsheet cells (`,,`): ignored")
}

/// A temporary copy of `bytes`.
fn temp_file(bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("export.csv");
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

#[test]
fn stray_commas_on_every_line_are_ignored_and_counted() {
    for file in [PLAIN, NO_SCALE, QUOTED[0]] {
        let original = read(&dir().join(file)).unwrap();
        let lines = fixture_lines(file);
        let (_d, path) = temp_file(through_a_spreadsheet(&lines, &[]).as_bytes());
        let rec = read(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(rec.channels, original.channels, "{file}");
        let (stray, rest): (Vec<String>, Vec<String>) = rec
            .notes
            .into_iter()
            .partition(|n| n.contains("stray spreadsheet cells"));
        assert_eq!(stray, [stray_note(lines.len())], "{file}");
        assert_eq!(rest, original.notes, "{file}");
    }
}

/// A recorder glitch (a torque of −1200 % among about −28 %, or −400 % among +36 %) with a
/// hand note after it (`-1200,,was -32.0`): the note is said with its line and not
/// read, the glitch is returned as written (glitch reports are `rtid import`'s).
#[test]
fn a_glitch_sample_beside_a_hand_note_is_kept_as_written() {
    let cases = [
        (PLAIN, 15, "0.000;-10;-32.0", -1200.0),
        (NO_SCALE, 300, "36736.000;10;32.5", -400.0),
    ];
    for (file, line, was, glitch) in cases {
        let original = read(&dir().join(file)).unwrap();
        let lines = fixture_lines(file);
        assert_eq!(lines[line - 1], format!("{was}\r\n"), "{file}");
        let (time, rest) = was.rsplit_once(';').unwrap();
        let edited = format!("{time};{glitch}");
        let note = format!("was {rest}");
        let text = through_a_spreadsheet(&lines, &[(line, &edited, &note)]);
        let (_d, path) = temp_file(text.as_bytes());
        let rec = read(&path).unwrap_or_else(|e| panic!("{file}: {e}"));

        assert_eq!(rec.channels[0], original.channels[0], "{file}: velocity");
        let torque = &rec.channels[1];
        assert_eq!(torque.name, "Torque actual value averaged");
        let first = torque.first_line.unwrap();
        let (Samples::Real(v), Samples::Real(w)) = (&torque.samples, &original.channels[1].samples)
        else {
            panic!("{file}: not real")
        };
        let k = line - first;
        assert_eq!(v[k], glitch, "{file}: the glitch as written");
        assert_ne!(w[k], glitch);
        let mut restored = v.clone();
        restored[k] = w[k];
        assert_eq!(&restored, w, "{file}: the other samples as in the export");

        let hand = format!("line {line}: text after the last value, not read: `{note}`");
        assert!(
            rec.notes.contains(&hand),
            "{file}: {hand} in {:?}",
            rec.notes
        );
        assert!(rec.notes.contains(&stray_note(lines.len())), "{file}");
        assert_eq!(rec.notes.len(), original.notes.len() + 2, "{:?}", rec.notes);
    }
}

#[test]
fn a_line_quoted_whole_by_a_spreadsheet_reads_as_unquoted() {
    for file in QUOTED {
        let mut lines = fixture_lines(file);
        let quoted = &lines[10];
        assert!(
            quoted.starts_with("\"Trigger:;") && quoted.contains(r#";""Parameter values"";"#),
            "{file}: {quoted}"
        );
        let rec = read(&dir().join(file)).unwrap();
        let unused = rec
            .notes
            .iter()
            .find(|n| n.starts_with("header lines not used: "));
        assert!(
            unused.is_some_and(|n| n.contains(", Trigger, TriggerAttributes")),
            "{file}: {:?}",
            rec.notes
        );
        let unquoted = quoted
            .strip_suffix("\"\r\n")
            .and_then(|q| q.strip_prefix('"'))
            .unwrap()
            .replace("\"\"", "\"");
        assert!(
            unquoted.starts_with("Trigger:;")
                && unquoted.ends_with(r#";"Parameter values";"Channel 1";"Rising above value""#),
            "{file}: {unquoted}"
        );
        lines[10] = format!("{unquoted}\r\n");
        let (_d, path) = temp_file(lines.concat().as_bytes());
        assert_eq!(read(&path).unwrap(), rec, "{file}");
    }
}

#[test]
fn a_period_disagreeing_with_the_time_column_is_noted() {
    let mut lines = fixture_lines(PLAIN);
    assert_eq!(lines[7], "Sampling period:;51.200\r\n");
    lines[7] = "Sampling period:;51.300\r\n".into();
    let (_d, path) = temp_file(lines.concat().as_bytes());
    let rec = read(&path).unwrap();
    assert!(
        rec.notes
            .iter()
            .any(|n| n.starts_with("line 16: the time 51.2 ms")),
        "{:?}",
        rec.notes
    );
}

#[test]
fn more_rows_than_declared_is_a_note() {
    let mut lines = fixture_lines(PLAIN);
    lines[6] = "Recorded samples:;499\r\n".into();
    let (_d, path) = temp_file(lines.concat().as_bytes());
    let rec = read(&path).unwrap();
    assert!(rec
        .notes
        .contains(&"500 samples where line 7 declares 499 recorded samples".into()));
}

/// Reading `bytes` fails with one error naming the file and `line`.
fn assert_fails_at(bytes: &[u8], line: usize, words: &str) {
    let (_d, path) = temp_file(bytes);
    let err = read(&path).unwrap_err();
    assert_eq!(err.path, path);
    assert_eq!(err.location, Location::Line(line), "{err}");
    assert!(err.message.contains(words), "{err}");
}

#[test]
fn a_file_cut_mid_row_names_the_row() {
    let lines = fixture_lines(PLAIN);
    let text = lines[..199].concat() + &lines[199][..8];
    assert_fails_at(text.as_bytes(), 200, "ends inside this row");
}

#[test]
fn a_file_cut_between_rows_misses_declared_samples() {
    let lines = fixture_lines(PLAIN);
    assert_fails_at(
        lines[..414].concat().as_bytes(),
        7,
        "holds 400 (its last line is 414)",
    );
}

#[test]
fn a_header_without_data_is_refused() {
    let lines = fixture_lines(PLAIN);
    assert_fails_at(
        lines[..14].concat().as_bytes(),
        7,
        "declares 500 recorded samples, the file holds 0",
    );
    assert_fails_at(
        lines[..13].concat().as_bytes(),
        13,
        "ends inside the header",
    );
}

#[test]
fn a_header_declaring_1e8_samples_with_none_there_is_refused() {
    let mut lines = fixture_lines(PLAIN);
    lines[6] = "Recorded samples:;100000000\r\n".into();
    assert_fails_at(lines[..14].concat().as_bytes(), 7, "declares 100000000");
}

#[test]
fn a_row_with_too_few_cells_is_refused() {
    let mut lines = fixture_lines(PLAIN);
    lines[99] = "5068.800;-10\r\n".into();
    assert_fails_at(
        lines.concat().as_bytes(),
        100,
        "2 cells where the header names 3 columns",
    );
}

#[test]
fn a_cell_that_is_not_a_number_is_refused() {
    let mut lines = fixture_lines(PLAIN);
    lines[299] = lines[299].replacen(';', ";abc", 1);
    assert_fails_at(
        lines.concat().as_bytes(),
        300,
        "(Velocity actual value averaged): `abc",
    );
    let text = through_a_spreadsheet(&lines, &[]);
    assert_fails_at(
        text.as_bytes(),
        300,
        "(Velocity actual value averaged): `abc",
    );
}

#[test]
fn binary_garbage_is_refused() {
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let garbage: Vec<u8> = (0..200_000)
        .map(|_| {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (x >> 56) as u8
        })
        .collect();
    assert_fails_at(&garbage, 1, "not an EPOS Studio export");
    let mut lines = fixture_lines(PLAIN).concat().into_bytes();
    let at = lines.len() - 4000;
    lines.splice(
        at..at,
        garbage[..64].iter().copied().filter(|&b| b != b'\n'),
    );
    let (_d, path) = temp_file(&lines);
    let err = read(&path).unwrap_err();
    assert!(matches!(err.location, Location::Line(n) if n > 14), "{err}");
}

#[test]
fn the_first_line_of_every_export_sniffs_as_epos() {
    for file in expected().files.keys() {
        assert!(sniff(&fixture_lines(file)[0]), "{file}");
    }
    for other in ["Name\ttc3_scope", "Date,2020", "", "time;x"] {
        assert!(!sniff(other), "{other}");
    }
}

/// EPOS Studio writes no NaN; a cell that reads as one, or overflows to infinity, is
/// damage (issue 28: a time of `1e3080` made an infinite abscissa).
#[test]
fn a_cell_that_is_not_finite_is_refused() {
    for (cell, column) in [("1e3080", "column 1 (time)"), ("NaN", "column 1 (time)")] {
        let mut lines = fixture_lines(PLAIN);
        let (_, rest) = lines[299].split_once(';').unwrap();
        lines[299] = format!("{cell};{rest}");
        let needle = format!("{column}: `{cell}` is not a finite number");
        assert_fails_at(lines.concat().as_bytes(), 300, &needle);
    }
    let mut lines = fixture_lines(PLAIN);
    lines[299] = lines[299].replacen(';', ";inf", 1);
    assert_fails_at(
        lines.concat().as_bytes(),
        300,
        "(Velocity actual value averaged): `inf",
    );
}
