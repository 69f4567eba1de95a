//! A servo trace that never holds a speed, offered as a friction map: the KUKA KR300's
//! axis 1, row 1 of the lab's MAT-file (fixtures/formats/matlab/kuka/). Its stretches of 10 to 31 samples within 5 % of
//! one speed mid-acceleration, and its standstill, are not runs (docs/import.md §2.1);
//! before issue 37 they were taken as 51 runs and friction laws fitted to them.

use crate::cli_support::{err, root, rtid};

#[test]
fn a_robot_trace_gives_no_runs_mid_acceleration() {
    let dir = tempfile::tempdir().unwrap();
    let mat = root().join("fixtures/formats/matlab/kuka/kuka_kr300_ff_a.mat");
    let out = rtid(
        &[
            "import",
            mat.to_str().unwrap(),
            "--kind",
            "friction-map",
            "--map",
            "speed=rec.act_vel_mot_deg_per_s(1,:):deg/s",
            "--map",
            "effort=rec.act_torque_abs_nm(1,:):N·m",
            "--out",
            "map",
        ],
        dir.path(),
    );
    let refused = err(&out);
    // The accelerations and decelerations are refused for their change of speed, the
    // standstill before the start as rest; what passes is the creeping approach to the
    // end position (slower than 0.3 % of the top speed), one direction only — no map,
    // and the one error says so.
    assert!(
        refused.contains("hold their speed, all in the positive direction")
            && refused.contains("a friction map needs runs both ways")
            && refused.contains("change their speed within the run")
            && refused.contains("at rest"),
        "{refused}"
    );
    let others: usize = refused
        .split("of the other ")
        .nth(1)
        .and_then(|rest| rest.split(',').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(others >= 40, "{others}: {refused}");
    assert!(refused.len() < 1024, "{} bytes", refused.len());
    assert!(!dir.path().join("map/friction_map.json").exists());
}
