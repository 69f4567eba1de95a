//! A fluctuation or unbalance record as experiment-file data, and back.

use super::{FluctuationTest, Record};
use crate::io::experiment_file::{Data, Kind, Manifest};
use crate::model::params::Params;

/// The experiment-file form of a record, of the test's kind.
pub fn to_data(record: &Record, kind: Kind) -> Data {
    let (time_s, motor_angle_rad, table_angle_rad) = (
        record.time.clone(),
        record.motor_angle.clone(),
        record.table_angle.clone(),
    );
    let extra = Default::default();
    if kind == Kind::Unbalance {
        Data::Unbalance {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            extra,
        }
    } else {
        Data::Fluctuation {
            time_s,
            motor_angle_rad,
            table_angle_rad,
            extra,
        }
    }
}

/// The record of a fluctuation or unbalance file (`None` for another kind).
pub fn from_data(data: &Data) -> Option<Record> {
    match data {
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
        } => Some(Record {
            time: time_s.clone(),
            motor_angle: motor_angle_rad.clone(),
            table_angle: table_angle_rad.clone(),
        }),
        _ => None,
    }
}

/// The manifest of a virtual fluctuation or unbalance test.
pub fn manifest(params: &Params, test: &FluctuationTest) -> Manifest {
    let mut m = Manifest::new(test.kind());
    m.mechanism = Some(params.name.clone());
    m.conditions.loop_mode = Some(test.loop_on(params));
    m.conditions.speed_deg_per_min = Some(test.speed.to_degrees() * 60.0);
    m.conditions.ratio = Some(params.ratio());
    if let Some((mass, radius)) = test.unbalance {
        m.conditions.mass_kg = Some(mass);
        m.conditions.radius_m = Some(radius);
    }
    m.notes = Some(format!(
        "virtual {} test by rtid: {} revolution(s) each way with {:.1}° run-in, encoders \
         quantised (table {:.6}°), sampled every {} ms",
        test.kind(),
        test.revolutions,
        test.run_in.to_degrees(),
        params.controller.table_encoder_resolution.to_degrees(),
        test.sample_period * 1e3
    ));
    m
}
