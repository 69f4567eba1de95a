//! `rtid import` on a MAT-file laid out as a robot lab saves it (issue 37): struct
//! `rec` of 6×2501 matrices, axes as rows, samples as columns
//! (fixtures/formats/matlab/kuka/, the KUKA KR300 record, MIT). The rows are the
//! signals, listed once per matrix; a map names a row as MATLAB does, its unit from
//! the variable's name; a misspelt channel is told the closest few names.

use std::path::PathBuf;
use std::process::{Command, Output};

use rtid::io::experiment_file::{self, Data};
use rtid::io::formats::{mat, Recording, Samples};

fn robot() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/formats/matlab/kuka/kuka_kr300_ff_a.mat")
}

/// `rtid import` of axis 1 as a servo trace into `out` (time, motor encoder,
/// reference, torque; a blank inside one index), with `extra` arguments.
fn import_axis_1(out: &std::path::Path, extra: &[&str]) -> Output {
    let (robot, out) = (robot(), out.to_str().unwrap().to_string());
    let mut args = vec![
        "import",
        robot.to_str().unwrap(),
        "--kind",
        "servo-trace",
        "--map",
        "time=rec.time_cont:s",
        "--map",
        "position=rec.act_pos_mot_deg(1,:)",
        "--map",
        "reference_position=rec.ref_pos_deg(1, :)",
        "--map",
        "effort=rec.act_torque_abs_nm(1,:)",
        "--out",
        &out,
    ];
    args.extend(extra);
    rtid(&args)
}

fn rtid(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(args)
        .output()
        .expect("the rtid binary runs")
}

fn real<'a>(r: &'a Recording, name: &str) -> &'a [f64] {
    match r
        .channels
        .iter()
        .find(|c| c.name == name)
        .map(|c| &c.samples)
    {
        Some(Samples::Real(v)) => v,
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn the_robots_matrices_are_cut_into_their_rows() {
    let r = mat::read(&robot()).unwrap();
    let g = r
        .groups
        .iter()
        .find(|g| g.name == "rec.act_pos_mot_deg")
        .unwrap();
    assert_eq!(
        (g.shape.as_slice(), g.signals_in_rows),
        (&[6, 2501][..], true)
    );
    assert_eq!(g.channels.len(), 6);
    let n = real(&r, "rec.time_cont").len();
    // The record's own identity, row by row: the position error is the command
    // minus the encoder the axis is controlled by (the link-side one on axes 1-3, the
    // motor's on 4-6). Rows cut the wrong way round would keep neither.
    let miss = |error: &[f64], reference: &[f64], encoder: &[f64]| {
        (0..n)
            .map(|k| (error[k] - (reference[k] - encoder[k])).abs())
            .fold(0.0, f64::max)
    };
    for axis in 1..=6 {
        let row = |name: &str| real(&r, &format!("rec.{name}({axis},:)"));
        let error = row("error_pos_deg");
        assert_eq!(error.len(), n);
        let link = miss(error, row("ref_pos_deg"), row("act_pos_se_deg"));
        let motor = miss(error, row("ref_pos_deg"), row("act_pos_mot_deg"));
        let encoder = if axis <= 3 { link } else { motor };
        assert!(
            encoder < 1e-9,
            "axis {axis}: error ≠ ref − encoder by {encoder}"
        );
    }
}

#[test]
fn the_list_shows_each_matrix_once_and_filters() {
    let out = rtid(&["import", robot().to_str().unwrap(), "--list"]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(out.status.success());
    let lines = text.lines().count();
    assert!((20..150).contains(&lines), "{lines} lines:\n{text}");
    let row = text
        .lines()
        .find(|l| l.contains("rec.act_pos_mot_deg(i,:), i = 1…6"))
        .expect("the matrix on one line");
    assert!(row.contains("(deg)") && row.contains("6×2501"), "{row}");
    let out = rtid(&[
        "import",
        robot().to_str().unwrap(),
        "--list",
        "--filter",
        "TORQUE_ABS",
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with('│') && l.contains("rec.act_torque_abs_nm("))
        .collect();
    assert_eq!(rows.len(), 6, "{text}");
    assert!(!text.contains("act_pos_mot"), "{text}");
}

#[test]
fn a_row_maps_onto_a_servo_trace_with_its_unit_from_the_name() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("kuka");
    let out = import_axis_1(
        &out_dir,
        &["--map", "table_position=rec.act_pos_se_deg(1,:)"],
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("its name says N·m"), "{stderr}");
    let experiment = experiment_file::read(&out_dir.join("servo_trace.json")).unwrap();
    let Data::ServoTrace(trace) = experiment.data else {
        panic!("not a servo trace")
    };
    let r = mat::read(&robot()).unwrap();
    let degrees = real(&r, "rec.act_pos_mot_deg(1,:)");
    assert_eq!(trace.position.len(), degrees.len());
    for (rad, deg) in trace.position.iter().zip(degrees) {
        assert!((rad - deg.to_radians()).abs() <= 1e-15 * deg.abs().max(1.0));
    }
    assert_eq!(trace.effort, real(&r, "rec.act_torque_abs_nm(1,:)"));
}

#[test]
fn a_misspelt_or_transposed_channel_gets_a_short_answer() {
    let run = |map: &str| {
        let dir = tempfile::tempdir().unwrap();
        let out = rtid(&[
            "import",
            robot().to_str().unwrap(),
            "--kind",
            "torque-curve",
            "--map",
            map,
            "--out",
            dir.path().to_str().unwrap(),
        ]);
        assert!(!out.status.success());
        String::from_utf8(out.stderr).unwrap()
    };
    let e = run("effort=rec.act_torq_abs_nm(1,:)");
    assert!(e.len() < 1024, "{} bytes: {e}", e.len());
    assert!(
        e.contains("rec.act_torque_abs_nm(i,:), i = 1…6") && e.contains("more"),
        "{e}"
    );
    let e = run("effort=rec.act_torque_abs_nm(:,1)");
    assert!(e.len() < 1024, "{} bytes: {e}", e.len());
    assert!(
        e.contains("one signal per row: rec.act_torque_abs_nm(i,:)"),
        "{e}"
    );
}

/// The robot's axis 1 imported as a servo trace with its gear ratio (1/u, u = 256.857
/// from the file's `para.u`) and evaluated: IDIM-LS at the motor meets the authors'
/// own friction model (Weigand et al., IROS 2021; `para` in the same file) taken to
/// the motor — Coulomb (f_coul + f_a)/u = 1.384 N·m, viscous f_vis/u² = 0.0311
/// N·m·s/rad, offset f_asym/u = 0.210 N·m — within 10 %, 12 % and 0.04 N·m. The
/// magnitudes say the recorded torque is the motor's (at the link it would be u
/// times larger): as recorded, over the link-side positions, J, Fv and Fc are in
/// neither frame, and rtid says so.
#[test]
fn the_robot_axis_at_the_motor_meets_the_authors_friction() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("kuka");
    let u = 256.857_142_86;
    let ratio = format!("ratio={}", 1.0 / u);
    let run = import_axis_1(&out, &["--condition", &ratio, "--quiet"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let manifest = out.join("servo_trace.json");
    let run = rtid(&["evaluate", manifest.to_str().unwrap(), "--json"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert_eq!(v["frame"], "motor");
    let value = |name: &str| v["inverse_dynamics"][name]["value"].as_f64().unwrap();
    let coulomb = (285.36 + 70.135) / u;
    let viscous = 2050.35 / (u * u);
    let offset = 54.024 / u;
    assert!((value("coulomb") / coulomb - 1.0).abs() < 0.10, "{v}");
    assert!((value("viscous") / viscous - 1.0).abs() < 0.12, "{v}");
    assert!((value("offset") - offset).abs() < 0.04, "{v}");
    // The table names the frame.
    let run = rtid(&["evaluate", manifest.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(text.contains("at the motor"), "{text}");
}
