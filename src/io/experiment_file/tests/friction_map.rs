//! The `friction_map` kind: its columns in any speed unit, rows sorted by speed, and
//! every cell it refuses named by file, line and column.

use crate::io::experiment_file::units::RPM;
use crate::io::experiment_file::*;

/// Reads `map.json` of kind `friction_map` with `csv` as `map.csv`.
fn read_map(csv: &str) -> Result<Experiment, ExperimentFileError> {
    let dir = tempfile::tempdir().unwrap();
    let manifest = r#"{"kind": "friction_map", "data": "map.csv"}"#;
    std::fs::write(dir.path().join("map.json"), manifest).unwrap();
    std::fs::write(dir.path().join("map.csv"), csv).unwrap();
    read(&dir.path().join("map.json"))
}

fn map(e: &Experiment) -> &FrictionMap {
    match &e.data {
        Data::FrictionMap(m) => m,
        other => panic!("not a friction map: {:?}", other.kind()),
    }
}

fn error(csv: &str) -> String {
    read_map(csv).unwrap_err().to_string()
}

#[test]
fn rpm_columns_read_as_rad_per_second_sorted_by_speed() {
    let csv = "# runs in rpm\nspeed_rpm,torque_nm,speed_std_rpm,samples,note\n\
               10,0.0033,0.5,498,1\n-2,-0.0030,0.25,500,2\n-50,-0.0035,1,497,3\n";
    let e = read_map(csv).unwrap();
    let m = map(&e);
    assert_eq!(m.axis, Axis::Rotary);
    assert_eq!(m.speed, [-50.0 * RPM, -2.0 * RPM, 10.0 * RPM]);
    assert_eq!(m.effort, [-0.0035, -0.0030, 0.0033]);
    assert_eq!(m.speed_std, Some(vec![RPM, 0.25 * RPM, 0.5 * RPM]));
    assert_eq!(m.samples, Some(vec![497.0, 500.0, 498.0]));
    assert_eq!((m.effort_std.as_ref(), m.dropped.as_ref()), (None, None));
    assert_eq!(m.extra["note"], [3.0, 2.0, 1.0]);
    assert_eq!(e.data.axis(), Some(Axis::Rotary));
    assert_eq!(e.data.len(), 3);
}

#[test]
fn a_linear_map_in_mm_per_second_reads_as_metres_per_second() {
    let e = read_map("speed_mm_s,force_n,force_std_n\n-5,-21.5,0.5\n20,24.5,0.25\n").unwrap();
    let m = map(&e);
    assert_eq!(m.axis, Axis::Linear);
    assert_eq!(m.speed, [-0.005, 0.02]);
    assert_eq!(m.effort_std, Some(vec![0.5, 0.25]));
}

#[test]
fn a_map_survives_a_round_trip_in_si_columns() {
    for axis in [Axis::Rotary, Axis::Linear] {
        let mut m = FrictionMap::new(axis, vec![3.5, -1.0 / 3.0, 0.1], vec![2.0, -1.5, 1.0]);
        m.speed_std = Some(vec![0.01, 0.02, 0.03]);
        m.effort_std = Some(vec![0.1, 0.2, 0.3]);
        m.samples = Some(vec![10.0, 11.0, 12.0]);
        m.dropped = Some(vec![0.0, 1.0, 2.0]);
        m.transient = Some(vec![5.0, 0.0, 3.0]);
        m.extra.insert("run_id".into(), vec![1.0, 2.0, 3.0]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map.json");
        let data = Data::FrictionMap(m.clone());
        write(&path, &Manifest::new(Kind::FrictionMap), &data).unwrap();
        let text = std::fs::read_to_string(dir.path().join("map.csv")).unwrap();
        let header = text.lines().nth(1).unwrap();
        let expected = match axis {
            Axis::Rotary => "speed_rad_s,torque_nm,speed_std_rad_s,torque_std_nm,samples,dropped,transient,run_id",
            Axis::Linear => "speed_m_s,force_n,speed_std_m_s,force_std_n,samples,dropped,transient,run_id",
        };
        assert_eq!(header, expected);
        // Written in order of speed, every column along.
        assert!(text
            .lines()
            .nth(2)
            .unwrap()
            .starts_with("-0.3333333333333333,-1.5,"));
        let back = read(&path).unwrap();
        assert_eq!(back.manifest.kind, Kind::FrictionMap);
        assert_eq!(map(&back), &m.sorted());
        assert_eq!(map(&back).extra["run_id"], [2.0, 3.0, 1.0]);
    }
}

#[test]
fn bad_cells_are_named_by_file_line_and_column() {
    let e = error("speed_rad_s,torque_nm\n1,0.1\n2,NaN\n");
    assert!(
        e.contains("map.csv, line 3, column `torque_nm`: `NaN` is not a finite number"),
        "{e}"
    );
    let e = error("speed_rad_s,torque_nm\n1,0.1\ninf,0.2\n");
    assert!(e.contains("line 3, column `speed_rad_s`"), "{e}");
    let e = error("# c\nspeed_rpm,torque_nm\n10,0.1\n-0,0.2\n");
    assert!(
        e.contains("map.csv, line 4, column `speed_rpm`: a speed of 0: a run at rest"),
        "{e}"
    );
    let e = error("speed_rad_s,torque_nm\n1,0.1\n2,0.2\n1,0.3\n");
    assert!(
        e.contains("line 4, column `speed_rad_s`: the same speed as line 2"),
        "{e}"
    );
    let e = error("speed_rad_s,torque_nm,dropped\n1,0.1,0\n2,0.2,1.5\n");
    assert!(
        e.contains("line 3, column `dropped`: 1.5 is not a count"),
        "{e}"
    );
    let e = error("speed_rad_s,torque_nm,samples\n1,0.1,-3\n");
    assert!(e.contains("column `samples`: -3 is not a count"), "{e}");
}

#[test]
fn bad_headers_are_named() {
    let e = error("speed_rpm,force_n\n10,1\n");
    assert!(
        e.contains("column `force_n` is a length or a force (linear) but `speed_rpm`"),
        "{e}"
    );
    let e = error("speed_mm_s,torque_nm,speed_std_rpm\n10,1,1\n");
    assert!(e.contains("rotary"), "{e}");
    let e = error("velocity_rpm,torque_nm\n10,1\n");
    assert!(
        e.contains("missing column `speed_rad_s` (or `speed_rpm`, `speed_deg_s`, `speed_m_s`, `speed_mm_s`)"),
        "{e}"
    );
    let e = error("speed_rpm,speed_rad_s,torque_nm\n10,1,1\n");
    assert!(e.contains("give the same speed"), "{e}");
    let e = error("speed_rpm\n10\n");
    assert!(
        e.contains("missing column `torque_nm` (or `force_n`)"),
        "{e}"
    );
}

#[test]
fn the_writer_refuses_a_map_that_would_not_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.json");
    let manifest = Manifest::new(Kind::FrictionMap);
    let refused = |m: FrictionMap| {
        let e = write(&path, &manifest, &Data::FrictionMap(m)).unwrap_err();
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
        e.to_string()
    };
    let e = refused(FrictionMap::new(
        Axis::Rotary,
        vec![1.0, 0.0],
        vec![1.0, 0.0],
    ));
    assert!(e.contains("a speed of 0"), "{e}");
    let e = refused(FrictionMap::new(
        Axis::Rotary,
        vec![1.0, 1.0],
        vec![1.0, 2.0],
    ));
    assert!(e.contains("the same speed"), "{e}");
    let e = refused(FrictionMap::new(
        Axis::Rotary,
        vec![1.0, f64::NAN],
        vec![1.0, 2.0],
    ));
    assert!(e.contains("not finite"), "{e}");
    let mut m = FrictionMap::new(Axis::Linear, vec![1.0, 2.0], vec![1.0, 2.0]);
    m.extra.insert("force_std_n".into(), vec![0.0, 0.0]);
    let e = refused(m);
    assert!(e.contains("clashes with a data column"), "{e}");
}
