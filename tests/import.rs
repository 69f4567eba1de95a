//! `rtid import` on the real files labs export (fixtures/formats/, each with its
//! provenance README): what `--list` shows, the experiment files written, and that an
//! identification from an imported record is the one from the shipped conversion.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use rtid::io::experiment_file::{self, Data};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn rtid(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the rtid binary runs")
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "rtid failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

fn err(out: &Output) -> String {
    assert!(!out.status.success(), "rtid succeeded where it should not");
    String::from_utf8(out.stderr.clone()).unwrap()
}

const EMPS_GAIN: &str = "35.15065188248547";

/// The EMPS MAT-file mapped as fixtures/real/emps/README.md converted it by hand.
fn import_emps(dir: &Path) -> PathBuf {
    let mat = root().join("fixtures/formats/matlab/DATA_EMPS.mat");
    let effort = format!("effort=vir*{EMPS_GAIN}:N");
    let gain = format!("drive_gain={EMPS_GAIN}");
    ok(&rtid(
        &[
            "import",
            mat.to_str().unwrap(),
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
            &effort,
            "--condition",
            &gain,
            "--condition",
            "loop_period_s=0.001",
            "--out",
            "emps",
        ],
        dir,
    ));
    dir.join("emps/servo_trace.json")
}

#[test]
fn the_emps_mat_file_imports_to_the_shipped_record_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let imported = experiment_file::read(&import_emps(dir.path())).unwrap();
    let shipped =
        experiment_file::read(&root().join("fixtures/real/emps/emps_estimation.json")).unwrap();
    let (Data::ServoTrace(a), Data::ServoTrace(b)) = (&imported.data, &shipped.data) else {
        panic!("both are servo traces");
    };
    assert_eq!(a.axis, b.axis);
    assert_eq!(a.time_s, b.time_s);
    assert_eq!(a.position, b.position);
    assert_eq!(a.reference_position, b.reference_position);
    assert_eq!(a.effort, b.effort);
    assert_eq!(a.controller_output, b.controller_output);
    assert_eq!(
        imported.manifest.conditions.drive_gain,
        shipped.manifest.conditions.drive_gain
    );
    let import = &imported.manifest.extra["import"];
    assert_eq!(import["sources"][0]["format"], "matlab-v5");
    assert_eq!(import["sources"][0]["sha256"].as_str().unwrap().len(), 64);
    assert_eq!(import["map"].as_array().unwrap().len(), 5);
}

#[test]
#[cfg_attr(
    not(feature = "slow-tests"),
    ignore = "slow tier (two EMPS identifications, ~30 s): --features slow-tests"
)]
fn an_identification_from_the_imported_emps_record_is_the_shipped_ones() {
    let dir = tempfile::tempdir().unwrap();
    let imported = import_emps(dir.path());
    let axis = root().join("fixtures/real/emps/axis.json");
    let shipped = root().join("fixtures/real/emps/emps_estimation.json");
    let fit = |manifest: &Path, out: &str| -> serde_json::Value {
        ok(&rtid(
            &[
                "identify",
                manifest.to_str().unwrap(),
                "--params",
                axis.to_str().unwrap(),
                "--quiet",
                "--out",
                out,
            ],
            dir.path(),
        ));
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(out)).unwrap()).unwrap()
    };
    let a = fit(&imported, "a.json");
    let b = fit(&shipped, "b.json");
    let pa = a["parameters"].as_object().unwrap();
    let pb = b["parameters"].as_object().unwrap();
    assert_eq!(pa.keys().collect::<Vec<_>>(), pb.keys().collect::<Vec<_>>());
    for (name, va) in pa {
        let (va, vb) = (va.as_f64().unwrap(), pb[name].as_f64().unwrap());
        assert!(
            ((va - vb) / vb).abs() <= 1e-9,
            "{name}: {va} from the MAT-file, {vb} from the CSV"
        );
    }
}

#[test]
fn list_names_every_channel_with_its_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let mat = root().join("fixtures/formats/matlab/DATA_EMPS.mat");
    let out = ok(&rtid(
        &["import", mat.to_str().unwrap(), "--list", "--json"],
        dir.path(),
    ));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["format"], "matlab-v5");
    let channels = v["channels"].as_array().unwrap();
    let qm = channels
        .iter()
        .find(|c| c["name"] == "qm")
        .expect("qm listed");
    assert_eq!(qm["samples"], 24841);
    for key in ["first", "last", "mean"] {
        assert!(qm[key].as_f64().unwrap().is_finite(), "{key}");
    }
}

#[test]
fn a_mapping_that_cannot_be_made_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let mat = root().join("fixtures/formats/matlab/DATA_EMPS.mat");
    let mat = mat.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["import", mat, "--kind", "servo-trace", "--out", "o"];
        args.extend_from_slice(extra);
        err(&rtid(&args, dir.path()))
    };
    // A channel the file lacks lists the ones it has.
    let e = run(&["--map", "time=time:s"]);
    assert!(e.contains("no channel `time`") && e.contains("`qm`"), "{e}");
    // A role the kind lacks lists its roles.
    let e = run(&["--map", "speed=qm:m"]);
    assert!(
        e.contains("not a role of servo-trace") && e.contains("reference_position"),
        "{e}"
    );
    // A MAT-file's arrays carry no unit: the map must give one.
    let e = run(&["--map", "time=t"]);
    assert!(e.contains("no unit") && e.contains("time=t:UNIT"), "{e}");
    // A unit of the wrong quantity.
    let e = run(&["--map", "time=t:m"]);
    assert!(e.contains("a length") && e.contains("a time"), "{e}");
    // Required roles missing.
    let e = run(&["--map", "time=t:s"]);
    assert!(
        e.contains("needs --map for reference_position, position, effort"),
        "{e}"
    );
    // Nothing is written.
    assert!(!dir.path().join("o").exists());
}

#[test]
fn a_laser_table_becomes_a_linear_positioning_test() {
    let dir = tempfile::tempdir().unwrap();
    let mut table = String::from("# interferometer export\nTarget;Dir;Cycle;Error\nmm;-;-;um\n");
    for run in 1..=5 {
        for (d, sign) in [(1, 1.0), (-1, -1.0)] {
            for k in 0..5 {
                let target = 100.0 * k as f64;
                let error = 2.0 * sign + 0.1 * run as f64 + 0.01 * k as f64;
                table += &format!(
                    "{target};{d};{run};{}\n",
                    error.to_string().replace('.', ",")
                );
            }
        }
    }
    std::fs::write(dir.path().join("laser.csv"), table).unwrap();
    ok(&rtid(
        &[
            "import",
            "laser.csv",
            "--kind",
            "positioning",
            "--map",
            "target=Target",
            "--map",
            "deviation=Error",
            "--map",
            "direction=Dir",
            "--map",
            "run=Cycle",
            "--out",
            "iso",
        ],
        dir.path(),
    ));
    let e = experiment_file::read(&dir.path().join("iso/positioning.json")).unwrap();
    let Data::LinearPositioning {
        target_m,
        deviation_m,
        run,
        ..
    } = &e.data
    else {
        panic!("a linear positioning test: {:?}", e.data.kind());
    };
    assert_eq!(target_m.len(), 50);
    assert!((target_m[4] - 0.4).abs() < 1e-15);
    assert!((deviation_m[0] - 2.1e-6).abs() < 1e-15);
    assert_eq!(run[49], 5);
    // And the ISO 230-2 evaluation takes it.
    ok(&rtid(
        &["evaluate", "iso/positioning.json", "--json"],
        dir.path(),
    ));
    // A run 0 is refused, naming its row.
    std::fs::write(dir.path().join("bad.csv"), "t,d,r,e\n0,1,0,1\n").unwrap();
    let e = err(&rtid(
        &[
            "import",
            "bad.csv",
            "--kind",
            "positioning",
            "--map",
            "target=t:mm",
            "--map",
            "deviation=e:um",
            "--map",
            "direction=d",
            "--map",
            "run=r",
            "--out",
            "o",
        ],
        dir.path(),
    ));
    assert!(e.contains("`r` row 1") && e.contains("from 1"), "{e}");
}

/// `rtid import FILE --kind servo-trace` of columns t (s), r and q (deg) and u (the
/// effort as `effort` maps it), in `dir`.
fn import_trace(dir: &Path, file: &str, effort: &str) -> Output {
    rtid(
        &[
            "import",
            file,
            "--kind",
            "servo-trace",
            "--map",
            "time=t:s",
            "--map",
            "reference_position=r:deg",
            "--map",
            "position=q:deg",
            "--map",
            effort,
            "--out",
            "o",
        ],
        dir,
    )
}

/// A mapped value beyond ±1e15 in SI, or one that overflows on conversion, is refused
/// by the import naming the source file, its line, the map and the channel, not
/// written for the experiment's reader to refuse (issue 28: a TwinCAT cell of 1e308
/// was written, and the written file then did not read).
#[test]
fn a_value_out_of_range_is_refused_at_its_source_line() {
    let dir = tempfile::tempdir().unwrap();
    let rows: String = (0..20)
        .map(|i| {
            let u = if i == 6 {
                "1e300".to_string()
            } else {
                format!("{}", i % 3)
            };
            format!("{},{i},{i},{u}\n", i as f64 * 1e-3)
        })
        .collect();
    std::fs::write(dir.path().join("trace.csv"), format!("t,r,q,u\n{rows}")).unwrap();
    let e = err(&import_trace(dir.path(), "trace.csv", "effort=u:N·m"));
    assert!(
        e.contains("trace.csv, line 8: --map effort=u:N·m: `u` is 1e300 in SI units, beyond ±1e15"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
    let e = err(&import_trace(dir.path(), "trace.csv", "effort=u*1e10:N·m"));
    assert!(
        e.contains("line 8") && e.contains("not a finite number"),
        "{e}"
    );
    assert!(!dir.path().join("o").exists(), "nothing written");
}

/// A servo trace whose time base skips a sample is refused naming the source line
/// (it named the written file's row before, issue 28).
#[test]
fn a_gap_in_a_servo_trace_is_refused_at_its_source_line() {
    let dir = tempfile::tempdir().unwrap();
    let rows: String = (0..20)
        .filter(|&i| i != 9)
        .map(|i| format!("{},{i},{i},1\n", i as f64 * 1e-3))
        .collect();
    std::fs::write(dir.path().join("gap.csv"), format!("t,r,q,u\n{rows}")).unwrap();
    let e = err(&import_trace(dir.path(), "gap.csv", "effort=u:N·m"));
    assert!(
        e.contains("gap.csv, line 11: the time base of `t`: the step from the previous row is 2.000000e-3 s"),
        "{e}"
    );
}

const EPOS_SPEED: &str = "speed=Velocity actual value averaged*-1:rpm";
const EPOS_EFFORT: &str = "effort=Torque actual value averaged*-1:%(9.84 mN·m)";

/// The velocity (rpm) and torque (%) columns of an EPOS Studio export, read here
/// independently of rtid's reader: the rows after the units row.
fn epos_columns(text: &str) -> (Vec<f64>, Vec<f64>) {
    let rows = text.lines().skip_while(|l| !l.starts_with("ms;")).skip(1);
    rows.filter(|l| !l.trim().is_empty())
        .map(|l| {
            let cells: Vec<f64> = l.split(';').map(|c| c.trim().parse().unwrap()).collect();
            (cells[1], cells[2])
        })
        .unzip()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn import_map(files: &[&str], dir: &Path) -> Output {
    let mut args = vec!["import"];
    args.extend_from_slice(files);
    args.extend([
        "--kind",
        "friction-map",
        "--map",
        EPOS_SPEED,
        "--map",
        EPOS_EFFORT,
        "--out",
        "map",
    ]);
    rtid(&args, dir)
}

#[test]
fn epos_steady_state_runs_become_a_friction_map() {
    let dir = tempfile::tempdir().unwrap();
    let epos = root().join("fixtures/formats/epos");
    let files = [
        epos.join("driveNo1/steady_state/10.csv"),
        epos.join("driveNo2/steady_state/n50.csv"),
    ];
    let names: Vec<&str> = files.iter().map(|f| f.to_str().unwrap()).collect();
    let out = import_map(&names, dir.path());
    assert!(ok(&out).contains("wrote map/friction_map.json (friction_map, 2 rows)"));
    let e = experiment_file::read(&dir.path().join("map/friction_map.json")).unwrap();
    let Data::FrictionMap(m) = &e.data else {
        panic!("a friction map: {:?}", e.data.kind());
    };
    assert_eq!(m.axis, rtid::model::Axis::Rotary);
    // Rows by speed: n50 (−50 rpm after the sign flip), then 10 (+10 rpm). Each the
    // plain mean of its 500 samples (no glitch, no transient), flipped and in SI.
    for (row, file) in [(0, &files[1]), (1, &files[0])] {
        let (rpm, percent) = epos_columns(&std::fs::read_to_string(file).unwrap());
        assert_eq!(rpm.len(), 500);
        let speed = -mean(&rpm) * std::f64::consts::PI / 30.0;
        let effort = -mean(&percent) * 9.84e-3 / 100.0;
        assert!((m.speed[row] - speed).abs() < 1e-12, "{}", m.speed[row]);
        assert!((m.effort[row] - effort).abs() < 1e-12, "{}", m.effort[row]);
        assert_eq!(m.samples.as_ref().unwrap()[row], 500.0);
        assert_eq!(m.dropped.as_ref().unwrap()[row], 0.0);
        assert_eq!(m.transient.as_ref().unwrap()[row], 0.0);
    }
    assert!(m.speed[0] < -5.0 && m.effort[0] < 0.0);
    // +10 rpm is π/3 rad/s.
    assert!((m.speed[1] - std::f64::consts::FRAC_PI_3).abs() < 1e-3 && m.effort[1] > 0.0);
    let import = &e.manifest.extra["import"];
    assert_eq!(import["sources"].as_array().unwrap().len(), 2);
    let findings: Vec<&str> = import["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    let run = findings
        .iter()
        .find(|f| f.contains("10.csv: a run at 1.047 rad/s (10 rpm as mapped)"))
        .unwrap_or_else(|| panic!("{findings:#?}"));
    assert!(run.contains("500 samples averaged (lines 15–514)"), "{run}");
    assert_eq!(import["runs"][1]["averaged"], "lines 15–514");
}

#[test]
fn a_glitch_is_dropped_from_its_run_and_an_unsettled_run_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let epos = root().join("fixtures/formats/epos/driveNo1/steady_state");
    // 10.csv with the torque of line 120 written over by a recorder glitch.
    let text = std::fs::read_to_string(epos.join("10.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let cells: Vec<&str> = lines[119].split(';').collect();
    lines[119] = format!("{};{};-400.0", cells[0], cells[1]);
    std::fs::write(dir.path().join("10.csv"), lines.join("\r\n") + "\r\n").unwrap();
    let out = import_map(&["10.csv"], dir.path());
    let stderr = String::from_utf8(out.stderr.clone()).unwrap();
    ok(&out);
    assert!(
        stderr.contains("10.csv, line 120: `Torque actual value averaged` = -400 is a glitch")
            && stderr.contains("dropped from the run's means"),
        "{stderr}"
    );
    assert!(
        stderr.contains("499 samples averaged (lines 15–514), 1 dropped as glitches"),
        "{stderr}"
    );
    let e = experiment_file::read(&dir.path().join("map/friction_map.json")).unwrap();
    let Data::FrictionMap(m) = &e.data else {
        panic!("a friction map");
    };
    let (_, mut percent) = epos_columns(&text);
    percent.remove(119 - 14);
    assert!((m.effort[0] + mean(&percent) * 9.84e-5).abs() < 1e-12);
    assert_eq!(
        (
            m.samples.as_ref().unwrap()[0],
            m.dropped.as_ref().unwrap()[0]
        ),
        (499.0, 1.0)
    );

    // At −2 rpm drive 1's speed readings jump between 0 and 15 rpm about their median
    // of 1: a fifth of them lie outside the settle band, but the run holds its speed
    // (its halves agree), so it is a row of the map, its mean speed near −2 rpm.
    let n2 = epos.join("n2.csv");
    ok(&import_map(&["10.csv", n2.to_str().unwrap()], dir.path()));
    let e = experiment_file::read(&dir.path().join("map/friction_map.json")).unwrap();
    let Data::FrictionMap(m) = &e.data else {
        panic!("a friction map");
    };
    let rpm = m.speed[0] * 60.0 / std::f64::consts::TAU;
    assert!(m.len() == 2 && (-2.6..-1.4).contains(&rpm), "{rpm} rpm");
    // The maps apply to each file: a channel one file lacks names that file.
    std::fs::write(
        dir.path().join("other.csv"),
        "t,w,q
s,rpm,N·m
0,1,1
",
    )
    .unwrap();
    let e = err(&import_map(&["10.csv", "other.csv"], dir.path()));
    assert!(
        e.contains("other.csv: --map speed=Velocity actual value averaged*-1:rpm: no channel"),
        "{e}"
    );
}

/// A stepped-speed record of one file (delimited text, as a DAQ script writes it):
/// ±20 and ±50 rpm held for 60 samples each, joined by changes of 5 samples, from rest.
fn stepped_record() -> (String, Vec<(usize, usize, f64)>) {
    let levels = [20.0, -20.0, 50.0, -50.0];
    let mut speed = vec![0.0; 10];
    let mut holds = Vec::new();
    let mut from = 0.0;
    for level in levels {
        speed.extend((1..=5).map(|j| from + (level - from) * j as f64 / 6.0));
        let start = speed.len();
        speed.extend((0..60).map(|i| level + 0.2 * [1.0, -1.0, 0.0][i % 3]));
        holds.push((start, speed.len(), level));
        from = level;
    }
    speed.extend((1..=5).map(|j| from * (1.0 - j as f64 / 5.0)));
    let mut text = String::from("# stepped-speed run\ntime,speed,torque\ns,rpm,mN·m\n");
    for (i, v) in speed.iter().enumerate() {
        // Friction: 2 mN·m Coulomb and 0.01 mN·m per rpm, with a little ripple.
        let torque = if *v == 0.0 {
            0.0
        } else {
            v.signum() * 2.0 + 0.01 * v + 0.05 * [1.0, 0.0, -1.0, 0.0][i % 4]
        };
        text += &format!("{},{v},{torque}\n", i as f64 * 0.01);
    }
    // Sample i is on line i + 4.
    let holds = holds
        .into_iter()
        .map(|(a, b, l)| (a + 4, b + 3, l))
        .collect();
    (text, holds)
}

#[test]
fn one_stepped_speed_record_is_cut_into_its_plateaus() {
    let dir = tempfile::tempdir().unwrap();
    let (text, holds) = stepped_record();
    std::fs::write(dir.path().join("steps.csv"), text).unwrap();
    let out = rtid(
        &[
            "import",
            "steps.csv",
            "--kind",
            "friction-map",
            "--map",
            "speed=speed",
            "--map",
            "effort=torque",
            "--map",
            "time=time",
            "--out",
            "map",
        ],
        dir.path(),
    );
    assert!(ok(&out).contains("(friction_map, 4 rows)"));
    let e = experiment_file::read(&dir.path().join("map/friction_map.json")).unwrap();
    let Data::FrictionMap(m) = &e.data else {
        panic!("a friction map");
    };
    let rpm = std::f64::consts::PI / 30.0;
    let mut expected: Vec<f64> = holds.iter().map(|h| h.2).collect();
    expected.sort_by(f64::total_cmp);
    for (row, level) in expected.iter().enumerate() {
        assert!(
            (m.speed[row] / rpm - level).abs() < 0.01,
            "{row}: {}",
            m.speed[row] / rpm
        );
        let effort = (level.signum() * 2.0 + 0.01 * level) * 1e-3;
        assert!(
            (m.effort[row] - effort).abs() < 3e-5,
            "{row}: {}",
            m.effort[row]
        );
        assert!(m.samples.as_ref().unwrap()[row] >= 50.0);
    }
    // Each run averaged lines of its hold only; the changes were left out.
    let import = &e.manifest.extra["import"];
    for run in import["runs"].as_array().unwrap() {
        let span = run["averaged"].as_str().unwrap();
        let (a, b) = span
            .strip_prefix("lines ")
            .and_then(|s| s.split_once('–'))
            .unwrap_or_else(|| panic!("{span}"));
        let (a, b): (usize, usize) = (a.parse().unwrap(), b.parse().unwrap());
        assert!(
            holds
                .iter()
                .any(|&(start, end, _)| a >= start && b <= end && b - a >= 49),
            "{span} is not within a hold: {holds:?}"
        );
    }
    let findings = import["findings"].to_string();
    assert!(
        findings.contains(
            "steps.csv: a stepped-speed record, its plateaus taken as runs: lines 19–78, lines 84–143, "
        ),
        "{findings}"
    );
    // The changes between the holds are transitions; the drive at rest before the
    // first is a plateau, but not one of the map.
    assert!(
        findings.contains("left out as transitions: lines 14–18, lines 79–83, "),
        "{findings}"
    );
    assert!(
        findings.contains("steps.csv, lines 4–13: a plateau not taken as a run: at rest"),
        "{findings}"
    );
}
