//! Linear units, current-driven and multisine records, and servo traces.

use super::{close, files, read_csv};
use crate::io::experiment_file::*;

/// Reads `csv` as the data of a manifest of `kind` with `conditions` (a JSON object).
fn read_with(kind: &str, conditions: &str, csv: &str) -> Result<Experiment, ExperimentFileError> {
    let manifest =
        format!(r#"{{"kind": "{kind}", "data": "run.csv", "conditions": {conditions}}}"#);
    let (_dir, path) = files(&[("run.json", &manifest), ("run.csv", csv)]);
    read(&path)
}

fn error(result: Result<Experiment, ExperimentFileError>) -> String {
    result.unwrap_err().to_string()
}

#[test]
fn metres_millimetres_and_micrometres_give_the_same_metres() {
    let lengths_mm = [0.0, 1.0 / 3.0, -250.0, 1e-3];
    for (unit, per_mm) in [("m", 1e-3), ("mm", 1.0), ("um", 1e3)] {
        let mut csv = format!("target_{unit},direction,run,deviation_{unit}\n");
        for (i, x) in lengths_mm.iter().enumerate() {
            csv += &format!("{:?},up,{},{:?}\n", x * per_mm, i + 1, x * per_mm * 1e-3);
        }
        let Data::LinearPositioning {
            target_m,
            deviation_m,
            ..
        } = read_csv("positioning", &csv).unwrap().data
        else {
            panic!("{unit}: not linear positioning")
        };
        let expected: Vec<f64> = lengths_mm.iter().map(|x| x * 1e-3).collect();
        assert!(close(&target_m, &expected), "{unit}: {target_m:?}");
        let dev: Vec<f64> = expected.iter().map(|x| x * 1e-3).collect();
        assert!(close(&deviation_m, &dev), "{unit}: {deviation_m:?}");
    }
}

#[test]
fn a_linear_positioning_file_gives_deviations_in_metres() {
    // ISO 230-2 on a linear axis: targets in mm, measured positions in mm.
    let csv = "target_mm,direction,run,measured_mm\n100,up,1,100.0025\n100,down,1,99.9975\n";
    let e = read_csv("positioning", csv).unwrap();
    assert_eq!(e.data.axis(), Some(Axis::Linear));
    let Data::LinearPositioning {
        target_m,
        direction,
        deviation_m,
        ..
    } = e.data
    else {
        panic!("{:?}", e.data)
    };
    assert_eq!(target_m, [0.1, 0.1]);
    assert_eq!(direction, [Direction::Up, Direction::Down]);
    assert!(close(&deviation_m, &[2.5e-6, -2.5e-6]), "{deviation_m:?}");
}

#[test]
fn a_torque_curve_in_newtons_is_a_force_curve() {
    let csv = "time_s,force_n,table_position_mm\n0,12.5,0\n0.001,13,0.25\n";
    let e = read_csv("torque_curve", csv).unwrap();
    assert_eq!(
        (e.data.kind(), e.data.axis()),
        (Kind::TorqueCurve, Some(Axis::Linear))
    );
    let Data::ForceCurve {
        force_n,
        table_position_m,
        ..
    } = e.data
    else {
        panic!("{:?}", e.data)
    };
    assert_eq!(force_n, [12.5, 13.0]);
    assert_eq!(table_position_m, Some(vec![0.0, 2.5e-4]));
    // Without a position column the force alone says linear.
    let e = read_csv("torque_curve", "time_s,force_n\n0,1\n").unwrap();
    assert!(matches!(
        e.data,
        Data::ForceCurve {
            table_position_m: None,
            ..
        }
    ));
}

#[test]
fn mixing_rotary_and_linear_units_names_the_column() {
    let tc = "torque_curve";
    for (kind, csv, expected) in [
        (tc, "time_s,force_n,table_angle_deg\n0,1,0\n", "run.csv, line 1: column `table_angle_deg` is an angle or a torque (rotary) but `force_n` is a length or a force (linear)"),
        (tc, "time_s,motor_torque_nm,table_position_um\n0,1,0\n", "column `table_position_um` is a length or a force (linear) but `motor_torque_nm` is an angle or a torque (rotary)"),
        (tc, "time_s,motor_torque_nm,force_n\n0,1,1\n", "columns `motor_torque_nm` and `force_n` give the same drive effort: keep one"),
        (tc, "time_s,table_angle_deg\n0,1\n", "missing column `motor_torque_nm` (or `force_n`)"),
        (tc, "time_s,force_n,table_angle_deg,table_position_mm\n0,1,0,0\n", "columns `table_angle_deg` and `table_position_mm` give the same position: keep one"),
        ("positioning", "target_deg,direction,run,deviation_um\n0,up,1,1\n", "column `deviation_um` is a length or a force (linear) but `target_deg` is an angle"),
        ("positioning", "target_mm,direction,run,measured_rad\n0,up,1,1\n", "column `measured_rad` is an angle or a torque (rotary) but `target_mm`"),
        ("positioning", "target_mm,target_um,direction,run,deviation_um\n0,0,up,1,1\n", "columns `target_mm` and `target_um` give the same position"),
        ("fluctuation", "time_s,motor_angle_deg,table_angle_mm\n0,0,0\n", "missing column `table_angle_deg` (or `table_angle_rad`, `table_angle_arcsec`)"),
    ] {
        let err = error(read_csv(kind, csv));
        assert!(err.contains(expected), "{csv:?}:\n  got  {err}\n  want {expected}");
    }
}

const RECORD_HEAD: &str =
    "time_s,current_ref_a,motor_current_a,motor_angle_rad,load_angle_rad,dc_bus_voltage_v\n";

/// `rows` rows of a current-driven record at `step` seconds.
fn current_record(rows: usize, step: f64) -> String {
    let mut csv = RECORD_HEAD.to_string();
    for k in 0..rows {
        let t = k as f64 * step;
        csv += &format!("{t:?},1,{},{},{},280\n", (t * 7.0).sin(), 0.1 * t, -0.1 * t);
    }
    csv
}

#[test]
fn a_current_driven_record_reads_its_load_angle_and_keeps_the_rest() {
    let e = read_csv("frequency_response_time", &current_record(5, 4e-4)).unwrap();
    let Data::FrequencyResponseTimeCurrent {
        motor_current_a,
        table_angle_rad,
        extra,
        ..
    } = &e.data
    else {
        panic!("{:?}", e.data)
    };
    assert_eq!(motor_current_a.len(), 5);
    assert!(close(
        table_angle_rad,
        &[0.0, -4e-5, -8e-5, -1.2e-4, -1.6e-4]
    ));
    assert_eq!(
        extra.keys().collect::<Vec<_>>(),
        ["current_ref_a", "dc_bus_voltage_v"]
    );
    for (csv, expected) in [
        (
            "time_s,motor_current_a,motor_torque_nm,motor_angle_deg,table_angle_deg\n0,0,0,0,0\n",
            "columns `motor_torque_nm` and `motor_current_a` give the same input: keep one",
        ),
        (
            "time_s,motor_current_a,motor_angle_deg,table_angle_deg,load_angle_rad\n0,0,0,0,0\n",
            "columns `table_angle_deg` and `load_angle_rad` give the same angle: keep one",
        ),
    ] {
        let err = error(read_csv("frequency_response_time", csv));
        assert!(err.contains(expected), "got {err}");
    }
}

#[test]
fn a_multisine_takes_its_period_and_lines() {
    let multisine = r#"{"excitation": "multisine", "period_s": 0.01, "first_line_hz": 100, "last_line_hz": 1000}"#;
    let e = read_with(
        "frequency_response_time",
        multisine,
        &current_record(100, 4e-4),
    )
    .unwrap();
    let c = e
        .manifest
        .conditions
        .with_defaults(Kind::FrequencyResponseTime);
    assert_eq!(c.excitation, Some(Excitation::Multisine));
    assert_eq!(
        (c.line_step_hz, c.transient_periods),
        (Some(100.0), Some(1))
    );
    // The manifest as written keeps only what was given.
    assert_eq!(e.manifest.conditions.line_step_hz, None);
    // A head of the record (less than one period) still reads.
    let head = current_record(3, 4e-4);
    assert!(read_with("frequency_response_time", multisine, &head).is_ok());
}

#[test]
fn malformed_multisine_conditions_are_named() {
    let k = "frequency_response_time";
    let csv = current_record(100, 4e-4);
    for (conditions, expected) in [
        (r#"{"excitation": "multisine"}"#, "run.json: a multisine record needs `conditions.period_s`"),
        (r#"{"excitation": "multisine", "period_s": -1}"#, "`conditions.period_s` is -1"),
        (r#"{"excitation": "multisine", "period_s": 0.01, "first_line_hz": 150, "last_line_hz": 1000}"#, "`conditions.first_line_hz` is 150: it must be a positive whole multiple of 1/period_s = 100 Hz"),
        (r#"{"excitation": "multisine", "period_s": 0.01, "first_line_hz": 100}"#, "`conditions.first_line_hz` and `last_line_hz` go together"),
        (r#"{"excitation": "multisine", "period_s": 0.01, "first_line_hz": 300, "last_line_hz": 200}"#, "`conditions.last_line_hz` is 200, below `first_line_hz` 300"),
        (r#"{"excitation": "multisine", "period_s": 0.01, "line_step_hz": 0}"#, "`conditions.line_step_hz` is 0"),
        (r#"{"excitation": "multisine", "period_s": 0.01, "transient_periods": 1.5}"#, "run.json, line 1, column"),
        // Checks against the record (2500 Hz, 100 samples).
        (r#"{"excitation": "multisine", "period_s": 0.0101}"#, "`conditions.period_s` is 0.0101 s, 25.2500 samples"),
        (r#"{"excitation": "multisine", "period_s": 0.01, "first_line_hz": 100, "last_line_hz": 1300}"#, "`conditions.last_line_hz` is 1300: at or above the Nyquist frequency 1250"),
    ] {
        let err = error(read_with(k, conditions, &csv));
        assert!(err.contains(expected), "{conditions}:\n  got  {err}\n  want {expected}");
    }
}

const SERVO: &str = "time_s,reference_position_deg,position_deg,torque_nm,controller_output_a\n\
                     0,0,0,0.5,0.1\n0.001,1,0.5,0.6,0.12\n0.002,2,1.5,0.7,0.14\n";

#[test]
fn a_servo_trace_reads_positions_effort_and_signals() {
    let e = read_csv("servo_trace", SERVO).unwrap();
    let Data::ServoTrace(t) = e.data else {
        panic!("{:?}", e.data)
    };
    assert_eq!(t.axis, Axis::Rotary);
    assert!(close(
        &t.reference_position,
        &[0.0, 1f64.to_radians(), 2f64.to_radians()]
    ));
    assert_eq!(t.effort, [0.5, 0.6, 0.7]);
    let out = t.controller_output.unwrap();
    assert_eq!(
        (out.unit, out.values),
        (CommandUnit::Ampere, vec![0.1, 0.12, 0.14])
    );
    assert!(t.controller_added.is_none() && t.table_position.is_none());
    // EMPS's spelling of the loop encoder, a second encoder and an added signal.
    let csv = "time_s,reference_position_m,motor_position_m,table_position_um,force_n,controller_output_v,controller_added_v\n\
               0,0,0,0,1,0.1,0\n0.00100002,0,0,1,1,0.1,0.05\n0.00199998,0,0,2,1,0.1,0\n";
    let e = read_csv("servo_trace", csv).unwrap();
    let Data::ServoTrace(t) = e.data else {
        panic!()
    };
    assert_eq!(t.axis, Axis::Linear);
    assert_eq!(t.table_position, Some(vec![0.0, 1e-6, 2e-6]));
    assert_eq!(t.controller_added.unwrap().values, [0.0, 0.05, 0.0]);
}

#[test]
fn malformed_servo_traces_are_named() {
    for (csv, expected) in [
        ("time_s,position_deg,torque_nm\n0,0,0\n", "missing column `reference_position_deg` (or `reference_position_rad`"),
        ("time_s,reference_position_deg,torque_nm\n0,0,0\n", "missing column `position_deg` (or `position_rad`, `position_arcsec`, `position_m`, `position_mm`, `position_um`, `motor_position_deg`"),
        ("time_s,reference_position_m,position_m,motor_position_m,force_n\n0,0,0,0,0\n", "columns `position_m` and `motor_position_m` give the same position: keep one"),
        ("time_s,reference_position_m,position_m\n0,0,0\n", "missing column `torque_nm` (or `force_n`)"),
        ("time_s,reference_position_m,position_deg,force_n\n0,0,0,0\n", "column `position_deg` is an angle or a torque (rotary) but `reference_position_m`"),
        ("time_s,reference_position_m,position_m,torque_nm\n0,0,0,0\n", "column `torque_nm` is an angle or a torque (rotary) but `reference_position_m`"),
        ("time_s,reference_position_m,position_m,force_n,controller_output_v,controller_output_a\n0,0,0,0,0,0\n", "columns `controller_output_v` and `controller_output_a` give the same signal"),
        ("time_s,reference_position_m,position_m,force_n,controller_output_v,controller_added_a\n0,0,0,0,0,0\n", "column `controller_added_a` is in A but the controller output in V"),
        ("time_s,reference_position_m,position_m,force_n\n0,0,0,0\n0.001,0,0,0\n0.003,0,0,0\n0.004,0,0,0\n", "run.csv, line 4, column `time_s`: the step from the previous row is 2.000000e-3 s"),
        ("time_s,reference_position_m,position_m,force_n\n0,0,0,0\n0.001,0,x,0\n", "run.csv, line 3, column `position_m`: `x` is not a number"),
    ] {
        let err = error(read_csv("servo_trace", csv));
        assert!(err.contains(expected), "{csv:?}:\n  got  {err}\n  want {expected}");
    }
    for (conditions, expected) in [
        (
            r#"{"drive_gain": 0}"#,
            "run.json: `conditions.drive_gain` is 0",
        ),
        (
            r#"{"loop_period_s": -0.001}"#,
            "run.json: `conditions.loop_period_s` is -0.001",
        ),
    ] {
        let err = error(read_with("servo_trace", conditions, SERVO));
        assert!(
            err.contains(expected),
            "{conditions}:\n  got  {err}\n  want {expected}"
        );
    }
}

#[test]
fn the_writer_refuses_linear_spellings_as_extra_columns_and_mixed_signal_units() {
    let dir = tempfile::tempdir().unwrap();
    let curve = Data::TorqueCurve {
        time_s: vec![0.0],
        motor_torque_nm: vec![1.0],
        table_angle_rad: None,
        extra: Columns::from([("table_position_um".to_string(), vec![0.0])]),
    };
    let err = write(
        &dir.path().join("a.json"),
        &Manifest::new(Kind::TorqueCurve),
        &curve,
    );
    assert!(err
        .unwrap_err()
        .to_string()
        .contains("extra column `table_position_um` clashes"));
    let signal = |unit| {
        Some(Signal {
            unit,
            values: vec![0.0],
        })
    };
    let trace = Data::ServoTrace(ServoTrace {
        axis: Axis::Linear,
        time_s: vec![0.0],
        reference_position: vec![0.0],
        position: vec![0.0],
        table_position: None,
        effort: vec![0.0],
        controller_output: signal(CommandUnit::Volt),
        controller_added: signal(CommandUnit::Ampere),
        extra: Columns::new(),
    });
    let err = write(
        &dir.path().join("b.json"),
        &Manifest::new(Kind::ServoTrace),
        &trace,
    );
    assert!(err
        .unwrap_err()
        .to_string()
        .contains("the added signal is in A but the controller output in V"));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
