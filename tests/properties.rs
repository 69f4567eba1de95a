//! Property tests of every parser of the library (issue 13): experiment files
//! (manifest and CSV of each kind), parameter files, torque files, sweep files, sweep
//! factor specifications and shards. Valid inputs from the fixtures are mutated at
//! random — a cell replaced by any text or number, bytes cut out or put in, a JSON
//! number replaced — and each parser must then either succeed with finite values or
//! fail with an error naming the file; it must never panic. (`tests/corpus.rs` runs the
//! binary on a fixed corpus; the option parsing's properties are in the binary's own
//! tests, `src/cli/properties.rs`.)

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use rtid::io::{experiment_file, params_file, torque_file};
use rtid::sweep::{self, spec, stream};

use crate::support;

/// The first `lines` lines of a fixture file, as text.
fn fixture(relative: &str, lines: usize) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(relative);
    let text = std::fs::read_to_string(path).unwrap();
    text.lines().take(lines).collect::<Vec<_>>().join("\n") + "\n"
}

/// A mutation of a text, picked at random by [`mutation`].
#[derive(Clone, Debug)]
enum Mutation {
    /// Cell `column` of line `line` (both taken modulo the sizes) becomes `value`.
    Cell {
        line: usize,
        column: usize,
        value: String,
    },
    /// Bytes `at .. at + len` are cut out (character boundaries kept).
    Cut { at: usize, len: usize },
    /// `text` is put in at `at`.
    Insert { at: usize, text: String },
    /// The `k`-th number of the text (JSON or CSV) becomes `value`.
    Number { k: usize, value: String },
}

/// Text a hostile or careless user might put in a cell.
fn cell_text() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|v| v.to_string()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
        Just("NaN".to_string()),
        Just("-inf".to_string()),
        Just("1e400".to_string()),
        Just(String::new()),
        Just("\"".to_string()),
        "[ -~]{0,12}",
        ".{0,6}",
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<usize>(), cell_text()).prop_map(|(line, column, value)| {
            Mutation::Cell {
                line,
                column,
                value,
            }
        }),
        (any::<usize>(), 0usize..200).prop_map(|(at, len)| Mutation::Cut { at, len }),
        (any::<usize>(), ".{0,8}").prop_map(|(at, text)| Mutation::Insert { at, text }),
        (any::<usize>(), cell_text()).prop_map(|(k, value)| Mutation::Number { k, value }),
    ]
}

/// The nearest character boundary of `text` at or below `at` (modulo its length).
fn boundary(text: &str, at: usize) -> usize {
    let mut i = at % (text.len() + 1);
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn apply(text: &str, m: &Mutation) -> String {
    match m {
        Mutation::Cell {
            line,
            column,
            value,
        } => {
            let mut lines: Vec<String> = text.lines().map(String::from).collect();
            let l = line % lines.len().max(1);
            if let Some(row) = lines.get_mut(l) {
                let mut cells: Vec<&str> = row.split(',').collect();
                let c = column % cells.len();
                cells[c] = value;
                *row = cells.join(",");
            }
            lines.join("\n") + "\n"
        }
        Mutation::Cut { at, len } => {
            let a = boundary(text, *at);
            let b = boundary(text, a + len);
            let b = b.max(a);
            format!("{}{}", &text[..a], &text[b..])
        }
        Mutation::Insert { at, text: t } => {
            let a = boundary(text, *at);
            format!("{}{t}{}", &text[..a], &text[a..])
        }
        Mutation::Number { k, value } => match support::number_spans(text) {
            spans if spans.is_empty() => text.to_string(),
            spans => {
                let (a, b) = spans[k % spans.len()];
                format!("{}{value}{}", &text[..a], &text[b..])
            }
        },
    }
}

/// An experiment (manifest and its CSV, the CSV cut to its first lines) to mutate.
struct Seed {
    manifest: String,
    csv: Option<String>,
}

fn seed(manifest: &str, csv_lines: usize) -> Seed {
    let csv = Path::new(manifest).with_extension("csv");
    let has_csv = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(&csv)
        .exists();
    Seed {
        manifest: fixture(manifest, 1000),
        csv: has_csv.then(|| fixture(csv.to_str().unwrap(), csv_lines)),
    }
}

/// Writes the experiment under the names `run.json` (+ `run.csv`) and reads it.
fn read_experiment(dir: &Path, manifest: &str, csv: Option<&str>) -> (PathBuf, String, bool) {
    let manifest = manifest.replace(
        &format!("\"{}\"", data_name(manifest).unwrap_or_default()),
        "\"run.csv\"",
    );
    let path = dir.join("run.json");
    std::fs::write(&path, &manifest).unwrap();
    if let Some(csv) = csv {
        std::fs::write(dir.join("run.csv"), csv).unwrap();
    }
    match experiment_file::read(&path) {
        Ok(e) => (path, format!("{:?}", e.data), true),
        Err(e) => (path, e.to_string(), false),
    }
}

/// The `data` file named in a manifest's text.
fn data_name(manifest: &str) -> Option<String> {
    let v: serde_json::Value = serde_json::from_str(manifest).ok()?;
    Some(v.get("data")?.as_str()?.to_string())
}

fn experiment_seeds() -> Vec<Seed> {
    vec![
        seed("worm-gear/frequency_response.json", 400),
        seed("worm-gear/torque_curve.json", 300),
        seed("worm-gear/unbalance.json", 300),
        seed("paper/worm-gear.json", 0),
        seed("real/emps/emps_estimation.json", 300),
        seed("real/two-mass/multisine_a.json", 300),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A mutated experiment file reads with finite data or fails naming the file.
    #[test]
    fn experiment_files_read_finite_or_fail_naming_the_file(
        which in 0usize..6,
        on_csv in any::<bool>(),
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let seeds = experiment_seeds();
        let s = &seeds[which];
        let (mut manifest, mut csv) = (s.manifest.clone(), s.csv.clone());
        for m in &mutations {
            match (&mut csv, on_csv) {
                (Some(c), true) => *c = apply(c, m),
                _ => manifest = apply(&manifest, m),
            }
        }
        let dir = tempfile::tempdir().unwrap();
        let (_, text, ok) = read_experiment(dir.path(), &manifest, csv.as_deref());
        if ok {
            prop_assert!(!support::non_finite(&text), "non-finite data read: {mutations:?}");
        } else {
            prop_assert!(
                text.contains("run.json") || text.contains("run.csv"),
                "the error does not name the file: {text}"
            );
        }
    }

    /// A mutated parameter file reads with finite values or fails naming the file.
    #[test]
    fn parameter_files_read_finite_or_fail_naming_the_file(
        preset in 0usize..4,
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let name = ["worm-gear", "roller-gear-cam", "direct-drive", "two-mass"][preset];
        let mut text = fixture(&format!("presets/{name}.json"), 10_000);
        for m in &mutations {
            text = apply(&text, m);
        }
        match params_file::parse(&text, Path::new("p.json")) {
            Ok(p) => {
                prop_assert!(!support::non_finite(&format!("{p:?}")), "non-finite: {mutations:?}");
                prop_assert!(p.validate().is_ok(), "an invalid set read: {mutations:?}");
            }
            Err(e) => prop_assert!(e.to_string().contains("p.json"), "{e}"),
        }
    }

    /// Any torque file reads as finite, increasing time with finite torque, or fails
    /// naming the file.
    #[test]
    fn torque_files_read_finite_or_fail_naming_the_file(
        rows in prop::collection::vec((cell_text(), cell_text()), 0..20),
        header in prop_oneof![Just("time_s,torque_nm"), Just("t,T"), Just("")],
    ) {
        let mut text = format!("{header}\n");
        for (t, q) in &rows {
            text.push_str(&format!("{t},{q}\n"));
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tq.csv");
        std::fs::write(&path, &text).unwrap();
        match torque_file::read(&path) {
            Ok((time, torque)) => {
                prop_assert!(time.iter().chain(&torque).all(|v| v.is_finite()), "{text}");
                prop_assert!(time.windows(2).all(|w| w[1] > w[0]), "{text}");
            }
            Err(e) => prop_assert!(e.to_string().contains("tq.csv"), "{e}"),
        }
    }

    /// A factor specification parses to a finite, non-empty range or is refused with
    /// the specification quoted.
    #[test]
    fn sweep_factor_specifications_parse_finite_or_are_refused(
        name in prop_oneof![
            Just("Kw".to_string()),
            Just("theta_bw".to_string()),
            Just("Kx".to_string()),
            "[A-Za-z_]{0,5}",
        ],
        low in cell_text(),
        high in cell_text(),
        tail in prop_oneof![
            Just(String::new()),
            Just(":log".to_string()),
            Just(":3".to_string()),
            Just(":0".to_string()),
            ":[0-9a-z]{0,4}",
        ],
    ) {
        let base = rtid::model::presets::load("worm-gear").unwrap();
        let text = format!("{name}={low}..{high}{tail}");
        match spec::parse(&text, &base) {
            Ok(f) => {
                prop_assert!(f.low.is_finite() && f.high.is_finite() && f.low < f.high, "{text}: {f:?}");
            }
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }

    /// Shards print and parse back; any other text is refused.
    #[test]
    fn shards_round_trip(index in 0usize..1000, extra in 1usize..1000, junk in ".{0,10}") {
        let s = stream::Shard { index, count: index + extra };
        prop_assert_eq!(s.to_string().parse::<stream::Shard>().unwrap(), s);
        if let Ok(parsed) = junk.parse::<stream::Shard>() {
            prop_assert!(parsed.index < parsed.count);
        }
    }
}

/// A small finished sweep file to mutate, made once.
fn sweep_file() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(|| {
        let p = rtid::model::presets::load("worm-gear").unwrap();
        let factors = ["Kw=1e5..1e6:log", "Jt=0.08..0.14"]
            .iter()
            .map(|s| spec::parse(s, &p).unwrap())
            .collect();
        let s = sweep::Sweep::new(
            p,
            factors,
            sweep::Method::Morris {
                trajectories: 3,
                levels: 4,
            },
            vec![sweep::Output::Resonances],
            sweep::TestLength::Short,
            7,
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("s.csv");
        sweep::run(&s, &out, &sweep::RunOptions::default()).unwrap();
        std::fs::read_to_string(out).unwrap()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// A mutated sweep file reads with finite numbers or fails naming the file.
    #[test]
    fn sweep_files_read_finite_or_fail_naming_the_file(
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let mut text = sweep_file().to_string();
        for m in &mutations {
            text = apply(&text, m);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        std::fs::write(&path, &text).unwrap();
        match stream::read(&path) {
            Ok((file, _)) => {
                for row in file.rows.values() {
                    for cell in &row[1..row.len() - 1] {
                        prop_assert!(
                            cell.is_empty() || cell.parse::<f64>().is_ok_and(f64::is_finite),
                            "`{cell}` read from {text}"
                        );
                    }
                }
            }
            Err(e) => prop_assert!(e.to_string().contains("s.csv"), "{e}"),
        }
    }
}

/// The seeds themselves read (so the properties above test mutations of valid files,
/// not of files refused whatever the mutation).
#[test]
fn the_unmutated_seeds_read() {
    for s in experiment_seeds() {
        let dir = tempfile::tempdir().unwrap();
        let (path, text, ok) = read_experiment(dir.path(), &s.manifest, s.csv.as_deref());
        assert!(ok, "{}: {text}", path.display());
        assert!(!support::non_finite(&text));
    }
    let (file, partial) = {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        std::fs::write(&path, sweep_file()).unwrap();
        stream::read(&path).unwrap()
    };
    assert!(!partial && file.rows.len() == 9);
    assert!(
        support::non_finite("[1.0, NaN]")
            && support::non_finite("x: -inf,")
            && !support::non_finite("\"inf\" 2.0")
    );
}
