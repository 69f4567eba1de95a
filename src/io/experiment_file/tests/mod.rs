use super::units::ARCSEC;
use super::*;
use crate::model::params::LoopMode;

mod friction_map;
mod units;

/// Writes `files` (name, text) into a fresh folder; returns it and the path of the first.
fn files(files: &[(&str, &str)]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let first = dir.path().join(files[0].0);
    (dir, first)
}

/// Reads a manifest `run.json` of `kind` with `csv` as `run.csv`.
fn read_csv(kind: &str, csv: &str) -> Result<Experiment, ExperimentFileError> {
    let manifest = format!(r#"{{"kind": "{kind}", "data": "run.csv"}}"#);
    let (_dir, path) = files(&[("run.json", &manifest), ("run.csv", csv)]);
    read(&path)
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-12 * x.abs().max(y.abs()))
}

/// Awkward numbers: thirds, tiny, huge, negative, zero.
fn series(n: usize, offset: f64) -> Vec<f64> {
    (0..n)
        .map(|i| offset + (i as f64 - 2.0) / 3.0 * 10f64.powi(i as i32 % 7 - 3))
        .collect()
}

fn times(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64 * 1e-4 + 1.0 / 3.0).collect()
}

fn extra(n: usize) -> Columns {
    Columns::from([("contact_loss_drive".to_string(), series(n, 0.5))])
}

/// One data set per kind.
fn samples() -> Vec<Data> {
    let n = 9;
    vec![
        Data::FrequencyResponse {
            frequency_hz: (1..=n).map(|i| 10.0 * i as f64 + 0.1).collect(),
            gain_db: series(n, -20.0),
            phase_rad: Some(series(n, -1.0)),
            extra: extra(n),
        },
        Data::Resonance {
            peaks_hz: vec![231.5, 1.0 / 3.0 * 1000.0],
            peak_gain_db: Some(vec![12.25, -3.1]),
        },
        Data::TorqueCurve {
            time_s: times(n),
            motor_torque_nm: series(n, 0.0),
            table_angle_rad: Some(series(n, 0.2)),
            extra: Columns::new(),
        },
        Data::Positioning {
            target_rad: (0..n)
                .map(|i| (i / 2) as f64 * 30f64.to_radians())
                .collect(),
            direction: (0..n)
                .map(|i| {
                    if i % 2 == 0 {
                        Direction::Up
                    } else {
                        Direction::Down
                    }
                })
                .collect(),
            run: (1..=n as u32).collect(),
            deviation_rad: series(n, 0.0).iter().map(|x| x * 1e-5).collect(),
            extra: extra(n),
        },
        Data::Fluctuation {
            time_s: times(n),
            motor_angle_rad: series(n, 100.0),
            table_angle_rad: series(n, 1.0),
            extra: Columns::new(),
        },
        Data::Unbalance {
            time_s: times(n),
            motor_angle_rad: series(n, -7.0),
            table_angle_rad: series(n, 3.0),
            extra: extra(n),
        },
        Data::FrequencyResponseTime {
            time_s: times(n),
            motor_torque_nm: series(n, 5.0),
            motor_angle_rad: series(n, -0.1),
            table_angle_rad: series(n, 2e-4),
            extra: extra(n),
        },
        Data::ForceCurve {
            time_s: times(n),
            force_n: series(n, 20.0),
            table_position_m: Some(series(n, 0.1)),
            extra: extra(n),
        },
        Data::LinearPositioning {
            target_m: (0..n).map(|i| (i / 2) as f64 * 0.025).collect(),
            direction: (0..n)
                .map(|i| {
                    if i % 3 == 0 {
                        Direction::Down
                    } else {
                        Direction::Up
                    }
                })
                .collect(),
            run: (1..=n as u32).rev().collect(),
            deviation_m: series(n, 0.0).iter().map(|x| x * 1e-6).collect(),
            extra: Columns::new(),
        },
        Data::FrequencyResponseTimeCurrent {
            time_s: times(n),
            motor_current_a: series(n, -3.0),
            motor_angle_rad: series(n, 7.0),
            table_angle_rad: series(n, -0.6),
            extra: extra(n),
        },
        servo_trace(Axis::Linear, n),
        servo_trace(Axis::Rotary, n),
        friction_map(Axis::Rotary, n),
        friction_map(Axis::Linear, n),
    ]
}

/// A friction map, rows not in order of speed; rotary with every optional column,
/// linear with none but an extra one.
fn friction_map(axis: Axis, n: usize) -> Data {
    let mut m = FrictionMap::new(axis, series(n, -0.5), series(n, 0.25));
    if axis == Axis::Rotary {
        m.speed_std = Some(series(n, 1.0));
        m.effort_std = Some(series(n, 2.0));
        m.samples = Some((0..n).map(|i| (100 + i) as f64).collect());
        m.dropped = Some((0..n).map(|i| (i % 3) as f64).collect());
        m.transient = Some((0..n).map(|i| (2 * i) as f64).collect());
    } else {
        m.extra = extra(n);
    }
    Data::FrictionMap(m)
}

/// A servo trace with every optional column.
fn servo_trace(axis: Axis, n: usize) -> Data {
    let unit = match axis {
        Axis::Rotary => CommandUnit::NewtonMetre,
        Axis::Linear => CommandUnit::Volt,
    };
    Data::ServoTrace(ServoTrace {
        axis,
        time_s: times(n),
        reference_position: series(n, 1e-3),
        position: series(n, 2e-3),
        table_position: Some(series(n, 3e-3)),
        effort: series(n, 50.0),
        controller_output: Some(Signal {
            unit,
            values: series(n, 1.0),
        }),
        controller_added: Some(Signal {
            unit,
            values: series(n, 0.1),
        }),
        extra: extra(n),
    })
}

/// A servo trace's series, absent signals empty.
fn servo_numbers(t: &ServoTrace) -> Vec<Vec<f64>> {
    let signal = |s: &Option<Signal>| s.as_ref().map_or(vec![], |s| s.values.clone());
    vec![
        t.time_s.clone(),
        t.reference_position.clone(),
        t.position.clone(),
        t.table_position.clone().unwrap_or_default(),
        t.effort.clone(),
        signal(&t.controller_output),
        signal(&t.controller_added),
    ]
}

/// A friction map's series in order of speed (as the reader returns its rows), its
/// extra columns included.
fn map_numbers(m: &FrictionMap) -> Vec<Vec<f64>> {
    let m = m.sorted();
    let mut v = vec![m.speed, m.effort];
    let optional = [m.speed_std, m.effort_std, m.samples, m.dropped, m.transient];
    v.extend(optional.into_iter().map(Option::unwrap_or_default));
    v.extend(m.extra.into_values());
    v
}

/// The numeric series of `data` in a fixed order, for comparison within 1e-12.
fn numbers(data: &Data) -> Vec<Vec<f64>> {
    let mut v = match data {
        Data::FrequencyResponse {
            frequency_hz,
            gain_db,
            phase_rad,
            ..
        } => vec![
            frequency_hz.clone(),
            gain_db.clone(),
            phase_rad.clone().unwrap_or_default(),
        ],
        Data::Resonance {
            peaks_hz,
            peak_gain_db,
        } => vec![peaks_hz.clone(), peak_gain_db.clone().unwrap_or_default()],
        Data::TorqueCurve {
            time_s,
            motor_torque_nm,
            table_angle_rad,
            ..
        } => vec![
            time_s.clone(),
            motor_torque_nm.clone(),
            table_angle_rad.clone().unwrap_or_default(),
        ],
        Data::Positioning {
            target_rad: target,
            deviation_rad: deviation,
            run,
            ..
        }
        | Data::LinearPositioning {
            target_m: target,
            deviation_m: deviation,
            run,
            ..
        } => vec![
            target.clone(),
            deviation.clone(),
            run.iter().map(|&r| r as f64).collect(),
        ],
        Data::ForceCurve {
            time_s,
            force_n,
            table_position_m,
            ..
        } => vec![
            time_s.clone(),
            force_n.clone(),
            table_position_m.clone().unwrap_or_default(),
        ],
        Data::Fluctuation {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            ..
        }
        | Data::Unbalance {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            ..
        } => vec![
            time_s.clone(),
            motor_angle_rad.clone(),
            table_angle_rad.clone(),
        ],
        Data::FrequencyResponseTime {
            time_s,
            motor_torque_nm: input,
            motor_angle_rad,
            table_angle_rad,
            ..
        }
        | Data::FrequencyResponseTimeCurrent {
            time_s,
            motor_current_a: input,
            motor_angle_rad,
            table_angle_rad,
            ..
        } => vec![
            time_s.clone(),
            input.clone(),
            motor_angle_rad.clone(),
            table_angle_rad.clone(),
        ],
        Data::ServoTrace(t) => servo_numbers(t),
        Data::FrictionMap(m) => return map_numbers(m),
    };
    v.extend(data.extra().into_iter().flat_map(|e| e.values().cloned()));
    v
}

#[test]
fn every_kind_survives_a_round_trip() {
    for data in samples() {
        let kind = data.kind();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(format!("{kind}.json"));
        let mut manifest = Manifest::new(kind);
        manifest.mechanism = Some("worm-gear".into());
        manifest.notes = Some("round trip".into());
        manifest.conditions = Conditions::default().with_defaults(kind);
        if kind == Kind::FrequencyResponseTime {
            manifest.conditions.frequencies_hz = Some(vec![10.0, 1.0 / 3.0]);
            manifest.conditions.dwell_s = Some(0.25);
            manifest.conditions.excitation = Some(Excitation::SteppedSine);
        }
        write(&path, &manifest, &data).unwrap();
        let back = read(&path).unwrap();
        assert_eq!(back.data.kind(), kind);
        assert_eq!(back.data.axis(), data.axis(), "{kind}");
        assert_eq!(
            std::mem::discriminant(&back.data),
            std::mem::discriminant(&data),
            "{kind}"
        );
        if let (Data::ServoTrace(a), Data::ServoTrace(b)) = (&data, &back.data) {
            let units = |t: &ServoTrace| t.controller_output.as_ref().map(|s| s.unit);
            assert_eq!(units(a), units(b));
        }
        let (a, b) = (numbers(&data), numbers(&back.data));
        assert_eq!(a.len(), b.len(), "{kind}");
        for (x, y) in a.iter().zip(&b) {
            assert!(close(x, y), "{kind}: {x:?} != {y:?}");
        }
        if let (
            Data::Positioning {
                direction: d1,
                extra: e1,
                ..
            }
            | Data::LinearPositioning {
                direction: d1,
                extra: e1,
                ..
            },
            Data::Positioning {
                direction: d2,
                extra: e2,
                ..
            }
            | Data::LinearPositioning {
                direction: d2,
                extra: e2,
                ..
            },
        ) = (&data, &back.data)
        {
            assert_eq!(
                (d1, e1.keys().collect::<Vec<_>>()),
                (d2, e2.keys().collect())
            );
        }
        // The written manifest names its CSV; everything else comes back as given.
        let mut expected = manifest.clone();
        if kind.has_data_file() {
            expected.data = Some(format!("{kind}.csv"));
            assert_eq!(back.data_path, Some(dir.path().join(format!("{kind}.csv"))));
        } else {
            expected.peaks_hz = back.manifest.peaks_hz.clone();
            expected.peak_gain_db = back.manifest.peak_gain_db.clone();
            assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        }
        assert_eq!(back.manifest, expected);
        assert_eq!(back.path, path);
    }
}

#[test]
fn a_round_trip_keeps_extra_keys_conditions_and_columns() {
    let text = r#"{
        "kind": "fluctuation",
        "data": "sub.csv",
        "conditions": {"speed_deg_per_min": 180, "ratio": 0.0125, "operator": "K.", "temp_c": 21.5},
        "rig": {"encoder": "RCN 8580", "lines": 32768},
        "version": 3
    }"#;
    let csv =
        "time_s,motor_angle_deg,table_angle_deg,contact_loss_drive\n0,0,0,0\n0.5,90,1.125,0.25\n";
    let (dir, path) = files(&[("a.json", text), ("sub.csv", csv)]);
    let first = read(&path).unwrap();
    let m = &first.manifest;
    assert_eq!(m.conditions.ratio, Some(0.0125));
    assert_eq!(m.conditions.extra["operator"], "K.");
    assert_eq!(m.conditions.extra["temp_c"], 21.5);
    assert_eq!(m.extra["rig"]["lines"], 32768);
    assert_eq!(m.extra["version"], 3);
    assert_eq!(
        first.data.extra().unwrap()["contact_loss_drive"],
        [0.0, 0.25]
    );

    let again = dir.path().join("b.json");
    write(&again, m, &first.data).unwrap();
    let second = read(&again).unwrap();
    assert_eq!(second.manifest, first.manifest);
    assert_eq!(second.data, first.data);
}

#[test]
fn degrees_radians_and_arcseconds_give_the_same_radians() {
    let angles_deg = [0.0, 1.0 / 3.0, -45.0, 359.999, 1e-6];
    let as_csv = |unit: &str, per_deg: f64| {
        let mut s = format!("time_s,motor_angle_{unit},table_angle_{unit}\n");
        for (i, a) in angles_deg.iter().enumerate() {
            s += &format!("{i},{:?},{:?}\n", a * per_deg * 2.0, a * per_deg);
        }
        s
    };
    let table = |csv: String| match read_csv("unbalance", &csv).unwrap().data {
        Data::Unbalance {
            motor_angle_rad,
            table_angle_rad,
            ..
        } => (motor_angle_rad, table_angle_rad),
        other => panic!("{other:?}"),
    };
    let (m_deg, t_deg) = table(as_csv("deg", 1.0));
    let (m_rad, t_rad) = table(as_csv("rad", std::f64::consts::PI / 180.0));
    let (m_sec, t_sec) = table(as_csv("arcsec", 3600.0));
    let expected: Vec<f64> = angles_deg.iter().map(|a| a.to_radians()).collect();
    for t in [&t_deg, &t_rad, &t_sec] {
        assert!(close(t, &expected), "{t:?} != {expected:?}");
    }
    for m in [&m_deg, &m_rad, &m_sec] {
        assert!(close(
            m,
            &expected.iter().map(|x| 2.0 * x).collect::<Vec<_>>()
        ));
    }
}

#[test]
fn positioning_deviation_is_measured_minus_target_in_any_unit() {
    let from = |csv: &str| match read_csv("positioning", csv).unwrap().data {
        Data::Positioning {
            target_rad,
            direction,
            run,
            deviation_rad,
            extra,
        } => (target_rad, direction, run, deviation_rad, extra),
        other => panic!("{other:?}"),
    };
    // 30° ± 2⁻¹⁰° and 2⁻¹¹°: exact in binary, so the expected deviation is exact too.
    let measured =
        "target_deg,direction,run,measured_deg\n30,up,1,30.0009765625\n30,CW,2.0,29.99951171875\n";
    let (target, direction, run, deviation, _) = from(measured);
    assert!(close(&target, &[30f64.to_radians(); 2]));
    assert_eq!(direction, [Direction::Up, Direction::Down]);
    assert_eq!(run, [1, 2]);
    let expected = [1.0f64 / 1024.0, -1.0 / 2048.0].map(f64::to_radians);
    assert!(
        close(&deviation, &expected),
        "{deviation:?} != {expected:?}"
    );

    let arcsec = "target_rad,direction,run,deviation_arcsec\n0.5235987755982988,ccw,1,3.515625\n0.5235987755982988,Down,2,-1.7578125\n";
    assert!(close(&from(arcsec).3, &expected));
    let mixed = "target_deg,direction,run,measured_rad\n30,up,1,0.5235987755982988\n";
    assert!(from(mixed).3[0].abs() < 1e-15);

    // Both given: the deviation column is used, the measured one kept as an extra.
    let both = "target_deg,direction,run,measured_deg,deviation_arcsec\n30,up,1,99,3.515625\n";
    let (.., deviation, extra) = from(both);
    assert!(close(&deviation, &expected[..1]));
    assert_eq!(extra["measured_deg"], [99.0]);
}

#[test]
fn directions_accept_up_down_ccw_cw_in_any_case() {
    for (text, expected) in [
        ("up", Direction::Up),
        ("CCW", Direction::Up),
        ("Ccw", Direction::Up),
        ("DOWN", Direction::Down),
        ("cw", Direction::Down),
        (" Cw ", Direction::Down),
    ] {
        assert_eq!(text.parse::<Direction>(), Ok(expected), "{text}");
    }
    assert!("left".parse::<Direction>().is_err());
}

#[test]
fn comments_blank_lines_extra_and_text_columns_are_accepted() {
    let csv = "# recorded 2026-11-02 on table 3\n\
               # torque from the drive\n\
               stamp, time_s , motor_torque_nm,spare,table_angle_deg,\n\
               # a comment between rows\n\
               12:00:00,0,1.5,7,0,\n\
               \n\
               12:00:01, 0.1 ,-2,8,1,\n";
    let e = read_csv("torque_curve", csv).unwrap();
    let Data::TorqueCurve {
        time_s,
        motor_torque_nm,
        table_angle_rad,
        extra,
    } = e.data
    else {
        panic!("{:?}", e.data)
    };
    assert_eq!(time_s, [0.0, 0.1]);
    assert_eq!(motor_torque_nm, [1.5, -2.0]);
    assert!(close(&table_angle_rad.unwrap(), &[0.0, 1f64.to_radians()]));
    // The text column is left out, the numeric one kept; the unnamed one ignored.
    assert_eq!(
        extra,
        Columns::from([("spare".to_string(), vec![7.0, 8.0])])
    );
}

#[test]
fn a_missing_data_key_means_the_manifest_name_with_csv() {
    let csv = "frequency_hz,gain_db\n100,-3\n";
    let (_dir, path) = files(&[
        ("sweep.json", r#"{"kind":"frequency_response"}"#),
        ("sweep.csv", csv),
    ]);
    let e = read(&path).unwrap();
    assert_eq!(e.data.len(), 1);
    assert_eq!(e.data_path, Some(path.with_extension("csv")));
}

#[test]
fn conditions_take_the_documented_defaults() {
    let given = Conditions {
        speed_deg_per_min: Some(90.0),
        ..Conditions::default()
    };
    let c = given.with_defaults(Kind::Unbalance);
    assert_eq!(c.speed_deg_per_min, Some(90.0));
    assert_eq!(c.loop_mode, Some(LoopMode::SemiClosed));
    assert_eq!(c.ratio, None);
    let t = Conditions::default().with_defaults(Kind::TorqueCurve);
    assert_eq!(
        (t.amplitude_deg, t.period_s, t.loop_mode),
        (Some(30.0), Some(3.0), Some(LoopMode::FullClosed))
    );
    let f = Conditions::default().with_defaults(Kind::FrequencyResponse);
    assert_eq!(f.torque_amplitude_nm, Some(5.0));
    assert_eq!(
        Conditions::default()
            .with_defaults(Kind::Fluctuation)
            .speed_deg_per_min,
        Some(180.0)
    );
    assert_eq!(
        Conditions::default()
            .with_defaults(Kind::Positioning)
            .dwell_s,
        Some(1.0)
    );
}

#[test]
fn malformed_csv_files_name_file_line_and_column() {
    let fr = "frequency_response";
    let tc = "torque_curve";
    let pos = "positioning";
    for (kind, csv, expected) in [
        (fr, "frequency_hz,gain\n10,1\n", "run.csv, line 1: missing column `gain_db` (header: frequency_hz,gain)"),
        (tc, "# c\ntime_s,motor_torque_nm\n0,1\n0.1,abc\n", "run.csv, line 4, column `motor_torque_nm`: `abc` is not a number"),
        (tc, "time_s,motor_torque_nm\n0,1\n0.1,\n", "line 3, column `motor_torque_nm`: empty cell"),
        (tc, "time_s,motor_torque_nm\n0,1\n0.1,NaN\n", "line 3, column `motor_torque_nm`: `NaN` is not a finite number"),
        (tc, "time_s,motor_torque_nm\n0,1\n0.1,-inf\n", "line 3, column `motor_torque_nm`: `-inf` is not a finite number"),
        (tc, "time_s,motor_torque_nm\n0,1\n0,2\n", "line 3, column `time_s`: 0 does not increase (previous row 0)"),
        (fr, "frequency_hz,gain_db\n20,1\n10,2\n", "line 3, column `frequency_hz`: 10 does not increase"),
        (tc, "", "run.csv, line 1: no header row"),
        (tc, "# only a comment\n", "no header row"),
        (tc, "time_s,motor_torque_nm\n# no rows\n", "run.csv, line 1: no data rows"),
        (tc, "time_s,motor_torque_nm\n0,1\n0.1,2,3\n", "run.csv, line 3: 3 fields where the rows before have 2"),
        (tc, "time_s,motor_torque_nm,time_s\n0,1,0\n", "line 1: column `time_s` appears twice"),
        (tc, "time_s,motor_torque_nm,table_angle_deg,table_angle_rad\n0,1,0,0\n", "columns `table_angle_deg` and `table_angle_rad` give the same angle"),
        ("fluctuation", "time_s,motor_angle_deg\n0,1\n", "missing column `table_angle_deg` (or `table_angle_rad`, `table_angle_arcsec`) (header: time_s,motor_angle_deg)"),
        (pos, "target_deg,direction,run\n0,up,1\n", "missing column `measured_deg` (or `measured_rad`, `measured_arcsec`, `measured_m`, `measured_mm`, `measured_um`, `deviation_deg`, `deviation_rad`, `deviation_arcsec`, `deviation_m`, `deviation_mm`, `deviation_um`)"),
        (pos, "target_deg,direction,run,measured_deg\n0,up,1,0\n0,sideways,1,0\n", "line 3, column `direction`: unknown direction `sideways`: expected up, down, ccw or cw"),
        (pos, "target_deg,direction,run,measured_deg\n0,up,0,0\n", "line 2, column `run`: run 0: runs are numbered from 1"),
        (pos, "target_deg,direction,run,measured_deg\n0,up,-1,0\n", "line 2, column `run`: `-1` is not a run number"),
        (pos, "target_deg,direction,run,measured_deg\n0,up,1.5,0\n", "line 2, column `run`: `1.5` is not a run number"),
        (pos, "target_deg,direction,run,deviation_arcsec\n0,up,1,1\n0,up,2,1e7\n", "line 3, column `deviation_arcsec`: a deviation of 4.848"),
        (pos, "target_mm,direction,run,measured_mm\n0,up,1,1\n10,up,1,2000\n", "line 3, column `measured_mm`: a deviation of 1.99e0 (SI) is beyond 1 m"),
    ] {
        let err = read_csv(kind, csv).unwrap_err().to_string();
        assert!(err.contains(expected), "{csv:?}:\n  got  {err}\n  want {expected}");
    }
}

/// The raw frequency-response record: every fault names file, line and column.
#[test]
fn malformed_frequency_response_records_name_file_line_and_column() {
    let k = "frequency_response_time";
    let head = "time_s,motor_torque_nm,motor_angle_deg,table_angle_deg\n";
    let ok_rows = "0,1,0,0\n0.001,1,0.1,0.001\n0.002,1,0.2,0.002\n";
    let with = |rows: &str| format!("{head}{rows}");
    for (csv, expected) in [
        (
            "time_s,motor_angle_deg,table_angle_deg\n0,0,0\n".to_string(),
            "run.csv, line 1: missing column `motor_torque_nm` (or `motor_current_a`) (header: time_s,motor_angle_deg,table_angle_deg)".to_string(),
        ),
        (
            "time_s,motor_torque_nm,table_angle_deg\n0,0,0\n".into(),
            "run.csv, line 1: missing column `motor_angle_deg` (or `motor_angle_rad`, `motor_angle_arcsec`)".into(),
        ),
        (
            "time_s,motor_torque_nm,motor_angle_deg\n0,0,0\n".into(),
            "run.csv, line 1: missing column `table_angle_deg` (or `table_angle_rad`, `table_angle_arcsec`, `load_angle_deg`, `load_angle_rad`, `load_angle_arcsec`)".into(),
        ),
        (
            "time_s,motor_torque_nm,motor_angle_deg,motor_angle_rad,table_angle_deg\n0,0,0,0,0\n".into(),
            "run.csv, line 1: columns `motor_angle_deg` and `motor_angle_rad` give the same angle".into(),
        ),
        (
            with("0,1,0,0\n0.001,x,0,0\n"),
            "run.csv, line 3, column `motor_torque_nm`: `x` is not a number".into(),
        ),
        (
            with("0,1,0,0\n0.001,1,NaN,0\n"),
            "run.csv, line 3, column `motor_angle_deg`: `NaN` is not a finite number".into(),
        ),
        (
            with("0,1,0,0\n0.001,1,0,\n"),
            "run.csv, line 3, column `table_angle_deg`: empty cell".into(),
        ),
        (
            with("0,1,0,0\n0.001,1,0,0\n0.001,1,0,0\n"),
            "run.csv, line 4, column `time_s`: 0.001 does not increase (previous row 0.001)".into(),
        ),
        (
            // A dropped sample: the step doubles at line 5 (comment on line 2).
            format!("{head}# c\n{ok_rows}0.004,1,0,0\n0.005,1,0,0\n"),
            "run.csv, line 6, column `time_s`: the step from the previous row is 2.000000e-3 s where the record steps 1.000000e-3 s".into(),
        ),
        (
            with("0,1,0,0\n0.001,1,0,0\n0.00206,1,0,0\n0.003,1,0,0\n0.004,1,0,0\n"),
            "run.csv, line 4, column `time_s`: the step from the previous row is 1.060000e-3 s".into(),
        ),
        (
            with("0,1,0,0\n0.001,1,0\n"),
            "run.csv, line 3: 3 fields where the rows before have 4".into(),
        ),
        (head.to_string(), "run.csv, line 1: no data rows".into()),
    ] {
        let err = read_csv(k, &csv).unwrap_err().to_string();
        assert!(err.contains(&expected), "{csv:?}:\n  got  {err}\n  want {expected}");
    }
    // Rounding of the times within the tolerance (2 %) is accepted.
    let jitter = with("0,1,0,0\n0.00102,1,0,0\n0.002,1,0,0\n0.00299,1,0,0\n");
    assert_eq!(read_csv(k, &jitter).unwrap().data.len(), 4);
    // The conditions a stepped sine needs, named.
    let csv = with(ok_rows);
    for (conditions, expected) in [
        (r#"{"excitation": "stepped_sine", "dwell_s": 1}"#, "m.json: a stepped-sine record needs `conditions.frequencies_hz`"),
        (r#"{"frequencies_hz": [10, 20]}"#, "m.json: a stepped-sine record needs `conditions.dwell_s`"),
        (r#"{"frequencies_hz": [10, -20], "dwell_s": 1}"#, "m.json: `conditions.frequencies_hz` holds -20"),
        (r#"{"frequencies_hz": [10], "dwell_s": 0}"#, "m.json: `conditions.dwell_s` is 0"),
        (r#"{"ratio": -0.01}"#, "m.json: `conditions.ratio` is -0.01"),
        (r#"{"excitation": "sweep"}"#, "m.json, line 1, column 91: unknown variant `sweep`, expected one of `stepped_sine`, `broadband`, `multisine`"),
    ] {
        let manifest = format!(r#"{{"kind": "{k}", "data": "run.csv", "conditions": {conditions}}}"#);
        let (_dir, path) = files(&[("m.json", &manifest), ("run.csv", &csv)]);
        let err = read(&path).unwrap_err().to_string();
        assert!(err.contains(expected), "{conditions}:\n  got  {err}\n  want {expected}");
    }
    // Broadband needs neither; the writer refuses what the reader would.
    let manifest = format!(r#"{{"kind": "{k}", "data": "run.csv"}}"#);
    let (_dir, path) = files(&[("m.json", &manifest), ("run.csv", &csv)]);
    let e = read(&path).unwrap();
    let c = e
        .manifest
        .conditions
        .with_defaults(Kind::FrequencyResponseTime);
    assert_eq!(c.excitation, Some(Excitation::Broadband));
    let Data::FrequencyResponseTime { mut time_s, .. } = e.data.clone() else {
        panic!("{:?}", e.data)
    };
    time_s[2] = 0.0035;
    let mut bad = e.data.clone();
    if let Data::FrequencyResponseTime { time_s: t, .. } = &mut bad {
        *t = time_s;
    }
    let dir = tempfile::tempdir().unwrap();
    let err = write(&dir.path().join("w.json"), &e.manifest, &bad).unwrap_err();
    assert!(err.to_string().contains("column `time_s`, row 2: the step from the previous row is 1.000000e-3 s where the record steps 2.500000e-3 s"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn malformed_manifests_name_the_file_and_position() {
    for (manifest, expected) in [
        ("{\"kind\": \"frequency\"}", "m.json, line 1, column 20: unknown variant `frequency`, expected one of `frequency_response`"),
        ("{\n  \"data\": \"x.csv\"\n}", "m.json, line 3, column 1: missing field `kind`"),
        ("{\n  \"kind\": \"resonance\",\n  \"peaks_hz\": [1, 2,]\n}", "m.json, line 3, column 21: trailing comma"),
        ("", "m.json, line 1, column 0: EOF while parsing"),
        ("[1]", "m.json, line 1, column 0: invalid type: sequence"),
        ("{\"kind\": \"positioning\", \"conditions\": {\"loop\": \"open\"}}", "m.json, line 1, column 53: unknown variant `open`, expected `semi_closed` or `full_closed`"),
        ("{\"kind\": \"resonance\", \"peaks_hz\": [100, 200], \"peak_gain_db\": [3]}", "m.json: `peaks_hz` has 2 values but `peak_gain_db` has 1"),
        ("{\"kind\": \"resonance\"}", "m.json: a resonance experiment needs `peaks_hz`"),
        ("{\"kind\": \"resonance\", \"peaks_hz\": []}", "m.json: `peaks_hz` is empty"),
        ("{\"kind\": \"resonance\", \"peaks_hz\": [100, 0]}", "m.json: `peaks_hz`[1] = 0: a resonance frequency is positive (Hz)"),
        ("{\"kind\": \"resonance\", \"peaks_hz\": [-100]}", "m.json: `peaks_hz`[0] = -100: a resonance frequency is positive (Hz)"),
        ("{\"kind\": \"resonance\", \"peaks_hz\": [100, 1e308]}", "m.json: `peaks_hz`[1] = 1e308 Hz: above 1 MHz"),
    ] {
        let (_dir, path) = files(&[("m.json", manifest)]);
        let err = read(&path).unwrap_err().to_string();
        assert!(err.contains(expected), "{manifest:?}:\n  got  {err}\n  want {expected}");
    }
}

#[test]
fn a_manifest_pointing_at_a_missing_csv_names_both_files() {
    let (_dir, path) = files(&[("m.json", r#"{"kind": "torque_curve", "data": "gone.csv"}"#)]);
    let err = read(&path).unwrap_err();
    assert!(
        matches!(err, ExperimentFileError::MissingData { .. }),
        "{err:?}"
    );
    let text = err.to_string();
    assert!(
        text.contains("m.json") && text.contains("gone.csv"),
        "{text}"
    );
    let (_dir, path) = files(&[("absent.json", "")]);
    let err = read(&path.with_file_name("nothing.json"))
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("cannot read ") && err.contains("nothing.json"),
        "{err}"
    );
}

#[test]
fn the_writer_refuses_data_that_would_not_read_back_and_writes_nothing() {
    let fr = |f: Vec<f64>, g: Vec<f64>, extra: Columns| Data::FrequencyResponse {
        frequency_hz: f,
        gain_db: g,
        phase_rad: None,
        extra,
    };
    let manifest = Manifest::new(Kind::FrequencyResponse);
    let mut clash = Manifest::new(Kind::FrequencyResponse);
    clash.extra.insert("kind".into(), "x".into());
    let mut nan_condition = Manifest::new(Kind::FrequencyResponse);
    nan_condition.conditions.ratio = Some(f64::NAN);
    let ok = fr(vec![1.0], vec![0.0], Columns::new());
    for (manifest, data, expected) in [
        (
            &manifest,
            fr(vec![1.0, 2.0], vec![0.0], Columns::new()),
            "column `gain_db` has 1 values, `frequency_hz` has 2",
        ),
        (
            &manifest,
            fr(vec![1.0], vec![f64::NAN], Columns::new()),
            "column `gain_db`, row 1: NaN is not finite",
        ),
        (
            &manifest,
            fr(vec![2.0, 1.0], vec![0.0, 0.0], Columns::new()),
            "column `frequency_hz`, row 2: 1 does not increase",
        ),
        (&manifest, fr(vec![], vec![], Columns::new()), "no rows"),
        (
            &manifest,
            fr(
                vec![1.0],
                vec![0.0],
                Columns::from([("phase_rad".into(), vec![0.0])]),
            ),
            "extra column `phase_rad` clashes",
        ),
        (
            &manifest,
            fr(
                vec![1.0],
                vec![0.0],
                Columns::from([(" x".into(), vec![0.0])]),
            ),
            "` x` cannot be a column name",
        ),
        (
            &manifest,
            Data::Resonance {
                peaks_hz: vec![1.0],
                peak_gain_db: None,
            },
            "the manifest says `frequency_response` but the data is `resonance`",
        ),
        (
            &clash,
            ok.clone(),
            "extra key `kind` repeats a manifest key",
        ),
        (&nan_condition, ok.clone(), "condition `ratio` is NaN"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let err = write(&dir.path().join("m.json"), manifest, &data)
            .unwrap_err()
            .to_string();
        assert!(err.contains(expected), "got {err}, want {expected}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "{err}");
    }
    let dir = tempfile::tempdir().unwrap();
    let runs = Data::Positioning {
        target_rad: vec![0.0],
        direction: vec![Direction::Up],
        run: vec![0],
        deviation_rad: vec![0.0],
        extra: Columns::new(),
    };
    let err = write(
        &dir.path().join("p.json"),
        &Manifest::new(Kind::Positioning),
        &runs,
    );
    assert!(err.unwrap_err().to_string().contains("run 0"));
}

/// Every prefix of a valid pair of files, and bytes changed here and there, give Ok or
/// an error: never a panic.
#[test]
fn no_input_makes_the_reader_panic() {
    let manifest =
        br#"{"kind": "positioning", "data": "p.csv", "conditions": {"loop": "semi_closed"}}"#;
    let csv = "# c\ntarget_deg,direction,run,measured_deg,x\n0,up,1,0.001,1\n30,cw,2,29.999,a\n";
    let dir = tempfile::tempdir().unwrap();
    let (m, c) = (dir.path().join("p.json"), dir.path().join("p.csv"));
    std::fs::write(&c, csv).unwrap();
    for end in 0..=manifest.len() {
        std::fs::write(&m, &manifest[..end]).unwrap();
        let _ = read(&m);
    }
    std::fs::write(&m, manifest).unwrap();
    let bytes = csv.as_bytes();
    for end in 0..=bytes.len() {
        std::fs::write(&c, &bytes[..end]).unwrap();
        let _ = read(&m);
    }
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    for _ in 0..2000 {
        let mut b = bytes.to_vec();
        for _ in 0..3 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let i = (state % b.len() as u64) as usize;
            let pool = b",\n#\"-0e.9aup\xff\x00 ";
            b[i] = pool[(state >> 32) as usize % pool.len()];
        }
        std::fs::write(&c, &b).unwrap();
        let _ = read(&m);
    }
}

/// The fenced code blocks of `text` with a language: (language, body).
fn code_blocks(text: &str) -> Vec<(&str, String)> {
    let mut blocks = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if let Some(lang) = line.strip_prefix("```").filter(|l| !l.is_empty()) {
            let body: Vec<&str> = lines
                .by_ref()
                .take_while(|l| !l.starts_with("```"))
                .collect();
            blocks.push((lang, body.join("\n") + "\n"));
        }
    }
    blocks
}

/// docs/experiment-files.md shows a manifest and CSV head per kind (and more for some
/// kinds: each CSV goes with the manifest above it): they must load, and the
/// positioning example's first two forms (deviation, measured) must agree.
#[test]
fn the_documented_examples_load() {
    let doc = include_str!("../../../../docs/experiment-files.md");
    let examples = doc.split("\n## Examples").nth(1).unwrap();
    let examples = examples.split("\n## ").next().unwrap();
    let mut kinds = Vec::new();
    for section in examples.split("\n### ").skip(1) {
        let title = section.lines().next().unwrap().trim();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("example.json");
        let mut manifest: Option<Manifest> = None;
        let mut read_back = Vec::new();
        for (language, body) in code_blocks(section) {
            if language == "json" {
                std::fs::write(&path, &body).unwrap();
                let m = read_manifest(&path).unwrap_or_else(|e| panic!("{title}: {e}"));
                assert_eq!(m.kind.name(), title);
                if manifest.is_none() {
                    kinds.push(m.kind);
                }
                if !m.kind.has_data_file() {
                    assert_eq!(read(&path).unwrap().data.len(), 2);
                }
                manifest = Some(m);
            } else if language == "csv" {
                let m = manifest.as_ref().expect("a CSV example after its manifest");
                std::fs::write(data_path(&path, m), &body).unwrap();
                let e = read(&path).unwrap_or_else(|e| panic!("{title}: {e}"));
                assert_eq!(e.data.len(), 4, "{title}");
                read_back.push(e.data);
            }
        }
        let manifest = manifest.unwrap_or_else(|| panic!("{title} has no manifest"));
        if manifest.kind.has_data_file() {
            assert!(!read_back.is_empty(), "{title} has no CSV example");
        }
        if let [Data::Positioning {
            direction: d1,
            deviation_rad: x1,
            ..
        }, Data::Positioning {
            direction: d2,
            deviation_rad: x2,
            ..
        }, ..] = read_back.as_slice()
        {
            assert_eq!(d1, d2);
            for (a, b) in x1.iter().zip(x2) {
                assert!((a - b).abs() < 0.01 * ARCSEC, "{a} vs {b}");
            }
        }
        let axes: Vec<Option<Axis>> = read_back.iter().map(Data::axis).collect();
        if title == "torque_curve" || title == "positioning" {
            assert_eq!(axes.last(), Some(&Some(Axis::Linear)), "{title}");
        }
    }
    assert_eq!(kinds, Kind::all().collect::<Vec<_>>());
}
