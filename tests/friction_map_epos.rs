//! The friction maps of the shared lead-screw drives (fixtures/formats/epos/, the files
//! as published) through `rtid import` and `rtid evaluate`, against an independent
//! reading and fit of the same files with numpy and scipy
//! (fixtures/formats/epos/make_friction_map.py → friction_map_expected.json): every run
//! to 1e-9, every law's determined values, standard errors and cost to 1 %, and the law
//! selected.
//!
//! Drive 1's two ±2 rpm runs stick and slip (speed readings of 0 … 15 rpm about a
//! median of 1): rtid averages them (docs/import.md §2), so its map has 32 runs, the
//! reference's `including_not_settled` fits. Drive 2 shows no Stribeck rise: rtid's
//! local Levenberg–Marquardt stops where Fs = Fc and says the rise is not shown, while
//! the reference's multi-start finds a step (δ in the thousands) between its two
//! 200 rpm runs with a lower cost — not a friction law, and not a number either fit
//! determines (a wider random search finds lower steps still). So on drive 2 the
//! Stribeck laws' cost is only checked to be no lower than the reference's, with the
//! rise said not to show, and the law selected (rtid: coulomb; the step would tip AICc
//! to stribeck by 1.0) is not compared there.

use std::path::Path;

use serde_json::Value;

use crate::cli_support::{ok, root, rtid};

/// `rtid evaluate --json` of the map of one drive's steady-state runs.
fn evaluated(drive: &str, dir: &Path) -> Value {
    let folder = root().join(format!("fixtures/formats/epos/{drive}/steady_state"));
    let mut files: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| p.ends_with(".csv"))
        .collect();
    files.sort();
    let mut args: Vec<&str> = vec!["import"];
    args.extend(files.iter().map(String::as_str));
    args.extend([
        "--kind",
        "friction-map",
        "--map",
        "speed=Velocity actual value averaged*-1:rpm",
        "--map",
        "effort=Torque actual value averaged*-1:%(9.84 mN·m)",
        "--out",
        drive,
        "--quiet",
    ]);
    ok(&rtid(&args, dir));
    let map = dir.join(drive).join("friction_map.json");
    serde_json::from_str(&ok(&rtid(
        &["evaluate", map.to_str().unwrap(), "--json"],
        dir,
    )))
    .unwrap()
}

fn close(what: &str, got: f64, expected: f64, tolerance: f64) {
    assert!(
        (got - expected).abs() <= tolerance * expected.abs(),
        "{what}: rtid {got}, scipy {expected}"
    );
}

#[test]
fn the_lead_screw_maps_agree_with_an_independent_fit() {
    let expected: Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("fixtures/formats/epos/friction_map_expected.json"))
            .unwrap(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    for drive in ["driveNo1", "driveNo2"] {
        let drive_entry = &expected["drives"][drive];
        let want = if drive == "driveNo1" {
            &drive_entry["including_not_settled"]
        } else {
            drive_entry
        };
        let got = evaluated(drive, dir.path());
        // The runs, in order of speed.
        let mut runs: Vec<&Value> = drive_entry["runs"].as_array().unwrap().iter().collect();
        runs.sort_by(|a, b| {
            a["speed_rad_s"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["speed_rad_s"].as_f64().unwrap())
        });
        let rows = got["runs"].as_array().unwrap();
        assert_eq!(rows.len(), runs.len(), "{drive}: runs");
        for (row, run) in rows.iter().zip(&runs) {
            let file = run["file"].as_str().unwrap();
            close(
                file,
                row["speed"].as_f64().unwrap(),
                run["speed_rad_s"].as_f64().unwrap(),
                1e-9,
            );
            close(
                file,
                row["effort"].as_f64().unwrap(),
                run["torque_nm"].as_f64().unwrap(),
                1e-9,
            );
        }
        // The laws: each value the data determine (a standard error under half the
        // value) to 1 %, with its standard error, and the cost.
        for fit in got["laws"]["fits"].as_array().unwrap() {
            let law = fit["law"].as_str().unwrap();
            let reference = &want["laws"][law];
            let (ssr, best) = (
                fit["ssr"].as_f64().unwrap(),
                reference["ssr"].as_f64().unwrap(),
            );
            if drive == "driveNo2" && law.starts_with("stribeck") {
                assert!(
                    ssr >= best * (1.0 - 1e-6),
                    "{drive} {law}: {ssr} below {best}"
                );
                let notes = fit["notes"].to_string();
                assert!(notes.contains("rise_not_shown"), "{drive} {law}: {notes}");
                continue;
            }
            close(&format!("{drive} {law} SSR"), ssr, best, 0.01);
            let names: Vec<&str> = reference["params"]
                .as_array()
                .unwrap()
                .iter()
                .map(|n| n.as_str().unwrap())
                .collect();
            for p in fit["parameters"].as_array().unwrap() {
                let name = p["name"].as_str().unwrap();
                let (value, se) = (p["value"].as_f64().unwrap(), p["std_error"].as_f64());
                let Some(se) = se.filter(|se| *se < 0.5 * value.abs()) else {
                    continue;
                };
                let k = names.iter().position(|n| *n == name).unwrap();
                let what = format!("{drive} {law} {name}");
                close(&what, value, reference["values"][k].as_f64().unwrap(), 0.01);
                close(
                    &format!("{what} SE"),
                    se,
                    reference["se"][k].as_f64().unwrap(),
                    0.01,
                );
            }
        }
        if drive == "driveNo1" {
            assert_eq!(
                got["laws"]["selected"], want["selected"],
                "{drive}: law selected"
            );
        }
    }
}

/// The shared worm drive's 46 runs (driveNo3, 60:1, ±1 … ±200 rpm). Its efforts carry
/// an offset (Coulomb's Fo ≈ −0.47 mN·m) and, at the two slowest speeds of each
/// direction, a change no Stribeck curve of these runs describes: in the positive
/// direction the effort is *lower* at 1 and 2 rpm than at 6 rpm. So the symmetric
/// Stribeck fit runs off (vs → 1e-56 rad/s, Fs → 114 N·m, unconverged after 500
/// iterations) and the asymmetric one has Fs_pos < Fc_pos: both are not determined
/// and ranked apart, and the law selected is a Coulomb law, said to miss the runs by
/// far more than their own scatter.
#[test]
fn the_worm_map_gives_no_stribeck_law_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let got = evaluated("driveNo3", dir.path());
    let runs = got["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 46);
    // The positive direction's two slowest runs against its 5th and 6th (6, 8 rpm).
    let positive: Vec<f64> = runs
        .iter()
        .filter(|r| r["speed"].as_f64().unwrap() > 0.0)
        .map(|r| r["effort"].as_f64().unwrap())
        .collect();
    assert!(
        positive[0].max(positive[1]) < positive[3].min(positive[4]),
        "{positive:?}"
    );
    let fits = got["laws"]["fits"].as_array().unwrap();
    let fit = |law: &str| fits.iter().find(|f| f["law"] == law).unwrap();
    let ranked: Vec<&str> = got["laws"]["selection"]["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["label"].as_str().unwrap())
        .collect();
    for (law, why) in [
        ("stribeck", "not_converged"),
        ("stribeck_asymmetric", "rise_negative"),
    ] {
        let f = fit(law);
        assert_eq!(f["determined"], false, "{law}: {f}");
        assert!(
            f["notes"].to_string().contains(why),
            "{law}: {}",
            f["notes"]
        );
        assert!(!ranked.contains(&law), "{law} ranked: {ranked:?}");
    }
    for law in ["coulomb", "coulomb_asymmetric"] {
        assert_eq!(fit(law)["determined"], true, "{law}");
        assert!(ranked.contains(&law), "{law} not ranked: {ranked:?}");
    }
    let selected = got["laws"]["selected"].as_str().unwrap();
    assert!(selected.starts_with("coulomb"), "{selected}");
    let ratio = got["misfit"]["ratio"].as_f64().unwrap();
    assert!(ratio > 3.0, "{ratio}");
}
