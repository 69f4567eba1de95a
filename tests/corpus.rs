//! The project's own corpus of malformed and hostile inputs (issue 13), generated
//! here and run through the real binary: every experiment-file kind with its manifest
//! and its CSV mutated, every model parameter set to extreme values, numeric options
//! given absurd values. Each run must end within its time limit, without a panic,
//! with exit 0 and finite output, or with a clear error: one line `error: …` (exit 1)
//! naming the culprit, or clap's usage error naming the option (exit 2).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support;

const LIMIT: Duration = Duration::from_secs(60);

/// What a run did.
struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

/// Runs `rtid ARGS` in `dir`, killed (and reported as a hang) after [`LIMIT`].
fn rtid(args: &[String], dir: &Path) -> Run {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the rtid binary runs");
    let started = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if started.elapsed() > LIMIT {
            let _ = child.kill();
            panic!("rtid {args:?} hangs (over {LIMIT:?})");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let out = child.wait_with_output().expect("output");
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// The failures of a corpus, reported together at the end.
#[derive(Default)]
struct Failures(Vec<String>);

impl Failures {
    /// Checks one run (see [`check`]), keeping its failure.
    fn check(&mut self, args: &[String], run: &Run, culprit: &str) {
        let r =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| check(args, run, culprit)));
        if let Err(e) = r {
            let message = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            self.0.push(message);
        }
    }

    fn assert_none(self, cases: usize) {
        assert!(
            self.0.is_empty(),
            "{} of {cases} cases failed:\n\n{}",
            self.0.len(),
            self.0
                .iter()
                .take(12)
                .cloned()
                .collect::<Vec<_>>()
                .join("\n\n")
        );
    }
}

/// The checks every run passes; `culprit` must appear in an error.
fn check(args: &[String], run: &Run, culprit: &str) {
    let what = format!(
        "rtid {args:?}\nstdout: {}\nstderr: {}",
        run.stdout, run.stderr
    );
    assert!(!run.stderr.contains("panicked"), "panic: {what}");
    match run.code {
        Some(0) => {
            for bad in ["NaN", "inf"] {
                assert!(
                    !run.stdout.contains(bad),
                    "`{bad}` in the output of a successful run: {what}"
                );
            }
            if let Ok(v) = serde_json::from_str::<serde_json::Value>(&run.stdout) {
                assert!(!nan_in(&v), "a NaN written as null among numbers: {what}");
            }
        }
        Some(1) => {
            let lines: Vec<&str> = run.stderr.lines().collect();
            assert_eq!(lines.len(), 1, "one line: {what}");
            assert!(lines[0].starts_with("error: "), "{what}");
            assert!(lines[0].contains(culprit), "`{culprit}` not named: {what}");
            assert!(lines[0].len() < 600, "a short message: {what}");
            assert!(!lines[0].contains(".tmp"), "a temporary name: {what}");
        }
        Some(2) => assert!(
            run.stderr.contains(culprit),
            "clap's error does not name `{culprit}`: {what}"
        ),
        other => panic!("exit {other:?}: {what}"),
    }
}

/// Whether a JSON value holds a null among numbers (how serde_json writes a NaN); a
/// null field alone is an absent value.
fn nan_in(v: &serde_json::Value) -> bool {
    use serde_json::Value;
    match v {
        Value::Array(items) => {
            (items.iter().any(Value::is_null) && items.iter().any(Value::is_number))
                || items.iter().any(nan_in)
        }
        Value::Object(map) => map.values().any(nan_in),
        _ => false,
    }
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn fixture(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(relative)
}

/// Mutations of a JSON manifest's text: each a new text.
fn manifest_mutations(text: &str) -> Vec<String> {
    let mut out = vec![
        String::new(),
        "{".into(),
        "[]".into(),
        "null".into(),
        "\u{0}\u{1}\u{2}binary".into(),
        text.replace("\"kind\"", "\"kinds\""),
        text.replace("\"data\"", "\"dada\""),
        text.replacen(':', ": \"x\", \"y\":", 1),
        text.replace('}', "},"),
        format!("{text}\n{{}}"),
    ];
    for cut in [1, text.len() / 3, text.len() / 2, text.len() - 2] {
        out.push(text[..cut.min(text.len())].to_string());
    }
    // Every number replaced in turn by hostile values.
    let numbers: Vec<(usize, usize)> = support::number_spans(text);
    for (k, &(a, b)) in numbers.iter().enumerate().take(8) {
        for value in ["-1", "0", "1e308", "-1e308", "1e-320", "\"5\"", "true"] {
            let _ = k;
            out.push(format!("{}{value}{}", &text[..a], &text[b..]));
        }
    }
    out
}

/// Mutations of a CSV's text.
fn csv_mutations(text: &str) -> Vec<String> {
    let lines: Vec<&str> = text.lines().collect();
    let header = lines.iter().position(|l| !l.starts_with('#')).unwrap_or(0);
    let body = |f: &dyn Fn(usize, &str) -> String| -> String {
        lines
            .iter()
            .enumerate()
            .map(|(i, l)| if i > header { f(i, l) } else { l.to_string() })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let at = header + 3;
    let replace_cell = |value: &'static str| {
        body(&move |i, l| {
            if i == at {
                let mut cells: Vec<&str> = l.split(',').collect();
                let last = cells.len() - 1;
                cells[last] = value;
                cells.join(",")
            } else {
                l.to_string()
            }
        })
    };
    let mut out = vec![
        String::new(),
        lines[..=header].join("\n"),
        lines[header + 1..].join("\n"),
        text.replacen(lines[header], &lines[header].replace(',', ";"), 1),
        text.replacen(
            lines[header],
            &format!("{},{}", lines[header], "extra_nm"),
            1,
        ),
        text.replacen(lines[header], "time_s", 1),
        body(&|i, l| {
            if i == at {
                String::new()
            } else {
                l.to_string()
            }
        }),
        body(&|i, l| {
            if i == at {
                format!("{l},7")
            } else {
                l.to_string()
            }
        }),
        body(&|i, l| {
            if i == at {
                l.split(',').next().unwrap_or("").to_string()
            } else {
                l.to_string()
            }
        }),
        body(&|i, l| {
            if i == at {
                lines[at - 1].to_string()
            } else {
                l.to_string()
            }
        }),
        body(&|i, l| {
            if i == at {
                lines[at + 1].to_string()
            } else {
                l.to_string()
            }
        }),
        format!("{}\n1,2", text),
        text[..text.len() * 2 / 3].to_string(),
        format!("\u{feff}{text}"),
    ];
    for value in [
        "nan", "NaN", "inf", "-inf", "1e309", "", "abc", "0x10", "1,5", "\"2\"",
    ] {
        out.push(replace_cell(value));
    }
    out
}

/// A copy of an experiment (manifest and CSV) in `dir`, with one of them replaced.
fn write_case(dir: &Path, manifest: &Path, text: Option<&str>, csv: Option<&str>) -> String {
    let m = std::fs::read_to_string(manifest).unwrap();
    let stem = manifest.file_stem().unwrap().to_str().unwrap();
    let data = manifest.with_extension("csv");
    let name = format!("{stem}.json");
    std::fs::write(dir.join(&name), text.unwrap_or(&m)).unwrap();
    if data.exists() {
        let c = std::fs::read_to_string(&data).unwrap();
        std::fs::write(dir.join(format!("{stem}.csv")), csv.unwrap_or(&c)).unwrap();
    }
    name
}

#[test]
fn malformed_experiment_files_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases = 0;
    let mut failures = Failures::default();
    for relative in [
        "worm-gear/frequency_response.json",
        "worm-gear/torque_curve.json",
        "worm-gear/unbalance.json",
        "real/emps/emps_estimation.json",
        "paper/worm-gear.json",
    ] {
        let manifest = fixture(relative);
        let text = std::fs::read_to_string(&manifest).unwrap();
        for m in manifest_mutations(&text) {
            let case = tempfile::tempdir_in(dir.path()).unwrap();
            let name = write_case(case.path(), &manifest, Some(&m), None);
            let args = strings(&["evaluate", &name, "--json", "--plot", "p.svg"]);
            failures.check(&args, &rtid(&args, case.path()), &name);
            cases += 1;
        }
        let data = manifest.with_extension("csv");
        if data.exists() && !relative.starts_with("real/") {
            let csv = std::fs::read_to_string(&data).unwrap();
            let csv_name = data.file_name().unwrap().to_str().unwrap().to_string();
            for c in csv_mutations(&csv) {
                let case = tempfile::tempdir_in(dir.path()).unwrap();
                let name = write_case(case.path(), &manifest, None, Some(&c));
                let args = strings(&["evaluate", &name, "--json", "--plot", "p.svg"]);
                let run = rtid(&args, case.path());
                // A data error names the CSV (the file, then its line and column).
                check(
                    &args,
                    &run,
                    if run.code == Some(1) {
                        &csv_name
                    } else {
                        &name
                    },
                );
                cases += 1;
            }
        }
    }
    assert!(cases >= 150, "{cases} cases");
    failures.assert_none(cases);
}

#[test]
fn extreme_parameter_values_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let names = [
        "Jm",
        "Jw",
        "Jt",
        "Mw",
        "Cm",
        "Cw",
        "Cb",
        "Ct",
        "Cig",
        "Ciw",
        "fm",
        "fw",
        "ft",
        "Kg",
        "Kw",
        "Kb",
        "Rg",
        "Rw",
        "r",
        "theta_bg",
        "theta_bw",
        "W",
        "fluct_order",
        "unbalance_mass",
        "encoder_delay",
    ];
    let mut cases = 0;
    let mut failures = Failures::default();
    for name in names {
        for value in ["-1", "0", "1e308", "1e-300", "nan", "inf", "x"] {
            let set = format!("{name}={value}");
            let args = strings(&["modes", "--preset", "worm-gear", "--set", &set, "--json"]);
            failures.check(&args, &rtid(&args, dir.path()), name);
            cases += 1;
        }
    }
    assert!(cases >= 150, "{cases} cases");
    failures.assert_none(cases);
}

#[test]
fn absurd_option_values_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let fr = [
        "experiment",
        "frequency-response",
        "--preset",
        "worm-gear",
        "--from-hz",
        "100",
        "--to-hz",
        "120",
        "--out",
        "o",
        "--quiet",
    ];
    let sim = [
        "simulate",
        "--preset",
        "worm-gear",
        "--input",
        "sine:freq_hz=100,amp_nm=5",
        "--duration-s",
        "0.01",
        "--out",
        "r.csv",
    ];
    let data = fixture("worm-gear/frequency_response.json");
    let identify = [
        "identify",
        data.to_str().unwrap(),
        "--preset",
        "worm-gear",
        "--fit",
        "Kw,Kg",
        "--model",
        "linear",
        "--starts",
        "1",
        "--max-iters",
        "3",
    ];
    let cases: &[(&[&str], &[&str])] = &[
        (&identify, &["--max-iters", "--starts"]),
        (
            &fr,
            &[
                "--amplitude-nm",
                "--preload-nm",
                "--step-hz",
                "--refine-step-hz",
                "--noise-percent",
                "--from-hz",
                "--to-hz",
            ],
        ),
        (&sim, &["--duration-s", "--sample-s", "--dt-s", "--load-nm"]),
    ];
    let mut n = 0;
    let mut failures = Failures::default();
    for (base, options) in cases {
        for option in *options {
            for value in ["-1", "0", "nan", "inf", "1e308", "1e-300", "abc"] {
                let mut args = strings(base);
                if let Some(i) = args.iter().position(|a| a == option) {
                    args[i + 1] = value.to_string();
                } else {
                    args.extend([option.to_string(), value.to_string()]);
                }
                failures.check(&args, &rtid(&args, dir.path()), option);
                n += 1;
            }
        }
    }
    assert!(n >= 84, "{n} cases");
    failures.assert_none(n);
}

/// The files labs export (fixtures/formats/) cut, corrupted and emptied: `rtid import
/// --list` reads what is left or names the file, never panics or hangs.
#[test]
fn malformed_lab_exports_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let mut sources: Vec<PathBuf> = Vec::new();
    for folder in ["matlab", "twincat-scope", "epos", "uff", "sinumerik"] {
        let mut found: Vec<PathBuf> = files_under(&fixture("formats").join(folder))
            .into_iter()
            .filter(|p| {
                matches!(
                    p.extension().and_then(|e| e.to_str()),
                    Some("mat" | "csv" | "uff" | "XML")
                )
            })
            .collect();
        found.sort();
        sources.extend(found.into_iter().take(3));
    }
    assert!(
        sources.len() >= 8,
        "the format fixtures are there: {sources:?}"
    );
    let mut failures = Failures::default();
    let mut cases = 0;
    for source in &sources {
        let bytes = std::fs::read(source).unwrap();
        let ext = source.extension().unwrap().to_str().unwrap();
        for (k, case) in byte_mutations(&bytes).into_iter().enumerate() {
            let name = format!(
                "{}-{k}.{ext}",
                source.file_stem().unwrap().to_string_lossy()
            );
            std::fs::write(dir.path().join(&name), &case).unwrap();
            let args = strings(&["import", &name, "--list", "--json"]);
            failures.check(&args, &rtid(&args, dir.path()), &name);
            cases += 1;
        }
    }
    failures.assert_none(cases);
}

/// Every file below `dir`.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else {
            out.push(path);
        }
    }
    out
}

/// A file's bytes cut short (in the header, in the middle, one byte before the end),
/// emptied, with a block overwritten by garbage, and with every byte of its first
/// kilobyte flipped.
fn byte_mutations(bytes: &[u8]) -> Vec<Vec<u8>> {
    let n = bytes.len();
    let mut out = vec![
        Vec::new(),
        bytes[..n.min(64)].to_vec(),
        bytes[..n / 2].to_vec(),
        bytes[..n.saturating_sub(1)].to_vec(),
    ];
    let mut garbage = bytes.to_vec();
    let (a, b) = (n / 3, (n / 3 + 512).min(n));
    for (i, x) in garbage[a..b].iter_mut().enumerate() {
        *x = (i as u8).wrapping_mul(151).wrapping_add(7);
    }
    out.push(garbage);
    let mut flipped = bytes.to_vec();
    for x in flipped.iter_mut().take(1024) {
        *x = !*x;
    }
    out.push(flipped);
    out
}

/// Lists with an empty name and repeated ranges are refused naming the option, not
/// fitted with the default parameters or the last range silently (issue 28).
#[test]
fn empty_names_and_repeated_bounds_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let data = fixture("worm-gear/frequency_response.json");
    let data = data.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--fit", ""], "--fit"),
        (&["--fit", "Kw,"], "--fit"),
        (&["--fit", "Kw,,Kg"], "--fit"),
        (&["--fit", "Kw", "--fit", "Kw"], "Kw"),
        (
            &[
                "--fit",
                "Kw",
                "--bound",
                "Kw=1e5..1e7",
                "--bound",
                "Kw=1e5..1e6",
            ],
            "--bound",
        ),
    ];
    for (extra, culprit) in cases {
        let mut args = strings(&[
            "identify",
            data,
            "--preset",
            "worm-gear",
            "--model",
            "linear",
            "--starts",
            "1",
            "--max-iters",
            "1",
            "--quiet",
        ]);
        args.extend(strings(extra));
        let run = rtid(&args, dir.path());
        assert_eq!(run.code, Some(1), "{extra:?} is refused: {}", run.stderr);
        check(&args, &run, culprit);
    }
}

/// A negative number in exponent form and a negative shard reach the option's own
/// check, which names the option, rather than clap's "unexpected argument '-1'".
#[test]
fn negative_values_reach_the_options_own_check() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "simulate",
                "--preset",
                "worm-gear",
                "--input",
                "sine:freq_hz=100,amp_nm=5",
                "--duration-s",
                "0.01",
                "--dt-s",
                "-1e-5",
                "--out",
                "r.csv",
            ],
            "--dt-s -1e-5",
        ),
        (
            &[
                "sweep",
                "--preset",
                "worm-gear",
                "--method",
                "local",
                "--vary",
                "Kw",
                "--outputs",
                "resonances",
                "--shard",
                "-1/2",
                "--out",
                "s.csv",
            ],
            "'-1/2' for '--shard",
        ),
    ];
    for (args, culprit) in cases {
        let args = strings(args);
        let run = rtid(&args, dir.path());
        assert!(
            !run.stderr.contains("unexpected argument"),
            "{}",
            run.stderr
        );
        assert_ne!(run.code, Some(0), "{args:?} is refused");
        check(&args, &run, culprit);
    }
}

/// Issue 28's classes met at their root: torque curves out of any physical range
/// (angles or torques of ±1e308, a time step of 1e-300 s or 1e300 s) are evaluated at
/// once with no null among the friction law's numbers (the law's least squares hung on
/// them, or wrote null), or refused naming the column.
#[test]
fn records_out_of_range_are_met_at_their_root() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let manifest = std::fs::read_to_string(fixture("worm-gear/torque_curve.json")).unwrap();
    let csv = std::fs::read_to_string(fixture("worm-gear/torque_curve.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let alternate = |k: usize| if k % 2 == 0 { "1e308" } else { "-1e308" }.to_string();
    type Edit = fn(usize, &mut Vec<String>, &dyn Fn(usize) -> String);
    // Each with what a refusal names: the value's column (beyond ±1e15 SI).
    let edits: [(&str, Edit, &str); 4] = [
        (
            "angles",
            |k, r, alt| r[2] = alt(k),
            "`table_angle_deg`: 1e308",
        ),
        (
            "torques",
            |k, r, alt| r[1] = alt(k),
            "`motor_torque_nm`: 1e308",
        ),
        (
            "tiny-step",
            |k, r, _| r[0] = format!("{:e}", k as f64 * 1e-300),
            "time_s",
        ),
        (
            "huge-step",
            |k, r, _| r[0] = format!("{:e}", k as f64 * 1e300),
            "`time_s`: 1e300",
        ),
    ];
    for (name, edit, culprit) in edits {
        let mut text = String::from("time_s,motor_torque_nm,table_angle_deg\n");
        for (k, row) in rows.iter().enumerate() {
            let mut row = row.clone();
            edit(k, &mut row, &alternate);
            text += &(row.join(",") + "\n");
        }
        std::fs::write(d.join(format!("{name}.csv")), text).unwrap();
        let m = manifest.replace("torque_curve.csv", &format!("{name}.csv"));
        std::fs::write(d.join(format!("{name}.json")), m).unwrap();
        let args = strings(&["evaluate", &format!("{name}.json"), "--json"]);
        let run = rtid(&args, d);
        check(&args, &run, culprit);
        if run.code == Some(0) {
            let v: serde_json::Value = serde_json::from_str(&run.stdout).unwrap();
            let law = &v["inverse_dynamics"];
            assert!(
                law.is_null() || !law.to_string().contains("null"),
                "{name}: {law}"
            );
        }
    }
}

/// A resonance file's non-positive or absurd peak, a parameter file's null, a weight
/// of 1e308 and a sample rate below the band's are refused naming the field or option.
#[test]
fn values_out_of_range_are_refused_naming_their_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let worm = fixture("worm-gear/frequency_response.json");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            strings(&["identify", "peaks.json", "--preset", "worm-gear"]),
            "peaks_hz",
        ),
        (strings(&["modes", "--params", "null.json"]), "`Cw` is null"),
        (
            strings(&[
                "identify",
                worm.to_str().unwrap(),
                "--preset",
                "worm-gear",
                "--weight",
                "1e308",
            ]),
            "--weight 1e308",
        ),
        (
            strings(&[
                "experiment",
                "frequency-response-time",
                "--preset",
                "worm-gear",
                "--sample-rate-hz",
                "1",
                "--out",
                "slow",
            ]),
            "--sample-rate-hz 1: a record sampled at it holds frequencies up to 0.5 Hz",
        ),
    ];
    let mut params: serde_json::Value = serde_json::from_str(&rtid_ok_json(d)).unwrap();
    params["Cw"] = serde_json::Value::Null;
    std::fs::write(d.join("null.json"), params.to_string()).unwrap();
    for peaks in ["[-100]", "[0, 200]", "[100, 1e308]"] {
        let m = format!("{{\"kind\": \"resonance\", \"peaks_hz\": {peaks}}}");
        std::fs::write(d.join("peaks.json"), m).unwrap();
        let (args, culprit) = &cases[0];
        let run = rtid(args, d);
        assert_eq!(run.code, Some(1), "{peaks}: {}", run.stderr);
        check(args, &run, culprit);
    }
    for (args, culprit) in &cases[1..] {
        let run = rtid(args, d);
        assert_eq!(run.code, Some(1), "{args:?}: {}", run.stderr);
        check(args, &run, culprit);
    }
}

/// A checkpoint resumed with another parameter held, or with a corrupted stage, or a
/// field nested thousands deep, is refused naming it; a start whose cost was emptied
/// runs again.
#[test]
fn checkpoints_of_other_runs_or_corrupted_are_met_at_their_root() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let worm = fixture("worm-gear/frequency_response.json");
    let fit = |extra: &[&str]| {
        let mut args = strings(&[
            "identify",
            worm.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--fit",
            "Kw,Kg",
            "--model",
            "linear",
            "--starts",
            "1",
            "--max-iters",
            "3",
            "--checkpoint",
            "c.json",
            "--quiet",
        ]);
        args.extend(strings(extra));
        (rtid(&args, d), args)
    };
    assert_eq!(fit(&[]).0.code, Some(0));
    let (run, args) = fit(&["--resume", "--set", "Jt=0.2"]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    check(&args, &run, "another problem (the parameters held differ)");
    let text = std::fs::read_to_string(d.join("c.json")).unwrap();
    let mut c: serde_json::Value = serde_json::from_str(&text).unwrap();
    c["stage"] = 7.into();
    std::fs::write(d.join("c.json"), c.to_string()).unwrap();
    let (run, args) = fit(&["--resume"]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    check(&args, &run, "stage is 7");
    // A field the checkpoint does not have, nested thousands deep.
    c["stage"] = 0.into();
    let deep = "[".repeat(5000) + &"]".repeat(5000);
    let text = c
        .to_string()
        .replacen('{', &format!("{{\"extra\": {deep}, "), 1);
    std::fs::write(d.join("c.json"), text).unwrap();
    let (run, args) = fit(&["--resume"]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    check(&args, &run, "not an rtid checkpoint");
    // A finished start whose cost was emptied runs again from its result (it ended
    // "no parameter set could be evaluated: stopped before any evaluation").
    for start in c["starts"].as_array_mut().unwrap() {
        start["cost"] = serde_json::Value::Null;
    }
    std::fs::write(d.join("c.json"), c.to_string()).unwrap();
    let (run, args) = fit(&["--resume", "--out", "f.json"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let f: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("f.json")).unwrap()).unwrap();
    assert!(
        f["cost"].as_f64().is_some_and(f64::is_finite),
        "{args:?}: {f}"
    );
}

/// The worm preset's parameter file, as `rtid params --out` writes it.
fn rtid_ok_json(dir: &Path) -> String {
    let args = strings(&[
        "params",
        "--preset",
        "worm-gear",
        "--out",
        "p.json",
        "--quiet",
    ]);
    let run = rtid(&args, dir);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    std::fs::read_to_string(dir.join("p.json")).unwrap()
}

/// Issue 37's frequency class: a response's lines at subnormal frequencies (1e-319 Hz:
/// the modal fit's arithmetic crawled for minutes), at 0 or below, are refused when
/// the file is read, naming the line and column; a line at 1e-6 Hz is still a
/// frequency.
#[test]
fn frequencies_no_test_can_reach_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let manifest = std::fs::read_to_string(fixture("worm-gear/frequency_response.json")).unwrap();
    let csv = std::fs::read_to_string(fixture("worm-gear/frequency_response.csv")).unwrap();
    for (name, scale, culprit) in [
        ("subnormal", 1e-320, Some("line 3, column `frequency_hz`")),
        ("negative", -1.0, Some("line 3, column `frequency_hz`")),
        ("slow", 1e-6, None),
    ] {
        let text: String = csv
            .lines()
            .map(|l| match l.split_once(',') {
                Some((f, rest)) if f.parse::<f64>().is_ok() => {
                    let f: f64 = f.parse().unwrap();
                    // Negative frequencies ascending too: only the sign is wrong.
                    let f = if scale < 0.0 { f - 1e4 } else { f * scale };
                    format!("{f:e},{rest}\n")
                }
                _ => format!("{l}\n"),
            })
            .collect();
        std::fs::write(d.join(format!("{name}.csv")), text).unwrap();
        let m = manifest.replace("frequency_response.csv", &format!("{name}.csv"));
        std::fs::write(d.join(format!("{name}.json")), m).unwrap();
        let args = strings(&["evaluate", &format!("{name}.json"), "--json"]);
        let run = rtid(&args, d);
        match culprit {
            Some(culprit) => {
                assert_ne!(run.code, Some(0), "{name}: {}", run.stdout);
                check(&args, &run, culprit);
            }
            None => check(&args, &run, ""),
        }
    }
}

/// Issue 37's size class: a frequency response of 400 000 lines of noise (19 MB;
/// some 120 000 local maxima) is evaluated in seconds — each peak's modal fit works on
/// its band's lines, found by bisection; it scanned every line per peak and took
/// minutes.
#[test]
fn a_long_noisy_response_is_evaluated_in_seconds() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut text = String::from("frequency_hz,gain_db,phase_deg\n");
    for k in 0..400_000 {
        let f = 1.0 + k as f64 * 0.005;
        text += &format!(
            "{f},{},{}\n",
            10.0 * uniform() - 5.0,
            360.0 * uniform() - 180.0
        );
    }
    std::fs::write(d.join("noisy.csv"), text).unwrap();
    std::fs::write(
        d.join("noisy.json"),
        r#"{"kind": "frequency_response", "data": "noisy.csv"}"#,
    )
    .unwrap();
    // Its report lists every maximum (megabytes): written to a file, not a pipe.
    let report = std::fs::File::create(d.join("report.txt")).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(["evaluate", "noisy.json"])
        .current_dir(d)
        .stdout(report)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(
            started.elapsed() < LIMIT,
            "evaluate hangs on a long noisy response"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(child.wait().unwrap().success());
    let text = std::fs::read_to_string(d.join("report.txt")).unwrap();
    assert!(
        text.contains("modes (") && !text.contains("NaN"),
        "{}",
        &text[..500]
    );
}

/// Issue 50's hostile corpus: misspelt names refused with the closest known one,
/// ranges through a parameter's forbidden zero, a doubled `:log`, a torque curve of
/// 6e-298 s and a ratio of 1e308 — each one line naming the field or option; a
/// frequency response written with ordinary number forms (signs, leading dots,
/// exponents) read as any other, with a finite result.
#[test]
fn misspellings_and_ranges_through_zero_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let worm = fixture("worm-gear/frequency_response.json");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&worm).unwrap()).unwrap();
    let csv = std::fs::read_to_string(worm.with_extension("csv")).unwrap();
    let write = |name: &str, edit: &dyn Fn(&mut serde_json::Value), text: &str| {
        let mut m = manifest.clone();
        m["data"] = format!("{name}.csv").into();
        edit(&mut m);
        std::fs::write(d.join(format!("{name}.json")), m.to_string()).unwrap();
        std::fs::write(d.join(format!("{name}.csv")), text).unwrap();
    };
    write(
        "preload",
        &|m| m["conditions"]["preload"] = 5.0.into(),
        &csv,
    );
    write("ratio", &|m| m["conditions"]["ratio"] = 1e308.into(), &csv);
    write(
        "column",
        &|_| {},
        &csv.replacen("phase_deg", "phase_degs", 1),
    );
    let torque = "time_s,motor_torque_nm\n0,0.1\n2e-298,0.2\n4e-298,-0.1\n6e-298,0.0\n";
    std::fs::write(d.join("short.json"), r#"{"kind": "torque_curve"}"#).unwrap();
    std::fs::write(d.join("short.csv"), torque).unwrap();
    let identify = |file: &str, more: &[&str]| {
        let mut a = strings(&["identify", file, "--preset", "worm-gear"]);
        a.extend(strings(more));
        a
    };
    let sweep = |vary: &str| {
        strings(&[
            "sweep",
            "--preset",
            "worm-gear",
            "--vary",
            vary,
            "--outputs",
            "resonances",
            "--out",
            "s.csv",
        ])
    };
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            identify("preload.json", &[]),
            "`conditions.preload` is not a condition rtid reads: did you mean `preload_nm`?",
        ),
        (identify("ratio.json", &[]), "`conditions.ratio` is 1e308"),
        (
            identify("column.json", &[]),
            "column `phase_degs` is not one rtid reads: did you mean `phase_deg`?",
        ),
        (strings(&["evaluate", "short.json"]), "short.csv, line 3"),
        (
            identify(
                worm.to_str().unwrap(),
                &["--fit", "Kw", "--bound", "Kw=-1..1e6"],
            ),
            "--bound Kw=-1..1000000",
        ),
        (
            identify(worm.to_str().unwrap(), &["--fit", "Kww"]),
            "did you mean `Kw`?",
        ),
        (
            sweep("Rg=-1..1"),
            "--vary Rg=-1..1: the parameter must not be 0",
        ),
        (sweep("Kw=1e5..2e5:log:log"), "the scale is given twice"),
    ];
    let fit = fixture("predict/worm-gear/fit.json");
    let predict = |uncertain: &str| {
        strings(&[
            "predict",
            fit.to_str().unwrap(),
            "--preset",
            "worm-gear",
            "--uncertain",
            uncertain,
        ])
    };
    let cases = cases.into_iter().chain([
        (
            predict("Kw=150%"),
            "--uncertain Kw=150%: the range must lie from 0 % (held exactly) to below 100 %",
        ),
        (predict("fm=10%"), "fm is fitted"),
        (predict("Kww=10%"), "did you mean `Kw`?"),
        (predict("Kw=10"), "expected NAME=X%"),
    ]);
    for (args, culprit) in cases {
        let run = rtid(&args, d);
        assert_eq!(run.code, Some(1), "{args:?}: {}", run.stderr);
        check(&args, &run, culprit);
    }
    // The same response with each line's numbers in another ordinary form, and as
    // Rust writes them: the same numbers, so the same fit to the last bit.
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|row| row.split(',').take(3).map(|c| c.parse().unwrap()).collect())
        .collect();
    let table = |form: &dyn Fn(usize, f64) -> String| {
        let mut text = String::from("frequency_hz,gain_db,phase_deg\n");
        for (k, cells) in rows.iter().enumerate() {
            let line: Vec<String> = cells.iter().map(|&x| form(k, x)).collect();
            text += &format!("{}\n", line.join(","));
        }
        text
    };
    write("plain", &|_| {}, &table(&|_, x| format!("{x}")));
    let forms = table(&|k, x| match k % 4 {
        0 => format!("{x:+e}"),
        1 if x.abs() < 1.0 => format!("{x}").replacen("0.", ".", 1),
        2 => format!("{x:E}"),
        _ => format!("{x}"),
    });
    assert!(forms.contains(",+") && forms.contains(",.") && forms.contains('E'));
    write("forms", &|_| {}, &forms);
    // (The results to files: this corpus's runs are read after they end, and a
    // result's JSON on stdout outgrows the pipe.)
    let fit = |name: &str| {
        let out = format!("{name}-fit.json");
        let args = identify(
            &format!("{name}.json"),
            &[
                "--fit", "Kw,Kg", "--model", "linear", "--out", &out, "--quiet",
            ],
        );
        let run = rtid(&args, d);
        check(&args, &run, "");
        assert_eq!(run.code, Some(0), "{}", run.stderr);
        let text = std::fs::read_to_string(d.join(out)).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert!(v["cost"].as_f64().is_some_and(f64::is_finite), "{text}");
        (v["parameters"].clone(), v["cost"].clone())
    };
    assert_eq!(fit("forms"), fit("plain"));
}
