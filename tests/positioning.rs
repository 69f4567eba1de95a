//! The virtual ISO 230-2 positioning test on both presets (docs/experiments.md (positioning)).

use rtid::experiments::positioning::iso230::{evaluate, ARCSEC_PER_RAD};
use rtid::experiments::positioning::{run, PositioningTest};
use rtid::model::presets;

#[test]
fn worm_reversal_is_its_lost_motion_and_the_roller_has_almost_none() {
    let test = PositioningTest::default();
    let worm = presets::load("worm-gear").unwrap();
    let report = evaluate(&run(&worm, &test, |_, _| {}).unwrap()).unwrap();
    let axis = report.axis.in_arcsec();
    // Semi-closed loop: the motor is positioned, the table lags by half the lost
    // motion on each side, so the mean reversal is the total lost motion at the
    // table: 2·θbw + 2·θbg·Rw (plus the elastic wind-up of the friction torques).
    let lost_motion =
        (2.0 * worm.theta_bw + 2.0 * worm.theta_bg.unwrap() * worm.rw) * ARCSEC_PER_RAD;
    eprintln!(
        "worm: B_mean {:.2}″ (lost motion {lost_motion:.2}″), R {:.2}″, A {:.2}″",
        axis.b_mean, axis.r, axis.a
    );
    assert!(
        (axis.b_mean.abs() - lost_motion).abs() < 0.1 * lost_motion,
        "worm mean reversal {:.2}″ vs lost motion {lost_motion:.2}″",
        axis.b_mean
    );
    let roller = presets::load("roller-gear-cam").unwrap();
    let report = evaluate(&run(&roller, &test, |_, _| {}).unwrap()).unwrap();
    let axis = report.axis.in_arcsec();
    // No backlash: what remains is the elastic wind-up of the table's friction
    // torque through the drive's series stiffness Kw ‖ Kb·r², opposite for the two
    // approach directions: 2·ft/K, to within one table-encoder count (0.36″).
    let k = 1.0 / (1.0 / roller.kw + 1.0 / (roller.kb * roller.r * roller.r));
    let windup = 2.0 * roller.ft / k * ARCSEC_PER_RAD;
    let count = roller.controller.table_encoder_resolution * ARCSEC_PER_RAD;
    eprintln!(
        "roller: B_mean {:.2}″ (wind-up {windup:.2}″), R {:.2}″, A {:.2}″",
        axis.b_mean, axis.r, axis.a
    );
    assert!(
        (axis.b_mean.abs() - windup).abs() < count,
        "roller mean reversal {:.2}″ vs wind-up {windup:.2}″",
        axis.b_mean
    );
    assert!(axis.b_mean.abs() < 0.05 * lost_motion);
}
