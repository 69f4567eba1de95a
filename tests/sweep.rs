//! Sensitivity sweeps: the Sobol estimators against the Ishigami function's analytic
//! indices, the physics of a Kw sweep, and the file contract — an interrupted and
//! resumed sweep, and merged shards, give the bytes of a straight run.

use std::f64::consts::PI;
use std::path::Path;

use rtid::model::presets;
use rtid::sweep::{
    self, designs::Design, sobol, Factor, Method, Output, RunOptions, Scale, Shard, Sweep,
    TestLength,
};

/// Ishigami (1990): y = sin x1 + a·sin² x2 + b·x3⁴·sin x1 on [−π, π]³.
fn ishigami(x: &[f64]) -> f64 {
    let (a, b) = (7.0, 0.1);
    x[0].sin() + a * x[1].sin().powi(2) + b * x[2].powi(4) * x[0].sin()
}

#[test]
fn sobol_indices_of_the_ishigami_function_match_the_analytic_values() {
    // Analytic, a = 7, b = 0.1 (Saltelli et al. 2008, §4.8; Ishigami & Homma 1990).
    let s1_exact = [0.3139, 0.4424, 0.0];
    let st_exact = [0.5576, 0.4424, 0.2437];
    let factors: Vec<Factor> = (1..=3)
        .map(|i| Factor::new(&format!("x{i}"), -PI, PI, Scale::Lin, 2).unwrap())
        .collect();
    let samples = 4096;
    for seed in [0, 1] {
        let method = Method::Sobol {
            samples,
            bootstrap: 100,
        };
        let d = Design::new(&method, &factors, &[], seed).unwrap();
        let y: Vec<f64> = d
            .values
            .rows()
            .into_iter()
            .map(|x| ishigami(&x.to_vec()))
            .collect();
        let s = sobol::indices(&y, 3, samples, 100, 0.95, seed).unwrap();
        for i in 0..3 {
            assert!(
                (s[i].s1 - s1_exact[i]).abs() < 0.02,
                "seed {seed}, S1_{}: {} vs {}",
                i + 1,
                s[i].s1,
                s1_exact[i]
            );
            assert!(
                (s[i].st - st_exact[i]).abs() < 0.02,
                "seed {seed}, ST_{}: {} vs {}",
                i + 1,
                s[i].st,
                st_exact[i]
            );
            assert!(s[i].st_low <= s[i].st && s[i].st <= s[i].st_high);
        }
    }
}

/// A worm-gear table whose spur stage and axial bearing are rigid: with the motor
/// held, θw and xw are held too and the table turns on Kw alone, f = √(Kw/Jt)/2π.
/// Kg = 1e9 N·m/rad (shaft units) against Kw·Rw² ≈ 190 and Kb·r² = 6.4e9 N·m/rad in
/// series with Kw ≤ 1e6 leave ≲ 1e-4 of the frequency to the rest of the drive.
fn rigid_worm() -> rtid::model::Params {
    let mut p = presets::load("worm-gear").unwrap();
    p.set("Kg", 1e9).unwrap();
    p.set("Kb", 1e12).unwrap();
    p
}

#[test]
fn with_a_rigid_spur_stage_and_bearing_the_table_mode_moves_as_the_root_of_kw() {
    let p = rigid_worm();
    let factors = vec![Factor::new("Kw", 1e5, 1e6, Scale::Log, 5).unwrap()];
    let s = Sweep::new(
        p.clone(),
        factors,
        Method::Grid,
        vec![Output::Resonances, Output::Modes],
        TestLength::Short,
        0,
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("kw.csv");
    let r = sweep::run(&s, &out, &RunOptions::default()).unwrap();
    assert!(r.complete && r.failed == 0);
    let (_, rows) = sweep::load_complete(&[out]).unwrap();
    let cols = s.columns();
    let col = |name: &str| cols.iter().position(|c| c == name).unwrap();
    let mut last: Option<(f64, f64)> = None;
    for row in rows.values() {
        let kw: f64 = row[col("Kw_nm_per_rad")].parse().unwrap();
        let mode: f64 = row[col("mode_1_hz")].parse().unwrap();
        let peak: f64 = row[col("resonance_1_hz")].parse().unwrap();
        let want = (kw / p.jt).sqrt() / (2.0 * PI);
        assert!(
            (mode / want - 1.0).abs() < 1e-3,
            "Kw {kw}: mode {mode} vs {want}"
        );
        // The damped peak: ζ = Ciw/(2√(Kw·Jt)) ≤ 3e-4 moves it far less than 0.1 %.
        assert!(
            (peak / want - 1.0).abs() < 1e-3,
            "Kw {kw}: peak {peak} vs {want}"
        );
        if let Some((k0, f0)) = last {
            let slope = (peak / f0).ln() / (kw / k0).ln();
            assert!((slope - 0.5).abs() < 2e-3, "d ln f / d ln Kw = {slope}");
        }
        last = Some((kw, peak));
    }
    // The local method says the same: ∂ln f/∂ln Kw = 0.5, ∂ln f/∂ln Jt = −0.5.
    let s = Sweep::new(
        p,
        vec![
            sweep::spec::parse("Kw", &rigid_worm()).unwrap(),
            sweep::spec::parse("Jt", &rigid_worm()).unwrap(),
        ],
        Method::Local { step: 0.01 },
        vec![Output::Modes],
        TestLength::Short,
        0,
    )
    .unwrap();
    let out = dir.path().join("local.csv");
    sweep::run(&s, &out, &RunOptions::default()).unwrap();
    let (_, rows) = sweep::load_complete(std::slice::from_ref(&out)).unwrap();
    let (indices, file) = sweep::write_indices(&s, &rows, &out).unwrap();
    let get = |output: &str, param: &str| {
        indices
            .rows
            .iter()
            .find(|r| r.output == output && r.parameter == param)
            .and_then(|r| r.values[0])
            .unwrap()
    };
    assert!((get("mode_1_hz", "Kw") - 0.5).abs() < 1e-3);
    assert!((get("mode_1_hz", "Jt") + 0.5).abs() < 1e-3);
    assert!(file.is_some_and(|f| f.exists()));
    let charts = rtid::report::sweep::tornadoes(&indices).unwrap();
    assert!(charts
        .iter()
        .any(|(column, svg)| column == "mode_1_hz" && svg.starts_with("<svg")));
}

/// A small Morris sweep over linear outputs (fast), for the file tests.
fn morris_sweep() -> Sweep {
    let p = presets::load("worm-gear").unwrap();
    let factors = ["Kw=1e5..1e6:log", "Kb=1e7..1e8:log", "Jt=0.08..0.14"]
        .iter()
        .map(|s| sweep::spec::parse(s, &p).unwrap())
        .collect();
    Sweep::new(
        p,
        factors,
        Method::Morris {
            trajectories: 12,
            levels: 4,
        },
        vec![Output::Resonances, Output::PeakGain],
        TestLength::Short,
        42,
    )
    .unwrap()
}

fn straight_run(s: &Sweep, dir: &Path) -> Vec<u8> {
    let out = dir.join("straight.csv");
    let r = sweep::run(s, &out, &RunOptions::default()).unwrap();
    assert!(r.complete && r.computed == r.total && r.total == 12 * 4);
    std::fs::read(out).unwrap()
}

#[test]
fn a_sweep_interrupted_and_resumed_equals_one_run_straight_through() {
    let s = morris_sweep();
    let dir = tempfile::tempdir().unwrap();
    let straight = straight_run(&s, dir.path());
    let out = dir.path().join("resumed.csv");
    let stop_after = |limit, resume| RunOptions {
        resume,
        limit: Some(limit),
        ..RunOptions::default()
    };
    let r = sweep::run(&s, &out, &stop_after(10, false)).unwrap();
    assert!(!r.complete && r.computed == 10);
    // The rows so far are on disk, in the order they finished; kill mid-row too.
    let partial = std::fs::read_to_string(&out).unwrap();
    assert_eq!(partial.lines().filter(|l| !l.starts_with('#')).count(), 11);
    std::fs::write(&out, format!("{partial}47,1234.5")).unwrap();
    // Without --resume an existing file is not overwritten.
    let err = sweep::run(&s, &out, &RunOptions::default()).unwrap_err();
    assert!(err.to_string().contains("--resume"), "{err}");
    let r = sweep::run(&s, &out, &stop_after(15, true)).unwrap();
    assert_eq!((r.resumed, r.computed, r.complete), (10, 15, false));
    let r = sweep::run(&s, &out, &stop_after(usize::MAX, true)).unwrap();
    assert_eq!((r.resumed, r.computed, r.complete), (25, 23, true));
    assert_eq!(
        std::fs::read(&out).unwrap(),
        straight,
        "resumed file differs"
    );
    // Resuming a finished sweep computes nothing and changes nothing.
    let r = sweep::run(&s, &out, &stop_after(usize::MAX, true)).unwrap();
    assert_eq!((r.computed, r.complete), (0, true));
    assert_eq!(std::fs::read(&out).unwrap(), straight);
    // A different sweep refuses to resume this file.
    let mut other = s.clone();
    other.seed = 43;
    let err = sweep::run(&other, &out, &stop_after(1, true)).unwrap_err();
    assert!(err.to_string().contains("different sweep"), "{err}");
}

#[test]
fn the_merge_of_n_shards_equals_the_unsharded_sweep() {
    let s = morris_sweep();
    let dir = tempfile::tempdir().unwrap();
    let straight = straight_run(&s, dir.path());
    let n = 3;
    let mut shards: Vec<_> = (0..n)
        .map(|i| {
            let path = dir.path().join(format!("shard-{i}.csv"));
            let opts = RunOptions {
                shard: Some(Shard { index: i, count: n }),
                ..RunOptions::default()
            };
            let r = sweep::run(&s, &path, &opts).unwrap();
            assert!(r.complete && r.total == 16);
            path
        })
        .collect();
    shards.reverse();
    // A missing shard is named.
    let err = sweep::load_complete(&shards[..2]).unwrap_err().to_string();
    assert!(
        err.contains("missing") && err.contains("missing shard 1/3"),
        "{err}"
    );
    // A shard stopped between rows (a cancelled job) is named with what it lacks.
    let text = std::fs::read_to_string(&shards[1]).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    std::fs::write(&shards[1], lines[..lines.len() - 2].join("\n") + "\n").unwrap();
    let err = sweep::load_complete(&shards).unwrap_err().to_string();
    let named = format!("{} (2 of 16 rows missing)", shards[1].display());
    assert!(err.contains(&named) && err.contains("--resume"), "{err}");
    std::fs::write(&shards[1], &text).unwrap();
    let (merged_sweep, rows) = sweep::load_complete(&shards).unwrap();
    assert_eq!(merged_sweep, s);
    let out = dir.path().join("merged.csv");
    sweep::write_final(&merged_sweep, &rows, &out).unwrap();
    assert_eq!(
        std::fs::read(&out).unwrap(),
        straight,
        "merged file differs"
    );
    let (indices, _) = sweep::write_indices(&s, &rows, &out).unwrap();
    // Morris on the first resonance: Kw and Kb matter (they are in series), all defined.
    assert_eq!(indices.rows.len(), s.output_columns().len() * 3);
}

/// Replaces, in the sweep file `path`, the first data row's cell `column` by `value`.
fn tamper(path: &Path, column: usize, value: &str) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let row = lines.iter().position(|l| l.starts_with("index,")).unwrap() + 1;
    let mut cells: Vec<&str> = lines[row].split(',').collect();
    cells[column] = value;
    lines[row] = cells.join(",");
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
}

#[test]
fn a_resumed_or_merged_file_with_a_nan_or_a_changed_point_is_refused_naming_it() {
    let s = morris_sweep();
    let dir = tempfile::tempdir().unwrap();
    let resume = |path: &Path| {
        let opts = RunOptions {
            resume: true,
            ..RunOptions::default()
        };
        sweep::run(&s, path, &opts).unwrap_err().to_string()
    };
    let partial = |name: &str| {
        let path = dir.path().join(name);
        let opts = RunOptions {
            limit: Some(5),
            ..RunOptions::default()
        };
        sweep::run(&s, &path, &opts).unwrap();
        path
    };
    // An output cell (column 4: the first output after index and three factors).
    let nan = partial("nan.csv");
    tamper(&nan, 4, "NaN");
    let err = resume(&nan);
    assert!(
        err.contains("nan.csv, line 4") && err.contains("`NaN` is not a finite number"),
        "{err}"
    );
    // A factor value that is not the design's.
    let moved = partial("moved.csv");
    tamper(&moved, 1, "123456");
    let err = resume(&moved);
    assert!(
        err.contains("moved.csv") && err.contains("design point"),
        "{err}"
    );
    // The same in a shard to merge.
    let shards: Vec<_> = (0..2)
        .map(|i| {
            let path = dir.path().join(format!("shard-{i}.csv"));
            let opts = RunOptions {
                shard: Some(Shard { index: i, count: 2 }),
                ..RunOptions::default()
            };
            sweep::run(&s, &path, &opts).unwrap();
            path
        })
        .collect();
    tamper(&shards[1], 2, "1e400");
    let err = sweep::load_complete(&shards).unwrap_err().to_string();
    assert!(
        err.contains("shard-1.csv, line 5") && err.contains("`1e400`"),
        "{err}"
    );
    tamper(&shards[1], 2, "5e7");
    let err = sweep::load_complete(&shards).unwrap_err().to_string();
    assert!(
        err.contains("shard-1.csv: row ") && err.contains("design point"),
        "{err}"
    );
    let err = sweep::load_complete(&shards[..1]).unwrap_err().to_string();
    assert!(err.contains("shard-0.csv: missing shard 2/2"), "{err}");
}

/// Runs the real binary in `dir`.
fn rtid(args: &[&str], dir: &Path) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the rtid binary runs")
}

#[test]
fn bad_vary_specifications_give_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let base = [
        "sweep",
        "--preset",
        "worm-gear",
        "--outputs",
        "modes",
        "--out",
        "x.csv",
    ];
    for (spec, needles) in [
        ("Kx=1..2", &["unknown parameter `Kx`", "Kw", "theta_bw"][..]),
        ("Kw=2e5..1e5", &["Kw=2e5..1e5", "empty"]),
        ("Kw=1e5..1e5:log", &["empty"]),
        ("Kw=-1e5..1e6:log", &["Kw=-1e5..1e6:log", "positive bounds"]),
        ("theta_bw=0..2e-4:log", &["positive bounds"]),
        ("Kw=1e5..1e6:1", &["1 levels"]),
        ("Kw=abc", &["expected NAME=LOW..HIGH"]),
    ] {
        let mut args = base.to_vec();
        args.extend(["--vary", spec]);
        let out = rtid(&args, dir.path());
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(out.status.code(), Some(1), "{spec}: {err}");
        assert_eq!(err.lines().count(), 1, "{spec}: {err}");
        assert!(
            err.starts_with("error: ") && !err.contains("panicked"),
            "{err}"
        );
        for n in needles {
            assert!(err.contains(n), "{spec}: `{n}` not in {err}");
        }
        assert!(!dir.path().join("x.csv").exists(), "no file for a bad spec");
    }
    // A grid needs a range; a local sweep of a parameter that is 0 has no log slope.
    let out = rtid(&[&base[..], &["--vary", "Kw"]].concat(), dir.path());
    assert!(String::from_utf8(out.stderr)
        .unwrap()
        .contains("needs a range"));
    let out = rtid(
        &[
            &base[..],
            &["--method", "local", "--vary", "W", "--set", "W=0"],
        ]
        .concat(),
        dir.path(),
    );
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("W is 0 at the base point"), "{err}");
}

#[test]
fn the_command_line_shards_merges_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let common = [
        "sweep",
        "--preset",
        "worm-gear",
        "--method",
        "sobol",
        "--samples",
        "64",
        "--vary",
        "Kw=1e5..1e6:log",
        "--vary",
        "Jt=0.08..0.14",
        "--outputs",
        "modes,peak_gain",
        "--quiet",
    ];
    let ok = |args: &[&str]| {
        let out = rtid(args, dir.path());
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    ok(&[&common[..], &["--out", "all.csv"]].concat());
    for i in 0..2 {
        let shard = format!("{}/2", i + 1);
        let file = format!("part{i}.csv");
        ok(&[&common[..], &["--shard", &shard, "--out", &file]].concat());
    }
    let json = ok(&[
        "sweep",
        "merge",
        "part1.csv",
        "part0.csv",
        "--out",
        "merged.csv",
        "--json",
    ]);
    let read = |f: &str| std::fs::read(dir.path().join(f)).unwrap();
    assert_eq!(read("merged.csv"), read("all.csv"));
    assert_eq!(read("merged-indices.csv"), read("all-indices.csv"));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["method"], "sobol");
    // mode_1 (the table on Kw) depends on Kw and Jt only: the two ST add up to ≈ 1.
    let st: f64 = v["indices"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["output"] == "mode_1_hz")
        .map(|r| r["values"][3].as_f64().unwrap())
        .sum();
    assert!((0.9..1.2).contains(&st), "ΣST = {st}");
    assert!(dir.path().join("all-mode_1_hz.svg").exists());
    // An existing file is kept unless --resume or --overwrite.
    let out = rtid(&[&common[..], &["--out", "all.csv"]].concat(), dir.path());
    assert!(String::from_utf8(out.stderr).unwrap().contains("--resume"));
}

#[test]
fn a_sweep_of_the_positioning_test_in_lanes_gives_each_point_its_lone_outputs() {
    // Points of two shapes (with and without the drive mesh's gap) and three
    // stiffnesses: batched in lanes by shape and step, each row must be the point's
    // own evaluation.
    let p = presets::load("worm-gear").unwrap();
    let factors = vec![
        Factor::new("Kw", 0.8 * p.kw, 1.2 * p.kw, Scale::Lin, 3).unwrap(),
        Factor::new("theta_bw", 0.0, p.theta_bw, Scale::Lin, 2).unwrap(),
    ];
    let outputs = vec![Output::Reversal, Output::Repeatability];
    let s = Sweep::new(
        p.clone(),
        factors,
        Method::Grid,
        outputs.clone(),
        TestLength::Short,
        0,
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("grid.csv");
    let r = sweep::run(&s, &out, &RunOptions::default()).unwrap();
    assert_eq!((r.total, r.failed), (6, 0));
    let evaluator = sweep::Evaluator {
        outputs,
        tests: TestLength::Short,
        topology: p.topology,
    };
    let text = std::fs::read_to_string(&out).unwrap();
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .collect();
    assert_eq!(rows.len(), 6);
    for row in rows {
        let fields: Vec<&str> = row.split(',').collect();
        let mut q = p.clone();
        q.set("Kw", fields[1].parse().unwrap()).unwrap();
        q.set("theta_bw", fields[2].parse().unwrap()).unwrap();
        let alone: Vec<String> = evaluator
            .evaluate(&q)
            .unwrap()
            .iter()
            .map(|v| v.unwrap().to_string())
            .collect();
        assert_eq!(fields[3..5], alone[..], "row {row}");
    }
}

#[test]
fn the_fluctuation_and_torque_outputs_in_lanes_equal_each_point_alone() {
    // Three points (friction and stiffness 10 % apart): the short fluctuation and
    // torque-curve tests of all three run in lanes, each point's outputs its own.
    let p = presets::load("worm-gear").unwrap();
    let points: Vec<rtid::model::Params> = [0.9, 1.0, 1.1]
        .iter()
        .map(|f| {
            let mut q = p.clone();
            q.fm *= f;
            q.kw *= f;
            q
        })
        .collect();
    let evaluator = sweep::Evaluator {
        outputs: vec![Output::FluctuationPp, Output::TorqueRms],
        tests: TestLength::Short,
        topology: p.topology,
    };
    let batch = evaluator.evaluate_batch(&points);
    for (l, (q, got)) in points.iter().zip(&batch).enumerate() {
        let alone = evaluator.evaluate(q).unwrap();
        assert_eq!(got.as_ref().unwrap(), &alone, "point {l}");
    }
    assert_ne!(batch[0].as_ref().unwrap(), batch[2].as_ref().unwrap());
}
