//! Property tests of the readers of the files labs export (issue 28): the real files
//! of `fixtures/formats/` (MAT-files v5 and v7, TwinCAT Scope CSV, EPOS Studio CSV,
//! UFF 58 and 58b) with their bytes mutated at random — cut short, cut out, put in,
//! overwritten with garbage, a binary size field set to 10⁸ or 2³²−1, a number of the
//! text replaced by 10⁸, −1 or 1e308, a line dropped or doubled. Each reader must then
//! return a consistent recording or an error naming the file; it must never panic, hang
//! or allocate beyond what the file can hold. And `rtid import` of a mutated file
//! mapped as the docs map it must write an experiment that reads back finite, or fail
//! in one line. (`tests/corpus.rs` runs a fixed set of such files through `import
//! --list`; this explores at random.)

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use rtid::io::experiment_file;
use rtid::io::formats::{detect, Abscissa, Recording, Samples};

use crate::alloc_watch::largest_allocation;
use crate::support;

/// The largest single allocation a reader may make: what the largest fixture (626 kB)
/// legitimately needs is a few MB (its doubles, grown by doubling); a size taken from a
/// header without a check against the file's bytes is 10⁸ samples, 800 MB.
const ALLOCATION_LIMIT: usize = 64 << 20;

/// A reader that takes longer than this on a file under 1 MB hangs.
const TIME_LIMIT: Duration = Duration::from_secs(30);

fn fixture(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(relative)
}

/// The real files the readers are fuzzed on: every format, both byte orders, both
/// MAT-file versions, ASCII and binary UFF.
const SEEDS: [&str; 15] = [
    "formats/matlab/DATA_EMPS.mat",
    "formats/matlab/arrays_be.mat",
    "formats/matlab/arrays_v7_compressed.mat",
    "formats/matlab/classes.mat",
    "formats/matlab/struct_be_compressed.mat",
    "formats/twincat-scope/tc3_scope_3_4_3145_3-DecimalMark_,.csv",
    "formats/twincat-scope/tc3_scope_3_4_3145_3_noOS.csv",
    "formats/epos/driveNo1/steady_state/20.csv",
    "formats/epos/driveNo2/start_stop/50.csv",
    "formats/uff/Sample_UFF58b_bin.first4000.uff",
    "formats/uff/pyuff_frf_uneven.uff",
    "formats/uff/pyuff_58b.uff",
    "formats/uff/time-history-not-all-columns-filled.uff",
    "frf/worm_frf.uff",
    "formats/sinumerik/freq_trace.XML",
];

/// A change to a file's bytes, picked at random by [`mutation`]; positions are taken
/// modulo the file's length.
#[derive(Clone, Debug)]
enum Mutation {
    /// The file ends at `at`.
    Truncate { at: usize },
    /// Bytes `at .. at + len` are cut out.
    Cut { at: usize, len: usize },
    /// `bytes` are put in at `at`.
    Insert { at: usize, bytes: Vec<u8> },
    /// `bytes` overwrite the file from `at`.
    Overwrite { at: usize, bytes: Vec<u8> },
    /// A 32-bit word at a 4-byte boundary (a binary format's size or type field)
    /// becomes `value`.
    Word {
        at: usize,
        value: u32,
        big_endian: bool,
    },
    /// The `k`-th run of ASCII digits becomes `text`.
    Number { k: usize, text: String },
    /// Line `k` is dropped or doubled.
    Line { k: usize, double: bool },
}

/// Sizes a hostile header declares.
fn size_word() -> impl Strategy<Value = u32> {
    prop_oneof![
        Just(100_000_000u32),
        Just(u32::MAX),
        Just(0x8000_0000),
        Just(0x7fff_ffff),
        Just(0),
        Just(1),
        any::<u32>(),
    ]
}

fn number_text() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("100000000".to_string()),
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("1e308".to_string()),
        Just("18446744073709551616".to_string()),
        Just("NaN".to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let garbage = prop::collection::vec(any::<u8>(), 1..64);
    prop_oneof![
        any::<usize>().prop_map(|at| Mutation::Truncate { at }),
        (any::<usize>(), 1usize..4096).prop_map(|(at, len)| Mutation::Cut { at, len }),
        (any::<usize>(), garbage.clone()).prop_map(|(at, bytes)| Mutation::Insert { at, bytes }),
        (any::<usize>(), garbage).prop_map(|(at, bytes)| Mutation::Overwrite { at, bytes }),
        (any::<usize>(), size_word(), any::<bool>()).prop_map(|(at, value, big_endian)| {
            Mutation::Word {
                at,
                value,
                big_endian,
            }
        }),
        (any::<usize>(), number_text()).prop_map(|(k, text)| Mutation::Number { k, text }),
        (any::<usize>(), any::<bool>()).prop_map(|(k, double)| Mutation::Line { k, double }),
    ]
}

/// The runs of ASCII digits in `bytes`, as ranges.
fn digit_runs(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit() {
            let start = i;
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
            runs.push((start, i));
        } else {
            i += 1;
        }
    }
    runs
}

/// The ranges of the lines of `bytes`, each with its end of line.
fn lines(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' {
            out.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < bytes.len() {
        out.push((start, bytes.len()));
    }
    out
}

fn splice(bytes: &[u8], (a, b): (usize, usize), with: &[u8]) -> Vec<u8> {
    [&bytes[..a], with, &bytes[b..]].concat()
}

fn apply(bytes: &[u8], m: &Mutation) -> Vec<u8> {
    let n = bytes.len();
    let at = |i: usize| i % (n + 1);
    match m {
        Mutation::Truncate { at: i } => bytes[..at(*i)].to_vec(),
        Mutation::Cut { at: i, len } => splice(bytes, (at(*i), (at(*i) + len).min(n)), &[]),
        Mutation::Insert { at: i, bytes: b } => splice(bytes, (at(*i), at(*i)), b),
        Mutation::Overwrite { at: i, bytes: b } => {
            let a = at(*i);
            splice(bytes, (a, (a + b.len()).min(n)), b)
        }
        Mutation::Word {
            at: i,
            value,
            big_endian,
        } if n >= 4 => {
            let a = (i % (n - 3)) & !3;
            let word = match big_endian {
                true => value.to_be_bytes(),
                false => value.to_le_bytes(),
            };
            splice(bytes, (a, a + 4), &word)
        }
        Mutation::Number { k, text } => match digit_runs(bytes) {
            runs if runs.is_empty() => bytes.to_vec(),
            runs => splice(bytes, runs[k % runs.len()], text.as_bytes()),
        },
        Mutation::Line { k, double } => match lines(bytes) {
            ls if ls.is_empty() => bytes.to_vec(),
            ls => {
                let (a, b) = ls[k % ls.len()];
                let with = if *double {
                    bytes[a..b].repeat(2)
                } else {
                    vec![]
                };
                splice(bytes, (a, b), &with)
            }
        },
        Mutation::Word { .. } => bytes.to_vec(),
    }
}

/// What a reader did with a file: its result (a recording's inconsistency as an
/// error), and the largest allocation it asked for.
struct Read {
    result: Result<Recording, String>,
    largest: usize,
}

/// Reads `path` (by its signature) on a watched thread, failing on a panic or after
/// [`TIME_LIMIT`].
fn read_watched(path: &Path) -> Result<Read, String> {
    let (send, receive) = mpsc::channel();
    let owned = path.to_path_buf();
    let worker = std::thread::spawn(move || {
        let (result, largest) =
            largest_allocation(|| detect::read(&owned, None).map_err(|e| e.to_string()));
        let _ = send.send(Read { result, largest });
    });
    match receive.recv_timeout(TIME_LIMIT) {
        Ok(read) => Ok(read),
        Err(mpsc::RecvTimeoutError::Timeout) => Err(format!("hangs (over {TIME_LIMIT:?})")),
        Err(mpsc::RecvTimeoutError::Disconnected) => Err(match worker.join() {
            Err(panic) => format!("panics: {}", panic_text(&*panic)),
            Ok(()) => "ended without a result".into(),
        }),
    }
}

fn panic_text(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<String>()
        .cloned()
        .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
        .unwrap_or_default()
}

/// What is wrong with a recording a reader returned, if anything: abscissae and
/// samples of different lengths, or a non-finite abscissa.
fn inconsistency(r: &Recording) -> Option<String> {
    for c in &r.channels {
        let n = c.samples.len();
        if let Samples::Complex { re, im } = &c.samples {
            if re.len() != im.len() {
                return Some(format!(
                    "`{}`: {} real, {} imaginary",
                    c.name,
                    re.len(),
                    im.len()
                ));
            }
        }
        match &c.abscissa {
            Abscissa::Values { values, .. } if values.len() != n => {
                return Some(format!(
                    "`{}`: {} abscissae, {n} samples",
                    c.name,
                    values.len()
                ))
            }
            Abscissa::Values { values, .. } if values.iter().any(|v| !v.is_finite()) => {
                return Some(format!("`{}`: a non-finite abscissa", c.name))
            }
            Abscissa::Uniform { start, step, .. } if !(start.is_finite() && step.is_finite()) => {
                return Some(format!("`{}`: abscissa {start} + k·{step}", c.name))
            }
            _ => {}
        }
    }
    None
}

/// Writes the mutated file under the seed's name in `dir` and checks its read.
fn check_read(dir: &Path, seed: &str, bytes: &[u8]) -> Result<(), String> {
    let name = Path::new(seed).file_name().unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let read = read_watched(&path)?;
    if read.largest > ALLOCATION_LIMIT {
        return Err(format!(
            "allocated {} bytes at once for a file of {} bytes",
            read.largest,
            bytes.len()
        ));
    }
    match read.result {
        Ok(recording) => inconsistency(&recording).map_or(Ok(()), Err),
        Err(message) if message.contains(&*name.to_string_lossy()) => Ok(()),
        Err(message) => Err(format!("the error does not name the file: {message}")),
    }
}

fn seed_bytes() -> Vec<Vec<u8>> {
    SEEDS
        .iter()
        .map(|s| std::fs::read(fixture(s)).unwrap())
        .collect()
}

#[test]
fn the_unmutated_files_read_within_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    for (seed, bytes) in SEEDS.iter().zip(seed_bytes()) {
        let name = Path::new(seed).file_name().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        let read = read_watched(&path).unwrap();
        let recording = read.result.unwrap_or_else(|e| panic!("{seed}: {e}"));
        assert!(!recording.channels.is_empty(), "{seed}");
        assert_eq!(inconsistency(&recording), None, "{seed}");
        // The limit holds the real files with room: what would fail is a header's
        // size believed, not a real file's need.
        assert!(
            read.largest * 8 < ALLOCATION_LIMIT,
            "{seed}: {} bytes at once",
            read.largest
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    /// A mutated export reads to a consistent recording or fails naming the file,
    /// within the time and allocation limits.
    #[test]
    fn mutated_exports_read_or_fail_naming_the_file(
        which in 0usize..SEEDS.len(),
        mutations in prop::collection::vec(mutation(), 1..4),
    ) {
        let seeds = seed_bytes_cached();
        let mut bytes = seeds[which].clone();
        for m in &mutations {
            bytes = apply(&bytes, m);
        }
        let dir = tempfile::tempdir().unwrap();
        let checked = check_read(dir.path(), SEEDS[which], &bytes);
        prop_assert!(checked.is_ok(), "{}: {}", SEEDS[which], checked.unwrap_err());
    }
}

fn seed_bytes_cached() -> &'static [Vec<u8>] {
    static SEEDS_READ: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    SEEDS_READ.get_or_init(seed_bytes)
}

/// An import of a seed: the file and the `--kind`, `--map` and `--condition` options
/// (the first two as the docs and tests map them).
struct Import {
    seed: &'static str,
    args: &'static [&'static str],
}

const IMPORTS: [Import; 3] = [
    Import {
        seed: "formats/matlab/DATA_EMPS.mat",
        args: &[
            "--kind",
            "servo-trace",
            "--map",
            "time=t:s",
            "--map",
            "position=qm:m",
            "--map",
            "reference_position=qg:m",
            "--map",
            "controller_output=vir:V",
            "--map",
            "effort=vir*35.15:N",
            "--condition",
            "drive_gain=35.15",
            "--condition",
            "loop_period_s=0.001",
        ],
    },
    Import {
        seed: "frf/worm_frf.uff",
        args: &[
            "--kind",
            "frequency-response",
            "--map",
            "frf=worm table/motor",
            "--mechanism",
            "worm-gear",
        ],
    },
    // A text export, whose mutations mostly still read: the import itself is reached.
    Import {
        seed: "formats/twincat-scope/tc3_scope_3_4_3145_3_noOS.csv",
        args: &[
            "--kind",
            "servo-trace",
            "--map",
            "reference_position=var_REAL64*0.001:rad",
            "--map",
            "position=var_INT32*0.001:rad",
            "--map",
            "effort=func_units_unscaled:N·m",
            "--condition",
            "loop_period_s=0.001",
        ],
    },
];

/// Runs `rtid import FILE ARGS --out out --quiet` in `dir`: exit code and stderr,
/// failing on a hang.
fn import(dir: &Path, file: &Path, args: &[&str]) -> Result<(Option<i32>, String), String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rtid"))
        .arg("import")
        .arg(file)
        .args(args)
        .args(["--out", "out", "--quiet"])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the rtid binary runs");
    let started = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if started.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            return Err(format!("hangs (over {TIME_LIMIT:?})"));
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let out = child.wait_with_output().expect("output");
    Ok((
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

/// The experiment an import wrote reads back with finite data; a failed import said
/// why in one line.
fn check_import(dir: &Path, which: usize, bytes: &[u8]) -> Result<(), String> {
    let spec = &IMPORTS[which];
    let file = dir.join(Path::new(spec.seed).file_name().unwrap());
    std::fs::write(&file, bytes).unwrap();
    let (code, stderr) = import(dir, &file, spec.args)?;
    match code {
        Some(0) => {
            let manifest = std::fs::read_dir(dir.join("out"))
                .map_err(|e| format!("no output folder: {e}"))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .find(|p| p.extension().is_some_and(|x| x == "json"))
                .ok_or("no manifest written")?;
            let e = experiment_file::read(&manifest)
                .map_err(|e| format!("what it wrote does not read back: {e}"))?;
            match support::non_finite(&format!("{:?}", e.data)) {
                true => Err("a non-finite value in what it wrote".into()),
                false => Ok(()),
            }
        }
        Some(1) if stderr.lines().count() == 1 && stderr.starts_with("error: ") => Ok(()),
        other => Err(format!("exit {other:?}: {stderr}")),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// A mutated export imported as the docs map it writes an experiment that reads
    /// back finite, or fails in one line.
    #[test]
    fn mutated_exports_import_finite_or_fail_in_one_line(
        which in 0usize..IMPORTS.len(),
        mutations in prop::collection::vec(mutation(), 1..3),
    ) {
        let seed = std::fs::read(fixture(IMPORTS[which].seed)).unwrap();
        let mut bytes = seed;
        for m in &mutations {
            bytes = apply(&bytes, m);
        }
        let dir = tempfile::tempdir().unwrap();
        let checked = check_import(dir.path(), which, &bytes);
        prop_assert!(checked.is_ok(), "{}: {}", IMPORTS[which].seed, checked.unwrap_err());
    }
}
