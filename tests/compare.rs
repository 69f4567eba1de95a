//! The paper's Table 3 (`rtid compare`, `experiments::compare`) on folders of virtual
//! experiments of both presets. Fast conditions: positioning with 2 runs at 0°, 180°,
//! 360°; one period of the torque curve; the linear frequency response (solved in the
//! frequency domain, no time simulation). Fluctuation and unbalance (≈ 20 s of CPU for
//! both presets) are left out: their rows must then print "—".

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use rtid::experiments::compare::{summarize, CompareError};
use rtid::experiments::frequency_response::linear;
use rtid::experiments::positioning::{self, PositioningTest};
use rtid::experiments::torque_curve::{self, TorqueTest};
use rtid::io::experiment_file::{self, Columns, Data, Kind, Manifest};
use rtid::model::{modes, presets, Params};

const PRESETS: [&str; 2] = ["worm-gear", "roller-gear-cam"];

/// Writes the three fast experiments of preset `name` into `dir`, plus a parameter
/// file (to be skipped).
fn write_folder(dir: &Path, name: &str) {
    std::fs::create_dir_all(dir).unwrap();
    let p = presets::load(name).unwrap();

    let test = PositioningTest {
        runs: 2,
        targets: vec![0.0, std::f64::consts::PI, std::f64::consts::TAU],
        ..Default::default()
    };
    let readings = positioning::run(&p, &test, |_, _| {}).unwrap();
    let mut m = positioning::manifest(&p, &test);
    m.data = Some("positioning.csv".into());
    experiment_file::write(
        &dir.join("positioning.json"),
        &m,
        &positioning::to_data(&readings, p.axis),
    )
    .unwrap();

    let test = TorqueTest {
        periods: 1.0,
        ..Default::default()
    };
    let curve = torque_curve::run(&p, &test, |_, _| {}).unwrap();
    let mut m = torque_curve::manifest(&p, &test);
    m.data = Some("torque_curve.csv".into());
    experiment_file::write(
        &dir.join("torque_curve.json"),
        &m,
        &torque_curve::to_data(&curve, p.axis),
    )
    .unwrap();

    let freqs: Vec<f64> = (10..=600).map(f64::from).collect();
    let gain = linear(&p, &freqs).unwrap();
    let mut m = Manifest::new(Kind::FrequencyResponse);
    m.mechanism = Some(p.name.clone());
    m.data = Some("frequency_response.csv".into());
    let data = Data::FrequencyResponse {
        gain_db: gain.iter().map(|g| g.0).collect(),
        phase_rad: Some(gain.iter().map(|g| g.1.to_radians()).collect()),
        frequency_hz: freqs,
        extra: Columns::new(),
    };
    experiment_file::write(&dir.join("frequency_response.json"), &m, &data).unwrap();

    // A parameter file beside them: JSON without `kind`, skipped quietly.
    std::fs::write(
        dir.join("params.json"),
        serde_json::to_string(&serde_json::json!({"name": name, "Kw": 1.0e6})).unwrap(),
    )
    .unwrap();
}

/// The two folders (worm, roller), written once for all tests.
fn folders() -> &'static (tempfile::TempDir, PathBuf, PathBuf) {
    static DIRS: OnceLock<(tempfile::TempDir, PathBuf, PathBuf)> = OnceLock::new();
    DIRS.get_or_init(|| {
        let root = tempfile::tempdir().unwrap();
        let (w, r) = (root.path().join("worm"), root.path().join("roller"));
        std::thread::scope(|s| {
            s.spawn(|| write_folder(&w, PRESETS[0]));
            s.spawn(|| write_folder(&r, PRESETS[1]));
        });
        (root, w, r)
    })
}

fn motor_friction(p: &Params) -> f64 {
    p.fm + p.fw * p.rg.unwrap_or(1.0) + p.ft * p.ratio()
}

#[test]
fn table_3_rows_of_both_presets() {
    let (_, worm_dir, roller_dir) = folders();
    for (dir, name) in [(worm_dir, PRESETS[0]), (roller_dir, PRESETS[1])] {
        let s = summarize(dir).unwrap();
        eprintln!("{name}: {}", serde_json::to_string(&s).unwrap());
        let p = presets::load(name).unwrap();
        assert_eq!(s.mechanism.as_deref(), Some(p.name.as_str()));
        assert_eq!(s.sources.len(), 3, "{:?}", s.sources);

        // Resonances of the linear response: the motor-held modes (docs/experiments.md (frequency response)).
        let res = s.resonances_hz.as_ref().unwrap();
        assert!(!res.is_empty() && res.len() <= 3, "{res:?}");
        assert!(res.windows(2).all(|w| w[0] < w[1]), "{res:?}");
        let clamped = modes::modes(&p).unwrap().clamped_hz;
        for f in res {
            assert!(
                clamped.iter().any(|c| (c - f).abs() < 5.0),
                "{name}: peak {f:.1} Hz not a clamped mode {clamped:?}"
            );
        }
        let first = clamped.iter().copied().fold(f64::INFINITY, f64::min);
        assert!((res[0] - first).abs() < 5.0, "{res:?} vs {first}");

        let friction = s.friction_torque_nm.unwrap();
        let expected = motor_friction(&p);
        assert!(
            (friction - expected).abs() < 0.2 * expected,
            "{name}: friction {friction} vs {expected}"
        );

        assert!(s.r_arcsec.unwrap() >= 0.0 && s.a_arcsec.unwrap() >= 0.0);
        assert_eq!(s.backlash_arcsec, s.b_mean_arcsec);
        assert_eq!(s.backlash_from, Some("positioning"));
        assert!(s.fluctuation.is_none() && s.unbalance.is_none());
    }
    let worm = summarize(worm_dir).unwrap();
    let roller = summarize(roller_dir).unwrap();
    assert!(
        worm.b_mean_arcsec.unwrap() > 20.0,
        "{:?}",
        worm.b_mean_arcsec
    );
    assert!(
        roller.b_mean_arcsec.unwrap() < 3.0,
        "{:?}",
        roller.b_mean_arcsec
    );
}

#[test]
fn a_malformed_manifest_is_an_error_naming_the_file() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path();
    // A positioning manifest whose CSV lacks the deviation column.
    std::fs::write(
        dir.join("bad.json"),
        r#"{"kind": "positioning", "mechanism": "worm-gear"}"#,
    )
    .unwrap();
    std::fs::write(dir.join("bad.csv"), "target_deg,direction,run\n0,up,1\n").unwrap();
    let e = summarize(dir).unwrap_err();
    assert!(matches!(e, CompareError::File(_)), "{e:?}");
    assert!(e.to_string().contains("bad"), "{e}");
    // An unknown kind too.
    std::fs::remove_file(dir.join("bad.json")).unwrap();
    std::fs::write(dir.join("odd.json"), r#"{"kind": "spin"}"#).unwrap();
    let e = summarize(dir).unwrap_err().to_string();
    assert!(e.contains("odd.json"), "{e}");
}

#[test]
fn cli_prints_table_3_with_dashes_for_missing_kinds() {
    let (_, worm_dir, roller_dir) = folders();
    let out = Command::new(env!("CARGO_BIN_EXE_rtid"))
        .arg("compare")
        .arg(worm_dir)
        .arg(roller_dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{stdout}");
    assert!(stdout.contains("Table 3"));
    for row in [
        "Frequency response",
        "Friction torque",
        "Mean reversal value",
        "Repeatability",
        "Accuracy",
        "Rotational fluctuation",
        "Influence of unbalance mass",
        "Backlash",
    ] {
        assert!(stdout.contains(row), "no row {row}");
    }
    let line = |name: &str| {
        stdout
            .lines()
            .find(|l| l.contains(name))
            .unwrap()
            .to_string()
    };
    // No fluctuation or unbalance file: both columns "—".
    assert_eq!(line("Rotational fluctuation").matches('—').count(), 2);
    assert_eq!(line("Influence of unbalance").matches('—').count(), 2);
    assert_eq!(line("Mean reversal").matches('—').count(), 0);

    let out = Command::new(env!("CARGO_BIN_EXE_rtid"))
        .args(["compare", "--json"])
        .arg(worm_dir)
        .arg(roller_dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let w = &v[worm_dir.display().to_string()];
    assert!(w["b_mean_arcsec"].as_f64().unwrap() > 20.0);
    assert!(w["fluctuation"].is_null());
}
