//! One complex frequency response in two formats gives one identification: the worm
//! table's response with 2 % complex noise as an rtid experiment file
//! (fixtures/frf/worm_frf.json + .csv) and as a UFF dataset 58b (worm_frf.uff), both
//! written by fixtures/frf/make_worm_frf.py from the same complex values. `rtid import`
//! of the UFF gives the CSV's frequencies, gains and phases, and `rtid identify` the
//! same parameters and cost from either. No objective is named: the two
//! identifications are compared with each other, whichever objective rtid uses for a
//! frequency response. The generator computes the CSV's gains and phases with the C
//! library's functions, as an importer does, so the two files hold the same numbers;
//! from gains and phases that differed in their last bits (a first draft's numpy
//! rounding) the complex fit stopped 3e-7 apart in Ciw (docs/import.md, UFF section).

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::cli_support::{ok, root, rtid};

/// The UFF's complex channel: its ID line 1.
const CHANNEL: &str = "worm table/motor";

fn fixture(name: &str) -> PathBuf {
    root().join("fixtures/frf").join(name)
}

/// `rtid import worm_frf.uff` into `dir/uff/`; the manifest's path.
fn import_uff(dir: &Path) -> PathBuf {
    let uff = fixture("worm_frf.uff");
    let map = format!("frf={CHANNEL}");
    ok(&rtid(
        &[
            "import",
            uff.to_str().unwrap(),
            "--kind",
            "frequency-response",
            "--map",
            &map,
            "--mechanism",
            "worm-gear",
            "--out",
            "uff",
            "--quiet",
        ],
        dir,
    ));
    dir.join("uff/frequency_response.json")
}

/// The rows (frequency_hz, gain_db, phase_deg) of a frequency-response CSV.
fn rows(csv: &Path) -> Vec<[f64; 3]> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty());
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{}: no column {name}", csv.display()))
    };
    let columns = [
        column("frequency_hz"),
        column("gain_db"),
        column("phase_deg"),
    ];
    lines
        .map(|l| {
            let cells: Vec<f64> = l.split(',').map(|c| c.trim().parse().unwrap()).collect();
            columns.map(|j| cells[j])
        })
        .collect()
}

/// A phase difference in degrees, taken into (−180, 180].
fn phase_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

#[test]
fn the_imported_uff_is_the_csv_point_by_point() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = import_uff(dir.path());
    let imported: Value =
        serde_json::from_str(&std::fs::read_to_string(&manifest).unwrap()).unwrap();
    assert_eq!(imported["kind"], "frequency_response");
    assert_eq!(imported["mechanism"], "worm-gear");
    let uff = rows(&manifest.with_extension("csv"));
    let csv = rows(&fixture("worm_frf.csv"));
    assert_eq!(uff.len(), csv.len(), "number of frequencies");
    assert_eq!(csv.len(), 1996);
    let (mut gain, mut phase) = (0.0_f64, 0.0_f64);
    for (u, c) in uff.iter().zip(&csv) {
        assert!(
            ((u[0] - c[0]) / c[0]).abs() <= 1e-9,
            "frequency {} Hz from the UFF, {} Hz in the CSV",
            u[0],
            c[0]
        );
        let dg = (u[1] - c[1]).abs();
        let dp = phase_difference(u[2], c[2]).abs();
        assert!(
            dg <= 1e-9,
            "{} Hz: gain {} dB from the UFF, {} dB in the CSV",
            c[0],
            u[1],
            c[1]
        );
        assert!(
            dp <= 1e-9,
            "{} Hz: phase {}° from the UFF, {}° in the CSV",
            c[0],
            u[2],
            c[2]
        );
        gain = gain.max(dg);
        phase = phase.max(dp);
    }
    eprintln!("UFF against CSV: largest gain difference {gain:.2e} dB, phase {phase:.2e}°");
}

#[test]
fn the_csv_and_the_imported_uff_give_the_same_identification() {
    let dir = tempfile::tempdir().unwrap();
    let imported = import_uff(dir.path());
    let fit = |manifest: &Path| -> Value {
        let out = ok(&rtid(
            &[
                "identify",
                manifest.to_str().unwrap(),
                "--preset",
                "worm-gear",
                "--model",
                "linear",
                "--fit",
                "Kw,Kg,Ciw,Cig",
                "--quiet",
                "--json",
            ],
            dir.path(),
        ));
        serde_json::from_str(&out).unwrap()
    };
    let from_csv = fit(&fixture("worm_frf.json"));
    let from_uff = fit(&imported);
    let relative = |a: f64, b: f64| ((a - b) / b).abs();

    let pc = from_csv["parameters"].as_object().unwrap();
    let pu = from_uff["parameters"].as_object().unwrap();
    let names: Vec<&String> = pc.keys().collect();
    assert_eq!(names, pu.keys().collect::<Vec<_>>());
    assert_eq!(names.len(), 4);
    for (name, c) in pc {
        let (c, u) = (c.as_f64().unwrap(), pu[name].as_f64().unwrap());
        assert!(c.is_finite() && c > 0.0, "{name} = {c}");
        eprintln!(
            "{name}: {c:e} from the CSV, {u:e} from the UFF ({:.1e} relative)",
            relative(u, c)
        );
        assert!(
            relative(u, c) <= 1e-9,
            "{name}: {u} from the UFF, {c} from the CSV"
        );
    }
    let (cc, cu) = (
        from_csv["cost"].as_f64().unwrap(),
        from_uff["cost"].as_f64().unwrap(),
    );
    eprintln!(
        "cost: {cc:e} from the CSV, {cu:e} from the UFF ({:.1e} relative)",
        relative(cu, cc)
    );
    assert!(
        relative(cu, cc) <= 1e-9,
        "cost {cu} from the UFF, {cc} from the CSV"
    );
}
