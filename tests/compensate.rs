//! `rtid compensate` and `rtid evaluate --compensation` on the worm-gear positioning
//! record of fixtures/compensate/worm-gear, against the values its numpy script
//! computed independently (expected.json; docs/compensation.md).

use std::path::{Path, PathBuf};

use crate::cli_support::{err, ok, root, rtid};
use rtid::experiments::positioning::iso230::{self, ARCSEC_PER_RAD};
use rtid::experiments::positioning::{self, compensate};
use rtid::io::compensation_file;

fn fixture() -> PathBuf {
    root().join("fixtures/compensate/worm-gear")
}

fn expected() -> serde_json::Value {
    let text = std::fs::read_to_string(fixture().join("expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Agreement of two computations of the same mean (different summation order).
fn same(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() < 1e-6,
        "{what}: rtid {got}, numpy {want}"
    );
}

fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_str(&ok(out)).unwrap()
}

/// Runs `compensate --runs 1-3` with every output into `dir`; its JSON.
fn compensate_into(dir: &Path) -> serde_json::Value {
    let record = fixture().join("positioning.json");
    let out = rtid(
        &[
            "compensate",
            record.to_str().unwrap(),
            "--runs",
            "1-3",
            "-o",
            "compensation.json",
            "--sinumerik",
            "AX4_EEC.SPF",
            "--axis-number",
            "4",
            "--csv",
            "table.csv",
            "--json",
        ],
        dir,
    );
    json(&out)
}

#[test]
fn the_worm_gear_compensation_agrees_with_numpy_and_cancels_the_build_runs() {
    let dir = tempfile::tempdir().unwrap();
    let got = compensate_into(dir.path());
    let want = expected();
    same(
        got["backlash"].as_f64().unwrap(),
        want["backlash_arcsec"].as_f64().unwrap(),
        "B̄",
    );
    let tables = numbers(&want["table_arcsec"]);
    let rows = got["targets"].as_array().unwrap();
    assert_eq!(rows.len(), tables.len());
    for (row, t) in rows.iter().zip(&tables) {
        same(row["table"].as_f64().unwrap(), *t, "table value");
    }
    for (key, at) in [("build", "E_build"), ("check", "E_check")] {
        let e = |when: &str| got[key][when]["E"].as_f64().unwrap();
        same(
            e("before"),
            want[format!("{at}_before_arcsec")].as_f64().unwrap(),
            at,
        );
        same(
            e("after"),
            want[format!("{at}_after_arcsec")].as_f64().unwrap(),
            at,
        );
    }
    assert_eq!(
        got["warnings"],
        serde_json::json!([]),
        "a steady axis: no warning"
    );
    cancels_the_build_runs(&dir.path().join("compensation.json"));
}

/// The file's table and backlash cancel runs 1–3's mean deviations: upwards exactly
/// (at 0° and 360°, which share one table value, up to half their difference),
/// downwards up to the scatter of the reversal about B̄.
fn cancels_the_build_runs(file: &Path) {
    let exp = rtid::io::experiment_file::read(&fixture().join("positioning.json")).unwrap();
    let all = positioning::from_data(&exp.data).unwrap();
    let build = compensate::select(&all, Some(&"1-3".parse().unwrap()));
    let before = iso230::evaluate(&build).unwrap();
    let comp = compensation_file::read(file).unwrap();
    let b_mean = comp.compensation.backlash.unwrap();
    same(
        b_mean * ARCSEC_PER_RAD,
        before.axis.b_mean * ARCSEC_PER_RAD,
        "backlash = B̄",
    );
    let after = iso230::evaluate(&compensate::apply(&build, &comp.compensation)).unwrap();
    let (first, last) = (
        &before.targets[0],
        &before.targets[before.targets.len() - 1],
    );
    let ends = 0.5 * (first.mean_up - last.mean_up).abs();
    let scatter = before
        .targets
        .iter()
        .map(|t| (t.reversal - b_mean).abs())
        .fold(0.0, f64::max);
    for (t, b) in after.targets.iter().zip(&before.targets) {
        let deg = t.target.to_degrees();
        let end = deg.abs() < 1e-6 || (deg - 360.0).abs() < 1e-6;
        let up_bound = if end { ends } else { 0.0 } + 1e-12;
        assert!(
            t.mean_up.abs() <= up_bound,
            "{deg}°: x̄↑ after {}″",
            t.mean_up * ARCSEC_PER_RAD
        );
        // Downwards: x̄↓ + table + B̄ = x̄↑ + table − (Bi − B̄).
        let down_bound = (b.reversal - b_mean).abs() + up_bound;
        assert!(
            t.mean_down.abs() <= down_bound && down_bound <= scatter + up_bound,
            "{deg}°: x̄↓ after {}″",
            t.mean_down * ARCSEC_PER_RAD
        );
    }
}

#[test]
fn evaluate_with_the_compensation_halves_e_on_the_runs_it_was_not_built_from() {
    let dir = tempfile::tempdir().unwrap();
    compensate_into(dir.path());
    let record = fixture().join("positioning.json");
    let out = rtid(
        &[
            "evaluate",
            record.to_str().unwrap(),
            "--runs",
            "4-5",
            "--compensation",
            "compensation.json",
            "--json",
        ],
        dir.path(),
    );
    let got = json(&out);
    assert_eq!(got["runs"], serde_json::json!([4, 5]));
    let (before, after) = (
        got["uncompensated"]["E"].as_f64().unwrap(),
        got["compensated"]["E"].as_f64().unwrap(),
    );
    assert!(after <= 0.5 * before, "E {before}″ → {after}″");
    let want = expected();
    same(
        before,
        want["E_check_before_arcsec"].as_f64().unwrap(),
        "E check before",
    );
    same(
        after,
        want["E_check_after_arcsec"].as_f64().unwrap(),
        "E check after",
    );
    let table = rtid(
        &[
            "evaluate",
            record.to_str().unwrap(),
            "--runs",
            "4-5",
            "--compensation",
            "compensation.json",
        ],
        dir.path(),
    );
    let text = ok(&table);
    assert!(
        text.contains("runs 4-5") && text.contains("compensated"),
        "{text}"
    );
}

/// The `name[…]=value` assignments of a SINUMERIK program: index and value.
fn assigned(lines: &[&str], name: &str) -> Vec<(String, f64)> {
    lines
        .iter()
        .filter_map(|l| l.strip_prefix(name))
        .map(|rest| {
            let (index, value) = rest.split_once("]=").unwrap();
            (index.to_string(), value.trim().parse::<f64>().unwrap())
        })
        .collect()
}

/// The SINUMERIK program parsed back holds the table's values with SINUMERIK's sign
/// (the axis's error, −table) to its printed precision, every 30° modulo 360°, less
/// their value at the reference point (by default the first, 0°), which its comment
/// and the command's JSON state.
#[test]
fn the_sinumerik_program_holds_the_table_modulo_360() {
    let dir = tempfile::tempdir().unwrap();
    let got = compensate_into(dir.path());
    let text = std::fs::read_to_string(dir.path().join("AX4_EEC.SPF")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "%_N_AX_EEC_INI");
    assert_eq!(lines[lines.len() - 1], "M17");
    // SINUMERIK's backlash is positive when the encoder leads the table (the table
    // stops short: B̄ < 0): −B̄ = +0.009710° here.
    let md = lines
        .iter()
        .find_map(|l| l.split("MD32450 $MA_BACKLASH[0,AX4] = ").nth(1))
        .unwrap();
    let value: f64 = md.split_whitespace().next().unwrap().parse().unwrap();
    let b_mean = expected()["backlash_arcsec"].as_f64().unwrap() / 3600.0;
    assert!(
        b_mean < 0.0 && (value + b_mean).abs() < 1e-9,
        "{value} against B̄ {b_mean}°"
    );
    let values = assigned(&lines, "$AA_ENC_COMP[0,");
    let want = numbers(&expected()["sinumerik_deg"]);
    assert_eq!(values.len(), want.len());
    assert_eq!(values[0].1, 0.0, "zero at the reference point 0°");
    for (i, ((index, v), w)) in values.iter().zip(&want).enumerate() {
        assert_eq!(index, &format!("{i},AX4"));
        let w = w - want[0];
        assert!((v - w).abs() <= 1e-9 + 1e-15, "point {i}: {v} vs {w}");
    }
    assert_eq!(
        values[0].1,
        values[values.len() - 1].1,
        "0° and 360° one value"
    );
    // The shift is the table's value at 0° (−x̄↑ there): in the program's comment in
    // degrees and in the JSON in arc-seconds.
    let shift = -want[0];
    let stated = format!("each value is -(table - {shift:.9}), rtid's table less its value there");
    assert!(text.contains(&stated), "{stated}:\n{text}");
    assert!(
        text.contains("; zero at the reference point 0.000000 deg"),
        "{text}"
    );
    assert!(
        text.contains("MD32700 $MA_ENC_COMP_ENABLE[0,AX4] = 0")
            && text.contains("then set MD32700 $MA_ENC_COMP_ENABLE[0,AX4] = 1"),
        "{text}"
    );
    assert_eq!(got["sinumerik"]["reference_deg"], 0.0, "{got}");
    same(
        got["sinumerik"]["shift"].as_f64().unwrap(),
        shift * 3600.0,
        "the shift",
    );
    let one = |name: &str| assigned(&lines, name)[0].1;
    assert_eq!(one("$AA_ENC_COMP_STEP[0,"), 30.0);
    assert_eq!(one("$AA_ENC_COMP_MIN[0,"), 0.0);
    assert_eq!(one("$AA_ENC_COMP_MAX[0,"), 360.0);
    assert_eq!(one("$AA_ENC_COMP_IS_MODULO[0,"), 1.0);
    let csv = std::fs::read_to_string(dir.path().join("table.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows[0], "position_deg,value_arcsec");
    assert_eq!(rows.len(), 14, "{csv}");
}

/// `--reference-deg 90`: the program is zero at 90° (its fourth point), every value
/// shifted by the table's value there, which the output states; a reference outside
/// the table, or in the other axis's unit, is refused naming the option.
#[test]
fn the_sinumerik_program_is_zero_at_the_reference_given() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let record = fixture().join("positioning.json");
    let record = record.to_str().unwrap();
    let args = [
        "compensate",
        record,
        "--runs",
        "1-3",
        "--sinumerik",
        "AX4_EEC.SPF",
        "--axis-number",
        "4",
        "--reference-deg",
        "90",
    ];
    let got = json(&rtid(&[&args[..], &["--json"]].concat(), d));
    let text = std::fs::read_to_string(d.join("AX4_EEC.SPF")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let values = assigned(&lines, "$AA_ENC_COMP[0,");
    assert_eq!(values[3], ("3,AX4".to_string(), 0.0), "{text}");
    let want = numbers(&expected()["sinumerik_deg"]);
    for (i, ((_, v), w)) in values.iter().zip(&want).enumerate() {
        assert!((v - (w - want[3])).abs() <= 1e-9 + 1e-15, "point {i}: {v}");
    }
    let table_at_90 = got["targets"][3]["table"].as_f64().unwrap();
    assert_eq!(got["sinumerik"]["reference_deg"], 90.0);
    same(
        got["sinumerik"]["shift"].as_f64().unwrap(),
        table_at_90,
        "the shift",
    );
    assert!(
        text.contains("; zero at the reference point 90.000000 deg"),
        "{text}"
    );
    let printed = ok(&rtid(&args, d));
    let line = format!(
        "SINUMERIK program: zero at the reference point 90.00°, rtid's table less its value there, {table_at_90:.2}″"
    );
    assert!(printed.contains(&line), "{line}:\n{printed}");
    let refused = |extra: [&str; 2], expect: &str| {
        let args = [&args[..8], &extra[..]].concat();
        let e = err(&rtid(&args, d));
        assert!(e.contains(expect), "{extra:?}: {e}");
    };
    refused(
        ["--reference-deg", "400"],
        "--reference-deg 400: outside the SINUMERIK table, which runs from 0.000 to 360.000 deg",
    );
    refused(["--reference-deg", "-1"], "--reference-deg -1: outside");
    refused(
        ["--reference-mm", "5"],
        "--reference-mm is for a linear axis",
    );
}

/// The fixture's record in `dir`, each reading (arc-seconds) changed by
/// `change(target_deg, run, reading)`.
fn changed_record(dir: &Path, change: impl Fn(f64, f64, f64) -> f64) {
    let csv = std::fs::read_to_string(fixture().join("positioning.csv")).unwrap();
    let mut changed = String::new();
    for line in csv.lines() {
        let cells: Vec<&str> = line.split(',').collect();
        match (
            cells.len(),
            cells.first().and_then(|c| c.parse::<f64>().ok()),
        ) {
            (4, Some(target)) => {
                let run: f64 = cells[2].parse().unwrap();
                let x = change(target, run, cells[3].parse().unwrap());
                changed.push_str(&format!("{},{},{},{x}\n", cells[0], cells[1], cells[2]));
            }
            _ => changed.push_str(&format!("{line}\n")),
        }
    }
    std::fs::write(dir.join("positioning.csv"), changed).unwrap();
    std::fs::copy(
        fixture().join("positioning.json"),
        dir.join("positioning.json"),
    )
    .unwrap();
}

/// The record with a warm-up drift added: runs shifted progressively, more at larger
/// angles (3″ per run across the turn). The table of runs 1–3 does not repeat on runs
/// 4–5, and the output says so.
#[test]
fn a_drifting_axis_gets_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    changed_record(dir.path(), |target, run, x| {
        x + (run - 3.0) * 3.0 * target / 360.0
    });
    let out = rtid(
        &["compensate", "positioning.json", "--runs", "1-3"],
        dir.path(),
    );
    let text = ok(&out);
    assert!(
        text.contains("warning: the error table does not help"),
        "{text}"
    );
    let got = json(&rtid(
        &["compensate", "positioning.json", "--runs", "1-3", "--json"],
        dir.path(),
    ));
    assert_eq!(got["warnings"][0]["code"], "table_does_not_help", "{got}");
    // Built from every run, it is not checked, and says that instead.
    let text = ok(&rtid(&["compensate", "positioning.json"], dir.path()));
    assert!(text.contains("warning: built from every run"), "{text}");
}

/// Runs 4–5 without their reversal at 90° (both directions read −17.28″ ± 2″): the
/// backlash of runs 1–3 leaves 35″ of reversal there, R of runs 4–5 grows, and the
/// table and the JSON say by how much.
#[test]
fn a_repeatability_made_worse_gets_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    changed_record(dir.path(), |target, run, x| {
        match (target.round() as i32, run as i32) {
            (90, 4) => -15.28,
            (90, 5) => -19.28,
            _ => x,
        }
    });
    let args = ["compensate", "positioning.json", "--runs", "1-3"];
    let text = ok(&rtid(&args, dir.path()));
    assert!(
        text.contains("warning: the compensation makes the repeatability R of the runs it was not built from worse by"),
        "{text}"
    );
    let got = json(&rtid(&[&args[..], &["--json"]].concat(), dir.path()));
    let warning = got["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|w| w["code"] == "repeatability_worse")
        .unwrap_or_else(|| panic!("{got}"));
    let (before, after) = (
        got["check"]["before"]["R"].as_f64().unwrap(),
        got["check"]["after"]["R"].as_f64().unwrap(),
    );
    assert!(after > before, "{got}");
    let message = warning["message"].as_str().unwrap();
    let by = format!("worse by {:.2}″: {before:.2}″ without it", after - before);
    assert!(message.contains(&by), "{by}: {message}");
}

#[test]
fn bad_input_is_refused_with_one_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for name in ["positioning.json", "positioning.csv"] {
        std::fs::copy(fixture().join(name), d.join(name)).unwrap();
    }
    let bad = |args: &[&str], expect: &str| {
        let e = err(&rtid(args, d));
        assert!(e.contains(expect), "{args:?}: {e}");
    };
    bad(
        &["compensate", "positioning.json", "-o", "positioning.csv"],
        "that is an input",
    );
    bad(
        &[
            "compensate",
            "positioning.json",
            "-o",
            "a.json",
            "--csv",
            "a.json",
        ],
        "that is an input",
    );
    bad(
        &["compensate", "positioning.json", "--sinumerik", "x.spf"],
        "--axis-number",
    );
    bad(
        &["compensate", "positioning.json", "--runs", "3-1"],
        "the first run is after the last",
    );
    bad(
        &["compensate", "positioning.json", "--runs", "7-9"],
        "no measurement of runs 7-9",
    );
    bad(
        &["compensate", "positioning.json", "--runs", "3"],
        "needs at least 2",
    );
    fn evaluate(file: &str) -> [&str; 4] {
        ["evaluate", "positioning.json", "--compensation", file]
    }
    std::fs::write(
        d.join("linear.json"),
        r#"{"axis": "linear", "unit": "mm", "backlash": {"value": 0.001}}"#,
    )
    .unwrap();
    bad(&evaluate("linear.json"), "linear.json: a compensation of a linear axis cannot be applied to a record of a rotary axis");
    std::fs::write(
        d.join("steps.json"),
        r#"{"axis": "rotary", "unit": "deg", "table": {"positions": [0, 90, 45], "values": [0, 0, 0]}}"#,
    )
    .unwrap();
    bad(
        &evaluate("steps.json"),
        "steps.json: field `table`: table position 2 (45) is not finite or does not increase",
    );
    std::fs::write(
        d.join("units.json"),
        r#"{"axis": "rotary", "unit": "arcsec", "backlash": {"value": 30}}"#,
    )
    .unwrap();
    bad(
        &evaluate("units.json"),
        "units.json: field `unit`: `arcsec`",
    );
    bad(&evaluate("positioning.json"), "unknown field");
    let nothing = ok(&rtid(&["compensate", "positioning.json"], d));
    assert!(nothing.contains("B̄"), "{nothing}");
    let files: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        files.len(),
        5,
        "nothing written without being asked: {files:?}"
    );
}

/// The compensation run in the model's controller (`experiment positioning
/// --compensation`): the worm-gear preset's own virtual test, compensated by the
/// backlash and table built from its record, shows the reversal gone (|B̄| < 2″) and
/// A at least halved (measured: 38.4″ → 4.5″ with 2 runs, the repeatability of so
/// few runs dominating) — the effect predicted by simulation, not by shifting
/// readings.
#[test]
fn the_compensation_run_in_the_models_controller_cancels_the_reversal() {
    let dir = tempfile::tempdir().unwrap();
    compensate_into(dir.path());
    let args = [
        "experiment",
        "positioning",
        "--preset",
        "worm-gear",
        "--runs",
        "2",
        "--dwell-s",
        "0.5",
        "--compensation",
        "compensation.json",
        "--out",
        "sim",
    ];
    ok(&rtid(&args, dir.path()));
    let manifest = std::fs::read_to_string(dir.path().join("sim/positioning.json")).unwrap();
    assert!(manifest.contains("compensation"), "{manifest}");
    let got = json(&rtid(
        &["evaluate", "sim/positioning.json", "--json"],
        dir.path(),
    ));
    let (b_mean, a) = (
        got["axis"]["B_mean"].as_f64().unwrap(),
        got["axis"]["A"].as_f64().unwrap(),
    );
    let record = fixture().join("positioning.json");
    let uncompensated = json(&rtid(
        &["evaluate", record.to_str().unwrap(), "--json"],
        dir.path(),
    ));
    let a_before = uncompensated["axis"]["A"].as_f64().unwrap();
    assert!(b_mean.abs() < 2.0, "B̄ {b_mean}″");
    assert!(a < 0.5 * a_before, "A {a_before}″ → {a}″");
    // A compensation of a linear axis is refused for a rotary table, naming the file.
    let linear = r#"{"axis": "linear", "unit": "mm", "backlash": {"value": 0.01}}"#;
    std::fs::write(dir.path().join("linear.json"), linear).unwrap();
    let mut wrong = args;
    wrong[9] = "linear.json";
    let e = err(&rtid(&wrong, dir.path()));
    assert!(e.contains("linear.json"), "{e}");
}

/// `--friction-map`: the worm-gear table's own virtual map gives the friction
/// compensation its Coulomb law at the motor, written in the file in SI with its
/// units and read back by the controller's run; a record passed as a map is refused.
#[test]
fn a_friction_map_adds_the_law_it_determines() {
    let dir = tempfile::tempdir().unwrap();
    let map = [
        "experiment",
        "friction-map",
        "--preset",
        "worm-gear",
        "--out",
        "map",
    ];
    ok(&rtid(&map, dir.path()));
    let record = fixture().join("positioning.json");
    let args = [
        "compensate",
        record.to_str().unwrap(),
        "--friction-map",
        "map/friction_map.json",
        "-o",
        "c.json",
        "--json",
    ];
    let got = json(&rtid(&args, dir.path()));
    let friction = &got["friction"];
    // The preset's friction lumped at the motor — every body's Coulomb level and
    // damping through the ratios, the model's steady effort's odd part L·sgn(ω) + S·ω
    // — as the map's Coulomb fit finds it, with no rise.
    let (coulomb, viscous) = (
        friction["coulomb"].as_f64().unwrap(),
        friction["viscous"].as_f64().unwrap(),
    );
    let p = rtid::model::presets::load("worm-gear").unwrap();
    let d = rtid::model::Drive::new(&p).unwrap();
    let effort = rtid::experiments::friction_map::model_effort;
    let odd = |w: f64| 0.5 * (effort(&d, w) - effort(&d, -w));
    let slope = odd(2.0) - odd(1.0);
    let level = odd(1.0) - slope;
    assert!((coulomb / level - 1.0).abs() < 0.01, "{coulomb} vs {level}");
    assert!((viscous / slope - 1.0).abs() < 0.01, "{viscous} vs {slope}");
    assert!(friction["stribeck"].is_null(), "{friction}");
    let file = compensation_file::read(&dir.path().join("c.json")).unwrap();
    let law = file.compensation.friction.unwrap().law;
    assert_eq!((law.coulomb, law.viscous), (coulomb, viscous));
    let mut wrong = args;
    wrong[3] = record.to_str().unwrap();
    wrong[5] = "d.json";
    let e = err(&rtid(&wrong, dir.path()));
    assert!(e.contains("not a friction map"), "{e}");
}
