use super::*;
use crate::controller::{FrictionCompensation, ReversalPulse};
use crate::model::friction::{Rise, SteadyFriction};
use std::f64::consts::TAU;

fn rotary() -> CompensationFile {
    CompensationFile {
        axis: Axis::Rotary,
        compensation: Compensation {
            backlash: Some(-1.7e-4),
            table: Some(ErrorTable {
                positions: (0..=12).map(|i| TAU * i as f64 / 12.0).collect(),
                values: (0..=12).map(|i| 1e-6 * ((i % 12) as f64 - 3.0)).collect(),
                modulo: Some(TAU),
            }),
            friction: Some(FrictionCompensation {
                law: SteadyFriction {
                    coulomb: 0.33,
                    viscous: 2.1e-3,
                    rise: Some(Rise {
                        rise: 0.05,
                        speed: 0.8,
                        shape: 1.5,
                    }),
                },
                offset: -4.7e-4,
                pulse: Some(ReversalPulse {
                    amplitude: 0.1,
                    decay_s: 0.02,
                }),
            }),
        },
        source: vec![Source {
            file: "positioning.json".into(),
            runs: Some("1-3".into()),
            model: None,
        }],
    }
}

fn read_text(text: &str) -> Result<CompensationFile, CompensationFileError> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("compensation.json");
    std::fs::write(&path, text).unwrap();
    read(&path)
}

#[test]
fn a_file_written_reads_back_in_si() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.json");
    let file = rotary();
    write(&path, &file).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("\"unit\": \"deg\"") && text.contains("\"modulo\": 360"),
        "{text}"
    );
    let back = read(&path).unwrap();
    assert_eq!(back.axis, Axis::Rotary);
    assert_eq!(back.source, file.source);
    let (a, b) = (back.compensation, file.compensation);
    assert!((a.backlash.unwrap() - b.backlash.unwrap()).abs() < 1e-18);
    let (ta, tb) = (a.table.unwrap(), b.table.unwrap());
    assert!((ta.modulo.unwrap() - TAU).abs() < 1e-12);
    for (x, y) in ta.positions.iter().zip(&tb.positions) {
        assert!((x - y).abs() < 1e-12, "{x} {y}");
    }
    for (x, y) in ta.values.iter().zip(&tb.values) {
        assert!((x - y).abs() < 1e-18, "{x} {y}");
    }
    // The friction law is SI in the file: it reads back exactly.
    assert_eq!(a.friction, b.friction);
    assert!(text.contains("\"effort_unit\": \"N·m\""), "{text}");
}

#[test]
fn bad_files_name_the_file_and_the_field() {
    let table = |positions: &str, values: &str, modulo: &str| {
        format!(
            r#"{{"axis": "rotary", "unit": "deg", "backlash": {{"value": -0.01}},
               "table": {{"positions": {positions}, "values": {values}{modulo}}}}}"#
        )
    };
    for (text, expect) in [
        (
            table("[0, 30, 30]", "[0, 1, 2]", ""),
            "field `table`: table position 2 (30) is not finite or does not increase",
        ),
        (
            table("[0, 30]", "[0, 1, 2]", ""),
            "field `table`: the table has 2 positions and 3 values",
        ),
        (table("[0, 30]", "[0, NaN]", ""), "expected value"),
        (
            table("[0, 30]", "[0, 1]", r#", "modulo": 400"#),
            "field `table.modulo`: 400",
        ),
        (
            table("[0, 400]", "[0, 1]", r#", "modulo": 360"#),
            "field `table.positions`: 400 is outside",
        ),
        (
            r#"{"axis": "rotary", "unit": "mm"}"#.to_string(),
            "field `unit`: `mm` is not the unit of a rotary axis (`deg`)",
        ),
        (
            r#"{"axis": "linear", "unit": "mm", "table": {"positions": [0, 1], "values": [0, 0], "modulo": 360}}"#
                .to_string(),
            "field `table.modulo`: a linear axis has no modulo",
        ),
        (
            r#"{"axis": "linear", "unit": "mm", "friction": {"effort_unit": "N·m", "speed_unit": "m/s", "coulomb": 1, "viscous": 0}}"#.to_string(),
            "field `friction.effort_unit`: `N·m`: a linear axis's law is in `N`",
        ),
        (
            r#"{"axis": "rotary", "unit": "deg", "friction": {"effort_unit": "N·m", "speed_unit": "rad/s", "coulomb": 1, "viscous": 0, "stribeck": {"rise": 0.1, "speed": 0, "shape": 2}}}"#.to_string(),
            "field `friction.stribeck.speed`: 0: must be finite and positive",
        ),
        (
            r#"{"axis": "rotary", "unit": "deg", "friction": {"effort_unit": "N·m", "speed_unit": "rad/s", "coulomb": -1, "viscous": 0}}"#.to_string(),
            "field `friction.coulomb`: -1: must be finite and non-negative",
        ),
        (
            r#"{"axis": "rotary", "unit": "deg", "backlsh": {"value": 1}}"#.to_string(),
            "unknown field `backlsh`",
        ),
        (
            r#"{"axis": "spindle", "unit": "deg"}"#.to_string(),
            "unknown variant `spindle`",
        ),
    ] {
        let e = read_text(&text).unwrap_err().to_string();
        assert!(e.contains("compensation.json"), "{e}");
        assert!(e.contains(expect), "{text}\n→ {e}");
    }
}

#[test]
fn a_compensation_of_another_axis_is_refused() {
    let file = rotary();
    let e = file
        .check_axis(Path::new("c.json"), Axis::Linear)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "c.json: a compensation of a rotary axis cannot be applied to a record of a linear axis"
    );
    file.check_axis(Path::new("c.json"), Axis::Rotary).unwrap();
}
