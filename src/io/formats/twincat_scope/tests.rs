//! The TwinCAT Scope reader against pytcs's reading of the same exports
//! (`fixtures/formats/twincat-scope/expected.json`, written by `make_expected.py`),
//! against exports made from them with other options (colon and comma separators,
//! shared time columns in unsorted groups), and against broken files made from them.

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
    channels: Vec<ChannelExpected>,
    pytcs_error: Option<String>,
}

#[derive(Deserialize)]
struct ChannelExpected {
    name: String,
    unit_raw: String,
    count: usize,
    sample_time_ms: f64,
    time_first_ms: f64,
    time_last_ms: f64,
    first: f64,
    last: f64,
    mean: f64,
}

const SPACE_SEPARATED: &str = "tc3_scope_3_4_3145_3-Seperator_1.csv";
const TAB_SEPARATED: &str = "tc3_scope_3_4_3145_3-DecimalMark_,.csv";
/// One time column per channel, sorted, values unscaled.
const DEFAULT: &str = "tc3_scope_3_4_3145_3-default.csv";

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/formats/twincat-scope")
}

fn expected() -> Expected {
    let text = std::fs::read_to_string(dir().join("expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn close(got: f64, want: f64, scale: f64) -> bool {
    (got - want).abs() <= 1e-12 * scale
}

fn assert_close(got: f64, want: f64, what: &str) {
    let scale = got.abs().max(want.abs());
    assert!(close(got, want, scale), "{what}: {got} vs {want}");
}

/// The 1-based line of the first row after the blank line ending the channel header.
fn first_data_line(bytes: &[u8]) -> usize {
    let lines: Vec<&[u8]> = bytes.split(|&b| b == b'\n').collect();
    let blank = (7..lines.len())
        .find(|&i| lines[i].iter().all(u8::is_ascii_whitespace))
        .unwrap();
    blank + 2
}

/// Every channel as pytcs read it; `rename` maps pytcs's names to the expected ones.
fn check(
    rec: &Recording,
    want: &[ChannelExpected],
    first_line: usize,
    rename: &dyn Fn(&str) -> String,
) {
    assert_eq!(rec.format, "twincat-scope");
    let names: Vec<&str> = rec.channels.iter().map(|c| c.name.as_str()).collect();
    let want_names: Vec<String> = want.iter().map(|c| rename(&c.name)).collect();
    assert_eq!(names, want_names);
    for (c, w) in rec.channels.iter().zip(want) {
        let unit = if w.unit_raw == "(None)" {
            ""
        } else {
            &w.unit_raw
        };
        assert_eq!(c.unit, unit, "{}", c.name);
        assert_eq!(c.first_line, Some(first_line), "{}", c.name);
        let Samples::Real(v) = &c.samples else {
            panic!("{}: not real", c.name)
        };
        let Abscissa::Values { values: t, unit } = &c.abscissa else {
            panic!("{}", c.name)
        };
        assert_eq!(unit, "s");
        assert_eq!((v.len(), t.len()), (w.count, w.count), "{}", c.name);
        assert_close(v[0], w.first, &c.name);
        assert_close(v[v.len() - 1], w.last, &c.name);
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let scale = v.iter().map(|x| x.abs()).sum::<f64>() / v.len() as f64;
        assert!(
            close(mean, w.mean, scale),
            "{}: mean {mean} vs {}",
            c.name,
            w.mean
        );
        assert_close(t[0], w.time_first_ms / 1000.0, &c.name);
        assert_close(t[t.len() - 1], w.time_last_ms / 1000.0, &c.name);
        assert_close((t[1] - t[0]) * 1000.0, w.sample_time_ms, &c.name);
    }
}

#[test]
fn every_export_reads_as_pytcs_reads_it() {
    let expected = expected();
    assert_eq!(expected.files.len(), 4);
    for (file, want) in &expected.files {
        if file == SPACE_SEPARATED {
            continue; // names with spaces in a space-separated export: see below
        }
        let path = dir().join(file);
        let rec = read(&path).unwrap_or_else(|e| panic!("{e}"));
        let first = first_data_line(&std::fs::read(&path).unwrap());
        check(&rec, &want.channels, first, &|n| n.to_string());
    }
}

#[test]
fn space_separated_names_with_spaces_are_refused_at_the_name_row() {
    let err = read(&dir().join(SPACE_SEPARATED)).unwrap_err();
    assert_eq!(err.location, Location::Line(7));
    assert!(
        err.message
            .contains("`Name` row has 22 cells for the 19 channels"),
        "{err}"
    );
    assert!(expected().files[SPACE_SEPARATED].pytcs_error.is_some());
}

/// A temporary copy of `bytes` under `name`.
fn temp_file(name: &str, bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

fn fixture_text(file: &str) -> String {
    std::fs::read_to_string(dir().join(file)).unwrap()
}

fn fixture_lines(file: &str) -> Vec<String> {
    fixture_text(file).split('\n').map(str::to_string).collect()
}

/// Reads `text` as the file `name`.
fn read_text(name: &str, text: &str) -> Recording {
    let (_d, path) = temp_file(name, text.as_bytes());
    read(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The separators made from the tab export, and whether its decimal commas become
/// points in the data rows (they must where the comma is the separator).
const SEPARATORS: [(char, bool); 3] = [(':', false), (':', true), (',', true)];

/// A tab-separated export (LF line ends) with `sep` for every tab (the exporter's
/// "Seperator" option): every cell as it was, the data rows' decimal commas as points
/// when `point`. The header keeps its decimal commas, as in every export
/// (`SampleTime[ms]` `0,2` with decimal points in the data in `-Seperator_1.csv`): with
/// the comma as the separator, that cell splits in two.
fn with_separator(tab_text: &str, sep: char, point: bool) -> String {
    let lines: Vec<&str> = tab_text.split('\n').collect();
    let blank = (7..lines.len()).find(|&i| lines[i].is_empty()).unwrap();
    let out: Vec<String> = lines
        .iter()
        .enumerate()
        .map(|(i, line)| {
            let line = if i > blank && point {
                line.replace(',', ".")
            } else {
                line.to_string()
            };
            line.replace('\t', &sep.to_string())
        })
        .collect();
    out.join("\n")
}

#[test]
fn colon_and_comma_separated_exports_read_as_the_tab_export() {
    let tab_text = fixture_text(TAB_SEPARATED);
    let tab = read(&dir().join(TAB_SEPARATED)).unwrap();
    let want = &expected().files[TAB_SEPARATED].channels;
    let first = first_data_line(tab_text.as_bytes());
    for (sep, point) in SEPARATORS {
        let text = with_separator(&tab_text, sep, point);
        assert!(!text.contains('\t'));
        assert_eq!(text.contains("SampleTime[ms],0,2,"), sep == ',');
        let rec = read_text("separated.csv", &text);
        check(&rec, want, first, &|n| n.to_string());
        assert_eq!(
            rec.channels, tab.channels,
            "separator {sep:?}, point {point}"
        );
    }
}

/// The channels of the default export in an order of the scope's own (as with
/// "SortChannels" off): 1 ms channels in three runs apart, between them the 5 ms and the
/// 0.2 ms channel, each run in another order than the default's.
const UNSORTED: [&str; 21] = [
    "test_special([{äöü!?ß$²}])",
    "var_INT16",
    "var_BIT",
    "test space",
    "func_freesample",
    "func_units_scaled",
    "var_UINT64",
    "func_scaled",
    "var_REAL32",
    "var_INT8",
    "func_scaled_int",
    "func_OS",
    "var_UINT8",
    "test space (1)",
    "var_REAL64",
    "var_INT64",
    "func_units_unscaled",
    "var_UINT16",
    "var_INT32",
    "func_timeshift",
    "var_UINT32",
];

/// The default export (a time column before each channel, LF line ends) as with
/// "ExcludeDoubleTimestamp": its channels in `order`, each run of channels with the same
/// `SampleTime[ms]` sharing one time column (the first's; panics unless the others'
/// are the same cells), every property row repeating its key before each run, and every
/// row cut after its last cell that is not blank, as the exporter cuts them.
fn shared_time_columns(default_text: &str, order: &[&str]) -> String {
    let lines: Vec<&str> = default_text.split('\n').collect();
    let blank = (7..lines.len()).find(|&i| lines[i].is_empty()).unwrap();
    let eof = lines.iter().position(|l| *l == "EOF").unwrap();
    let props: Vec<Vec<&str>> = lines[6..blank]
        .iter()
        .map(|l| l.split('\t').collect())
        .collect();
    let rows: Vec<Vec<&str>> = lines[blank + 1..eof]
        .iter()
        .map(|l| l.split('\t').collect())
        .collect();
    /// A cell of a row; past the row's end, `blank` (empty in a property row, ` ` in a
    /// data row, as the exporter writes a blank cell in either).
    fn cell<'a>(row: &[&'a str], col: usize, blank: &'a str) -> &'a str {
        row.get(col).copied().unwrap_or(blank)
    }
    /// A row's cells up to the last one that is not blank, as the exporter cuts them.
    fn cut(cells: &[&str]) -> String {
        let kept = cells.iter().rposition(|c| !c.trim().is_empty()).unwrap() + 1;
        cells[..kept].join("\t")
    }
    let names = &props[0];
    let index = |name: &str| {
        (0..names.len() / 2)
            .find(|&i| names[2 * i + 1] == name)
            .unwrap()
    };
    let sample_times = props.iter().find(|p| p[0] == "SampleTime[ms]").unwrap();
    for p in &props {
        // A row may end before its last empty cell (`SymbolComment`).
        assert!(
            p.len() + 1 >= names.len() && p.len() <= names.len(),
            "{}",
            p[0]
        );
        assert!(p.iter().step_by(2).all(|key| *key == p[0]), "{}", p[0]);
    }
    let mut runs: Vec<Vec<usize>> = Vec::new();
    for name in order {
        let i = index(name);
        match runs.last_mut() {
            Some(run) if sample_times[2 * run[0] + 1] == sample_times[2 * i + 1] => run.push(i),
            _ => runs.push(vec![i]),
        }
    }
    for run in &runs {
        for &i in &run[1..] {
            let same = rows
                .iter()
                .all(|r| cell(r, 2 * i, " ") == cell(r, 2 * run[0], " "));
            assert!(same, "`{}` has its own time column", names[2 * i + 1]);
        }
    }
    let mut out: Vec<String> = lines[..6].iter().map(|l| l.to_string()).collect();
    for p in &props {
        let mut cells = Vec::new();
        for run in &runs {
            cells.push(p[0]);
            cells.extend(run.iter().map(|&i| cell(p, 2 * i + 1, "")));
        }
        out.push(cut(&cells));
    }
    out.push(String::new());
    for r in &rows {
        let mut cells = Vec::new();
        for run in &runs {
            cells.push(cell(r, 2 * run[0], " "));
            cells.extend(run.iter().map(|&i| cell(r, 2 * i + 1, " ")));
        }
        out.push(cut(&cells));
    }
    out.extend(["EOF".to_string(), String::new()]);
    out.join("\n")
}

#[test]
fn shared_time_columns_in_unsorted_groups_read_as_the_default_export() {
    let default_text = fixture_text(DEFAULT);
    let default = read(&dir().join(DEFAULT)).unwrap();
    let mut sorted = UNSORTED.to_vec();
    sorted.sort_unstable();
    let mut all: Vec<&str> = default.channels.iter().map(|c| c.name.as_str()).collect();
    all.sort_unstable();
    assert_eq!(sorted, all, "UNSORTED holds every channel once");

    let text = shared_time_columns(&default_text, &UNSORTED);
    let lines: Vec<&str> = text.split('\n').collect();
    let name_row: Vec<&str> = lines[6].split('\t').collect();
    assert_eq!(name_row.len(), 5 + 21, "five time columns");
    assert_eq!(name_row.iter().filter(|c| **c == "Name").count(), 5);
    let first = first_data_line(text.as_bytes());
    // Past the 1 ms channels' end only the 0.2 ms one goes on, after blank cells.
    let late: Vec<&str> = lines[first - 1 + 2000].split('\t').collect();
    assert_eq!(late.len(), 16, "{late:?}");
    assert!(late[..14].iter().all(|c| c.trim().is_empty()), "{late:?}");

    let rec = read_text("shared.csv", &text);
    let names: Vec<&str> = rec.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, UNSORTED);
    assert_eq!(first, first_data_line(default_text.as_bytes()));
    for c in &rec.channels {
        let want = default.channels.iter().find(|d| d.name == c.name).unwrap();
        assert_eq!(c, want, "{}", c.name);
    }
}

#[test]
fn space_separated_export_reads_when_no_name_holds_a_space() {
    let mut lines = fixture_lines(SPACE_SEPARATED);
    lines[6] = lines[6]
        .replace("test space (1)", "test_space_(1)")
        .replace("test space", "test_space");
    let bytes = lines.join("\n");
    let (_d, path) = temp_file("space.csv", bytes.as_bytes());
    let rec = read(&path).unwrap_or_else(|e| panic!("{e}"));
    let want = &expected().files[SPACE_SEPARATED].channels;
    let first = first_data_line(bytes.as_bytes());
    check(&rec, want, first, &|n| n.replace(' ', "_"));
    assert!(rec
        .notes
        .iter()
        .any(|n| n.contains("split after each word in parentheses")));
}

#[test]
fn declared_scaling_is_noted_not_applied() {
    let rec = read(&dir().join(TAB_SEPARATED)).unwrap();
    let note = rec
        .notes
        .iter()
        .find(|n| n.contains("declaring a scaling"))
        .unwrap();
    for named in [
        "`func_scaled` (ScaleFactor -1, Offset 1)",
        "`func_scaled_int` (ScaleFactor -1, Offset 1)",
        "`func_units_scaled` (Unit ScaleFactor -10, Unit Offset 10)",
    ] {
        assert!(note.contains(named), "{named} in {note}");
    }
    assert!(!note.contains("func_units_unscaled"));
}

#[test]
fn a_windows_1252_header_is_decoded() {
    let text = std::fs::read_to_string(dir().join(TAB_SEPARATED)).unwrap();
    let special = "test_special([{äöü!?ß$²}])";
    let mut bytes = Vec::new();
    for ch in text.chars() {
        let c = u32::from(ch);
        assert!(c < 0x100, "only Latin-1 characters in the fixture");
        bytes.push(c as u8); // Latin-1 = Windows-1252 for these
    }
    let (_d, path) = temp_file("ansi.csv", &bytes);
    let rec = read(&path).unwrap();
    assert!(rec.channels.iter().any(|c| c.name == special));
    assert!(rec.notes.iter().any(|n| n.contains("Windows-1252")));
}

#[test]
fn the_first_line_of_every_export_sniffs_as_twincat() {
    for file in expected().files.keys() {
        assert!(sniff(&fixture_lines(file)[0]), "{file}");
    }
    for (sep, point) in SEPARATORS {
        let text = with_separator(&fixture_text(TAB_SEPARATED), sep, point);
        assert!(sniff(text.lines().next().unwrap()), "separator {sep:?}");
    }
    let shared = shared_time_columns(&fixture_text(DEFAULT), &UNSORTED);
    assert!(sniff(shared.lines().next().unwrap()));
    for other in [
        "Date:;2020-07-08 21:24:28",
        "Name;Value;Unit",
        "",
        "Name",
        "time,x",
    ] {
        assert!(!sniff(other), "{other}");
    }
}

/// Reading `bytes` fails with one error naming the file and `line`.
fn assert_fails_at(name: &str, bytes: &[u8], line: usize, words: &str) {
    let (_d, path) = temp_file(name, bytes);
    let err = read(&path).unwrap_err();
    assert_eq!(err.path, path);
    assert_eq!(err.location, Location::Line(line), "{err}");
    assert!(err.message.contains(words), "{err}");
}

#[test]
fn a_file_cut_mid_row_names_the_row() {
    let bytes = std::fs::read(dir().join(TAB_SEPARATED)).unwrap();
    let line_100 = bytes
        .split(|&b| b == b'\n')
        .take(99)
        .map(|l| l.len() + 1)
        .sum::<usize>();
    assert_fails_at(
        "cut.csv",
        &bytes[..line_100 + 20],
        100,
        "ends inside this row",
    );
}

#[test]
fn a_header_without_data_is_refused() {
    let lines = fixture_lines(TAB_SEPARATED);
    let header = lines[..24].join("\n") + "\n";
    assert_fails_at("header.csv", header.as_bytes(), 24, "no samples");
    let cut = lines[..23].join("\n") + "\n";
    assert_fails_at(
        "cut-header.csv",
        cut.as_bytes(),
        23,
        "inside the channel header",
    );
}

#[test]
fn a_row_with_too_few_cells_is_refused() {
    let mut lines = fixture_lines(TAB_SEPARATED);
    let cells: Vec<&str> = lines[99].split('\t').take(10).collect();
    lines[99] = cells.join("\t");
    assert_fails_at(
        "short.csv",
        lines.join("\n").as_bytes(),
        100,
        "too few cells",
    );
}

#[test]
fn a_cell_that_is_not_a_number_is_refused() {
    let mut lines = fixture_lines(TAB_SEPARATED);
    lines[299] = lines[299].replacen("\t", "\tabc", 3);
    assert_fails_at("nan.csv", lines.join("\n").as_bytes(), 300, "`abc");
}

/// Deterministic bytes of every value (a linear congruential generator).
fn garbage(n: usize) -> Vec<u8> {
    let mut x: u64 = 0x2545_F491_4F6C_DD1D;
    (0..n)
        .map(|_| {
            x = x.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (x >> 56) as u8
        })
        .collect()
}

#[test]
fn binary_garbage_is_refused() {
    assert_fails_at(
        "garbage.csv",
        &garbage(200_000),
        1,
        "not a TwinCAT Scope export",
    );
    let mut bytes = std::fs::read(dir().join(TAB_SEPARATED)).unwrap();
    let line_500 = bytes
        .split(|&b| b == b'\n')
        .take(499)
        .map(|l| l.len() + 1)
        .sum::<usize>();
    let noise: Vec<u8> = garbage(64).into_iter().filter(|&b| b != b'\n').collect();
    bytes.splice(line_500..line_500, noise);
    assert_fails_at("noise.csv", &bytes, 500, "not a number");
}

#[test]
fn an_empty_file_is_refused() {
    let (_d, path) = temp_file("empty.csv", b"");
    let err = read(&path).unwrap_err();
    assert_eq!(err.location, Location::File);
}

/// A time cell of `NaN` (or one that overflows) is refused by its line: as an
/// abscissa it would make every later step, and the import's sample period, NaN
/// (issue 28).
#[test]
fn a_time_that_is_not_finite_is_refused() {
    let text = fixture_text(TAB_SEPARATED);
    let first = first_data_line(text.as_bytes());
    for cell in ["NaN", "1e3080"] {
        let mut lines: Vec<String> = text.split('\n').map(str::to_string).collect();
        let row = &mut lines[first + 9];
        let (_, rest) = row.split_once('\t').unwrap();
        *row = format!("{cell}\t{rest}");
        let words = "column 1: the time";
        assert_fails_at("time.csv", lines.join("\n").as_bytes(), first + 10, words);
    }
}
