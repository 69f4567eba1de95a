//! A servo trace that never holds a speed, offered as a friction map: the KUKA KR300's
//! axis 1 (fixtures/real/kuka-kr300/). Its stretches of 10 to 31 samples within 5 % of
//! one speed mid-acceleration, and its standstill, are not runs (docs/import.md §2.1);
//! before issue 37 they were taken as 51 runs and friction laws fitted to them.

use crate::cli_support::{err, ok, root, rtid};

#[test]
fn a_robot_trace_gives_no_runs_mid_acceleration() {
    let dir = tempfile::tempdir().unwrap();
    let csv = root().join("fixtures/real/kuka-kr300/axis1.csv");
    let out = rtid(
        &[
            "import",
            csv.to_str().unwrap(),
            "--kind",
            "friction-map",
            "--map",
            "speed=velocity_deg_per_s:deg/s",
            "--map",
            "effort=torque_nm:N·m",
            "--out",
            "map",
        ],
        dir.path(),
    );
    ok(&out);
    let stderr = String::from_utf8(out.stderr.clone()).unwrap();
    // The accelerations and decelerations are refused for their change of speed, the
    // standstill before the start as rest.
    let held = stderr
        .matches("not a held speed: the speed changes by")
        .count();
    assert!(held >= 40, "{held}: {stderr}");
    assert_eq!(
        stderr.matches("at rest: median speed").count(),
        5,
        "{stderr}"
    );
    // What passes is the creeping approach to the end position: slower than 0.3 % of
    // the top speed (0.436 rad/s), one direction only — no map a law can be fitted to.
    let e = experiment(&dir.path().join("map/friction_map.json"));
    assert!(e.len() <= 4, "{e:?}");
    assert!(e.iter().all(|&v| v > 0.0 && v < 0.003 * 0.436), "{e:?}");
    let refused = err(&rtid(&["evaluate", "map/friction_map.json"], dir.path()));
    assert!(refused.contains("one direction only"), "{refused}");
}

/// The speeds of a friction-map file's rows.
fn experiment(path: &std::path::Path) -> Vec<f64> {
    match rtid::io::experiment_file::read(path).unwrap().data {
        rtid::io::experiment_file::Data::FrictionMap(m) => m.speed,
        _ => panic!("a friction map"),
    }
}
