//! The friction map end to end: a virtual map of a preset with a known Stribeck law
//! (1 % noise on the torque samples) gives the law back — by the direct fit of
//! `rtid evaluate` and by identification through the model — and maps no law can be
//! fitted to are refused naming the file.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::cli_support::{err, ok, rtid};

/// The direct drive's table with a Stribeck law and a load: Coulomb 1.5 N·m, static
/// 2.0 N·m, Stribeck speed 0.2 rad/s, δ = 1, viscous 0.3 N·m·s/rad, Tload 0.3 N·m.
const TRUTH: [(&str, f64); 6] = [
    ("ft", 1.5),
    ("fst", 0.5),
    ("vst", 0.2),
    ("stribeck_shape", 1.0),
    ("Ct", 0.3),
    ("Tload", 0.3),
];

fn virtual_map(dir: &Path, seed: &str) -> PathBuf {
    let mut args = vec![
        "experiment",
        "friction-map",
        "--preset",
        "direct-drive",
        "--speeds-rpm",
        "0.5,1,2,5,10,20,50,100",
        "--noise-percent",
        "1",
        "--seed",
        seed,
        "--out",
        "map",
        "--quiet",
        "--json",
    ];
    let sets: Vec<String> = TRUTH.iter().map(|(n, v)| format!("{n}={v}")).collect();
    for s in &sets {
        args.extend(["--set", s]);
    }
    ok(&rtid(&args, dir));
    dir.join("map/friction_map.json")
}

fn within(name: &str, got: f64, truth: f64, tolerance: f64) {
    assert!(
        ((got - truth) / truth).abs() < tolerance,
        "{name}: {got} against {truth}"
    );
}

#[test]
fn a_virtual_map_gives_its_stribeck_law_back_directly_and_through_the_model() {
    for seed in ["1", "2"] {
        let dir = tempfile::tempdir().unwrap();
        let map = virtual_map(dir.path(), seed);
        // The direct fit: the symmetric Stribeck law is selected, each value within 2 %.
        let out = ok(&rtid(
            &["evaluate", map.to_str().unwrap(), "--json"],
            dir.path(),
        ));
        let e: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(e["laws"]["selected"], "stribeck", "seed {seed}");
        let fit = e["laws"]["fits"]
            .as_array()
            .unwrap()
            .iter()
            .find(|f| f["law"] == "stribeck")
            .unwrap();
        let value = |name: &str| {
            fit["parameters"]
                .as_array()
                .unwrap()
                .iter()
                .find(|p| p["name"] == name)
                .unwrap()["value"]
                .as_f64()
                .unwrap()
        };
        // At the motor of a direct drive: Fc = ft, Fs = ft + fst, Fv = Ct, Fo = −Tload.
        for (name, truth) in [
            ("Fc", 1.5),
            ("Fs", 2.0),
            ("vs", 0.2),
            ("delta", 1.0),
            ("Fv", 0.3),
            ("Fo", -0.3),
        ] {
            within(name, value(name), truth, 0.02);
        }
        // Through the model, from the preset's values (the search starts at the direct
        // fit carried onto the model) and from the preset alone (`--start given`; the
        // preset's Tload of 0 needs bounds).
        for start in ["estimate", "given"] {
            let fit = dir.path().join(format!("fit-{start}.json"));
            ok(&rtid(
                &[
                    "identify",
                    map.to_str().unwrap(),
                    "--preset",
                    "direct-drive",
                    "--set",
                    "fst=0.2",
                    "--set",
                    "vst=0.5",
                    "--fit",
                    "ft,fst,vst,stribeck_shape,Ct,Tload",
                    "--start",
                    start,
                    "--bound",
                    "Tload=-2..2",
                    "--out",
                    fit.to_str().unwrap(),
                    "--quiet",
                ],
                dir.path(),
            ));
            let r: Value = serde_json::from_str(&std::fs::read_to_string(&fit).unwrap()).unwrap();
            assert_eq!(r["termination"]["code"], "converged", "{start}: {r}");
            for (name, truth) in TRUTH {
                within(name, r["parameters"][name].as_f64().unwrap(), truth, 0.02);
            }
        }
    }
}

/// A map file of the given rows (rad/s, N·m) in `dir`.
fn map_file(dir: &Path, name: &str, rows: &[(f64, f64)]) -> PathBuf {
    let csv: String = rows.iter().map(|(v, t)| format!("{v},{t}\n")).collect();
    std::fs::write(
        dir.join(format!("{name}.csv")),
        format!("speed_rad_s,torque_nm\n{csv}"),
    )
    .unwrap();
    let manifest = dir.join(format!("{name}.json"));
    std::fs::write(&manifest, r#"{"kind": "friction_map"}"#).unwrap();
    manifest
}

#[test]
fn maps_no_law_can_be_fitted_to_are_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let law = |v: f64| 0.3f64.copysign(v) + 0.01 * v;
    let cases: [(&str, Vec<f64>, &str); 3] = [
        ("one_direction", vec![1.0, 2.0, 5.0, 10.0], "direction"),
        ("single_speed", vec![-5.0, 1.0, 2.0, 5.0], "single speed"),
        ("one_sign", vec![-5.0, -2.0, 2.0, 5.0], "sign"),
    ];
    for (name, speeds, says) in cases {
        let rows: Vec<(f64, f64)> = speeds
            .iter()
            .map(|&v| {
                (
                    v,
                    if name == "one_sign" {
                        law(v).abs()
                    } else {
                        law(v)
                    },
                )
            })
            .collect();
        let file = map_file(dir.path(), name, &rows);
        for command in [
            vec!["evaluate", file.to_str().unwrap()],
            vec![
                "identify",
                file.to_str().unwrap(),
                "--preset",
                "direct-drive",
                "--fit",
                "ft,Ct",
                "--out",
                "fit.json",
                "--quiet",
            ],
        ] {
            let e = err(&rtid(&command, dir.path()));
            assert!(
                e.contains(&format!("{name}.json")) && e.to_lowercase().contains(says),
                "{name}, {}: {e}",
                command[0]
            );
        }
    }
}
