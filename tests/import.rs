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
