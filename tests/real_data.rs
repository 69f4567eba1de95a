//! Real records from other labs, read as they are through the experiment-file reader:
//! EMPS (a linear axis in a sampled P/P cascade, `servo_trace`) and FdiTools' two-mass
//! bench (a current-driven periodic multisine, `frequency_response_time`). Provenance in
//! `fixtures/real/*/README.md`.

use std::path::Path;

use rtid::io::experiment_file::{
    self, sample_period, Axis, CommandUnit, Data, Excitation, Kind, ServoTrace,
};

fn read(path: &str) -> experiment_file::Experiment {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    experiment_file::read(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn emps() -> (experiment_file::Experiment, ServoTrace) {
    let e = read("fixtures/real/emps/emps_estimation.json");
    let Data::ServoTrace(trace) = e.data.clone() else {
        panic!("{:?}", e.data.kind())
    };
    (e, trace)
}

#[test]
fn emps_loads_as_a_linear_servo_trace_in_metres_and_newtons() {
    let (e, t) = emps();
    assert_eq!(e.manifest.kind, Kind::ServoTrace);
    assert_eq!(t.axis, Axis::Linear);
    assert_eq!(e.data.axis(), Some(Axis::Linear));
    // 24 841 rows over 24.84 s at 1 kHz; the times jitter by ±2e-8 s.
    assert_eq!(t.time_s.len(), 24_841);
    let ts = sample_period(&t.time_s).unwrap();
    assert!((ts - 1e-3).abs() < 1e-12, "{ts}");
    let jitter = t
        .time_s
        .iter()
        .enumerate()
        .map(|(k, x)| (x - k as f64 * 1e-3).abs())
        .fold(0.0, f64::max);
    assert!(jitter > 1e-8 && jitter < 1e-7, "{jitter}");
    // The loop encoder is the file's `motor_position_m`, read in metres as written
    // (first rows 7.45e-6 m and 1.43e-5 m); the carriage travels some 0.2 m.
    assert_eq!(t.position[..2], [7.45e-6, 1.4299999999999999e-5]);
    let travel = t.position.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - t.position.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    assert!(travel > 0.1 && travel < 0.3, "{travel} m");
    assert_eq!(t.reference_position[0], 0.00010782208000001829);
    assert!(t.table_position.is_none() && t.controller_added.is_none());
    assert!(e.data.extra().unwrap().is_empty());
}

#[test]
fn emps_force_is_the_drive_gain_times_the_controller_output() {
    let (e, t) = emps();
    let gain = e.manifest.conditions.drive_gain.unwrap();
    assert_eq!(gain, 35.15065188248547);
    assert_eq!(e.manifest.conditions.loop_period_s, Some(1e-3));
    // Informative controller settings are kept as written.
    assert_eq!(e.manifest.conditions.extra["output_limit_v"], 10);
    let output = t.controller_output.as_ref().unwrap();
    assert_eq!(output.unit, CommandUnit::Volt);
    let worst = output
        .values
        .iter()
        .zip(&t.effort)
        .map(|(v, f)| (gain * v - f).abs() / f.abs().max(1.0))
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "{worst}");
    // The drive would saturate at ±10 V; this record stays well inside (4.33 V).
    let peak = output.values.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(peak > 4.3 && peak < 4.4, "{peak} V");
}

#[test]
fn the_two_mass_record_loads_as_a_current_driven_multisine() {
    let e = read("fixtures/real/two-mass/multisine_a.json");
    let Data::FrequencyResponseTimeCurrent {
        time_s,
        motor_current_a,
        motor_angle_rad,
        table_angle_rad,
        extra,
    } = &e.data
    else {
        panic!("{:?}", e.data.kind())
    };
    assert_eq!(e.data.kind(), Kind::FrequencyResponseTime);
    assert_eq!(e.data.axis(), Some(Axis::Rotary));
    // 20 periods of 2500 samples at 2500 Hz.
    assert_eq!(time_s.len(), 50_000);
    let ts = sample_period(time_s).unwrap();
    assert!((ts - 4e-4).abs() < 1e-15, "{ts}");
    // The input is the measured q-axis current, the load channel `load_angle_rad`
    // (already negated in the file), both as written.
    assert_eq!(motor_current_a[..2], [10.9882, 10.58191]);
    assert_eq!(motor_angle_rad[0], -7.456285);
    assert_eq!(table_angle_rad[0], -0.6056647);
    // Columns the kind does not use are kept, by name, as written.
    let names: Vec<&str> = extra.keys().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "current_ref_a",
            "dc_bus_voltage_v",
            "load_velocity_rad_per_s",
            "motor_velocity_rad_per_s",
        ]
    );
    assert_eq!(extra["current_ref_a"][0], 12.97525);
    assert!(extra.values().all(|v| v.len() == 50_000));
    let c = e
        .manifest
        .conditions
        .with_defaults(Kind::FrequencyResponseTime);
    assert_eq!(c.excitation, Some(Excitation::Multisine));
    assert_eq!(
        (c.period_s, c.first_line_hz, c.last_line_hz, c.line_step_hz),
        (Some(1.0), Some(11.0), Some(250.0), Some(1.0))
    );
    assert_eq!((c.transient_periods, c.ratio), (Some(1), Some(1.0)));
}

/// The fixtures are the other labs' files byte for byte: their first lines are the
/// converter's comments, and their sizes are those of shared/data.
#[test]
fn the_fixtures_are_the_records_as_published() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real");
    for (file, bytes, first) in [
        (
            "emps/emps_estimation.csv",
            2_181_804,
            "# EMPS benchmark, estimation record",
        ),
        (
            "two-mass/multisine_a.csv",
            3_769_618,
            "# FdiTools motor bench",
        ),
    ] {
        let text = std::fs::read_to_string(root.join(file)).unwrap();
        assert!(text.starts_with(first), "{file}");
        assert_eq!(text.len(), bytes, "{file}");
    }
}
