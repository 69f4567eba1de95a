//! A torque curve as experiment-file data, and back, with its manifest.

use super::{TorqueCurve, TorqueTest};
use crate::io::experiment_file::{Data, Kind, Manifest};
use crate::model::params::{Axis, Params};

/// The experiment-file form of a recorded curve on `axis` (torque and angle, or
/// force and position).
pub fn to_data(curve: &TorqueCurve, axis: Axis) -> Data {
    Data::effort_curve(
        axis,
        curve.time.clone(),
        curve.motor_torque.clone(),
        Some(curve.table_angle.clone()),
    )
}

/// The curve of a torque-curve experiment file (`None` for another kind); on a
/// linear axis the force in `motor_torque` and the carriage position in
/// `table_angle`. The table angle is empty when the file has none.
pub fn from_data(data: &Data) -> Option<TorqueCurve> {
    let (time, effort, position) = match data {
        Data::TorqueCurve {
            time_s,
            motor_torque_nm,
            table_angle_rad,
            ..
        } => (time_s, motor_torque_nm, table_angle_rad),
        Data::ForceCurve {
            time_s,
            force_n,
            table_position_m,
            ..
        } => (time_s, force_n, table_position_m),
        _ => return None,
    };
    Some(TorqueCurve {
        time: time.clone(),
        motor_torque: effort.clone(),
        table_angle: position.clone().unwrap_or_default(),
    })
}

/// The manifest of a virtual torque-curve test.
pub fn manifest(params: &Params, test: &TorqueTest) -> Manifest {
    let mut m = Manifest::new(Kind::TorqueCurve);
    m.mechanism = Some(params.name.clone());
    match params.axis {
        Axis::Rotary => m.conditions.amplitude_deg = Some(test.amplitude.to_degrees()),
        Axis::Linear => m.conditions.amplitude_m = Some(test.amplitude),
    }
    m.conditions.period_s = Some(test.period);
    m.conditions.loop_mode = Some(test.loop_mode);
    m.notes = Some(format!(
        "virtual friction-torque test by rtid: {} period(s) recorded after a run-in of {}, \
         motor torque command sampled every {} ms, time restarted at 0 after the run-in",
        test.periods,
        test.run_in_periods,
        test.sample * 1e3
    ));
    m
}
