//! The virtual ISO 230-2 positioning test on both presets (docs/experiments.md (positioning)).

use rtid::experiments::positioning::iso230::{evaluate, ARCSEC_PER_RAD};
use rtid::experiments::positioning::{run, PositioningTest};
use rtid::model::presets;

#[test]
fn worm_reversal_is_its_lost_motion_and_the_roller_has_almost_none() {
    let test = PositioningTest::default();
    let worm = presets::load("worm-gear").unwrap();
    let report = evaluate(&run(&worm, &test, |_, _| {}).unwrap()).unwrap();
    let axis = report.axis.in_arcsec();
    // Semi-closed loop: the motor is positioned, the table lags by half the lost
    // motion on each side, so the mean reversal is the total lost motion at the
    // table: 2·θbw + 2·θbg·Rw (plus the elastic wind-up of the friction torques).
    let lost_motion =
        (2.0 * worm.theta_bw + 2.0 * worm.theta_bg.unwrap() * worm.rw) * ARCSEC_PER_RAD;
    eprintln!(
        "worm: B_mean {:.2}″ (lost motion {lost_motion:.2}″), R {:.2}″, A {:.2}″",
        axis.b_mean, axis.r, axis.a
    );
    assert!(
        (axis.b_mean.abs() - lost_motion).abs() < 0.1 * lost_motion,
        "worm mean reversal {:.2}″ vs lost motion {lost_motion:.2}″",
        axis.b_mean
    );
    let roller = presets::load("roller-gear-cam").unwrap();
    let report = evaluate(&run(&roller, &test, |_, _| {}).unwrap()).unwrap();
    let axis = report.axis.in_arcsec();
    // No backlash: what remains is the elastic wind-up of the table's friction
    // torque through the drive's series stiffness Kw ‖ Kb·r², opposite for the two
    // approach directions: 2·ft/K, to within one table-encoder count (0.36″).
    let k = 1.0 / (1.0 / roller.kw + 1.0 / (roller.kb * roller.r * roller.r));
    let windup = 2.0 * roller.ft / k * ARCSEC_PER_RAD;
    let count = roller.controller.table_encoder_resolution * ARCSEC_PER_RAD;
    eprintln!(
        "roller: B_mean {:.2}″ (wind-up {windup:.2}″), R {:.2}″, A {:.2}″",
        axis.b_mean, axis.r, axis.a
    );
    assert!(
        (axis.b_mean.abs() - windup).abs() < count,
        "roller mean reversal {:.2}″ vs wind-up {windup:.2}″",
        axis.b_mean
    );
    assert!(axis.b_mean.abs() < 0.05 * lost_motion);
}

/// The parameter file's `controller.loop` is the test's loop: a worm gear set to
/// full-closed runs full-closed without `--loop`, reading what `--loop full_closed`
/// reads; `--loop` overriding a different loop says so (unless `--quiet`), in the
/// manifest too. Library side: a default test runs each set in its own loop.
#[test]
fn the_parameter_files_loop_is_the_default_and_loop_overrides_it() {
    use crate::cli_support::{ok, root, rtid};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let preset = std::fs::read_to_string(root().join("fixtures/presets/worm-gear.json")).unwrap();
    let full = preset.replace("\"loop\": \"semi_closed\"", "\"loop\": \"full_closed\"");
    assert_ne!(full, preset, "the preset states its loop");
    std::fs::write(d.join("full.json"), full).unwrap();
    let short = [
        "--runs",
        "2",
        "--target-step-deg",
        "120",
        "--dwell-s",
        "0.3",
    ];
    let run = |out: &str, extra: &[&str]| {
        let args = [
            &[
                "experiment",
                "positioning",
                "--params",
                "full.json",
                "--out",
                out,
            ][..],
            &short[..],
            extra,
        ]
        .concat();
        let done = rtid(&args, d);
        let stderr = String::from_utf8_lossy(&done.stderr).to_string();
        ok(&done);
        let csv = std::fs::read_to_string(d.join(out).join("positioning.csv")).unwrap();
        let manifest = std::fs::read_to_string(d.join(out).join("positioning.json")).unwrap();
        (csv, manifest, stderr)
    };
    let (own, manifest, stderr) = run("own", &[]);
    assert!(manifest.contains("\"loop\": \"full_closed\""), "{manifest}");
    assert!(!stderr.contains("note:"), "{stderr}");
    let (explicit, _, stderr) = run("explicit", &["--loop", "full_closed"]);
    assert_eq!(own, explicit, "the file's loop is the default");
    assert!(!stderr.contains("note:"), "no override, no note: {stderr}");
    let (semi, manifest, stderr) = run("semi", &["--loop", "semi_closed"]);
    assert_ne!(own, semi, "the loops read differently");
    let note = "--loop semi_closed overrides the parameter set's controller.loop (full_closed)";
    assert!(stderr.contains(&format!("note: {note}")), "{stderr}");
    assert!(manifest.contains(note), "{manifest}");
    let (_, _, stderr) = run("quiet", &["--loop", "semi_closed", "--quiet"]);
    assert!(!stderr.contains("note:"), "{stderr}");
    // The library: a default test leaves each set its loop, and a test's loop wins.
    let mut p = presets::load("worm-gear").unwrap();
    p.controller.loop_mode = rtid::model::LoopMode::FullClosed;
    let test = PositioningTest {
        targets: vec![0.0, 120f64.to_radians(), 240f64.to_radians()],
        runs: 2,
        dwell: 0.3,
        ..PositioningTest::default()
    };
    let forced = PositioningTest {
        loop_mode: Some(rtid::model::LoopMode::FullClosed),
        ..test.clone()
    };
    assert_eq!(
        run_readings(&p, &test),
        run_readings(&presets::load("worm-gear").unwrap(), &forced)
    );
}

fn run_readings(
    p: &rtid::Params,
    test: &PositioningTest,
) -> Vec<rtid::experiments::positioning::iso230::Measurement> {
    run(p, test, |_, _| {}).unwrap()
}
