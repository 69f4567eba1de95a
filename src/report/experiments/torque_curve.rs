//! Figures of the friction-torque test (paper Fig. 9).

use crate::experiments::torque_curve::{TorqueCurve, TorqueReport};
use crate::report::figure::{Figure, Series, Style};

/// The paper's Fig. 9: motor torque over time, the velocity reversals marked.
pub fn over_time(curve: &TorqueCurve, report: &TorqueReport, title: &str) -> Figure {
    let torque = curve
        .time
        .iter()
        .copied()
        .zip(curve.motor_torque.iter().copied())
        .collect();
    let marks = report
        .reversals
        .iter()
        .map(|r| (r.time_s, curve.torque_at(r.time_s)))
        .collect();
    Figure::new(title, "time, s", "motor torque, N·m")
        .with(Series::new("motor torque", torque, Style::Line))
        .with(Series::new("velocity reversals", marks, Style::Markers))
}

/// Motor torque over table angle (a friction loop); `None` when the curve has no
/// table angle.
pub fn over_angle(curve: &TorqueCurve, title: &str) -> Option<Figure> {
    if curve.table_angle.is_empty() {
        return None;
    }
    let points = curve
        .table_angle
        .iter()
        .map(|a| a.to_degrees())
        .zip(curve.motor_torque.iter().copied())
        .collect();
    Some(
        Figure::new(title, "table angle, deg", "motor torque, N·m").with(Series::new(
            "motor torque",
            points,
            Style::Line,
        )),
    )
}
