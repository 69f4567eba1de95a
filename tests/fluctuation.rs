//! The virtual rotational-fluctuation and unbalance tests on both presets
//! (docs/experiments.md, fluctuation and unbalance), and how evaluation fails. The full default conditions are run (one
//! revolution each way, 180°/min and 360°/min): about 7 s and 3 s of CPU per preset.

use rtid::experiments::fluctuation::{
    evaluate, evaluate_experiment, manifest, run, to_data, FluctuationTest, Record, STEP_WINDOW,
};
use rtid::experiments::positioning::iso230::ARCSEC_PER_RAD;
use rtid::io::experiment_file::{self, Kind};
use rtid::model::presets;

#[test]
fn worm_fluctuates_at_72_cycles_per_revolution_and_the_roller_does_not() {
    let test = FluctuationTest::default();
    let worm = presets::load("worm-gear").unwrap();
    let w = evaluate(&run(&worm, &test, |_, _| {}).unwrap(), worm.ratio()).unwrap();
    // One fluctuation cycle per worm revolution, 1/Rw = 72 worm turns per table turn.
    let top = w.dominant[0];
    let w_arcsec = worm.w * ARCSEC_PER_RAD;
    eprintln!(
        "worm: dominant {:?}, pp {:.2}″, gap {:.2}″ (W = {w_arcsec:.2}″)",
        w.dominant,
        w.pp_arcsec,
        w.gap_arcsec.unwrap()
    );
    assert!(
        (top.order - 72.0).abs() <= 1.0,
        "worm peak at {}",
        top.order
    );
    // In semi-closed loop at 3°/s (0.6 Hz of fluctuation, far below the 190 Hz modes)
    // the table follows e(θw) quasi-statically: amplitude W, peak-to-peak 2W.
    assert!((top.amplitude - w_arcsec).abs() < 0.1 * w_arcsec, "{top:?}");
    assert!((w.pp_arcsec - 2.0 * w_arcsec).abs() < 0.2 * w_arcsec);
    // The gap between the CW and CCW curves is the lost motion (docs/experiments.md (rotational fluctuation)).
    let lost = (2.0 * worm.theta_bw + 2.0 * worm.theta_bg.unwrap() * worm.rw) * ARCSEC_PER_RAD;
    let gap = w.gap_arcsec.unwrap();
    assert!(
        gap > lost && gap < 1.2 * lost,
        "gap {gap:.2}″ vs {lost:.2}″"
    );

    let roller = presets::load("roller-gear-cam").unwrap();
    let r = evaluate(&run(&roller, &test, |_, _| {}).unwrap(), roller.ratio()).unwrap();
    let (at_w, at_r) = (w.spectrum.psd_at(72.0), r.spectrum.psd_at(72.0));
    eprintln!(
        "roller: dominant {:?}, pp {:.2}″; PSD at 72: roller {at_r:.3e}, worm {at_w:.3e} ″²/(c/rev)",
        r.dominant, r.pp_arcsec
    );
    // The roller has W = 0: nothing in its model repeats 72 times a turn, so order 72
    // holds only encoder quantisation (a count is 0.36″, spread over thousands of
    // bins). 1e-4 of the worm's PSD is an amplitude of 1 % of W (0.03″), a tenth of
    // one table-encoder count: a peak that small is not a fluctuation.
    assert!(
        at_r < 1e-4 * at_w,
        "roller PSD at 72 {at_r:.3e} vs worm {at_w:.3e}"
    );
    assert!(r.dominant.iter().all(|p| (p.order - 72.0).abs() > 1.0));
}

#[test]
fn unbalance_makes_the_worm_cross_its_backlash_and_not_the_roller() {
    let test = FluctuationTest::unbalance(10.0, 0.1);
    let worm = presets::load("worm-gear").unwrap();
    let w = evaluate(&run(&worm, &test, |_, _| {}).unwrap(), worm.ratio()).unwrap();
    // Where the gravity moment m·g·e·sin θ passes the friction torque the mesh torque
    // changes sign and the table crosses the free play of both meshes: 2θbw + 2θbg·Rw
    // at the table (34.7″). At that point the mesh torque is near zero, so the elastic
    // deflection hardly adds; the gear fluctuation changes by at most 2W·sin(π·0.5°/5°)
    // ≈ 1.9″ across the 0.5° window. Hence ±15 %.
    let lost = (2.0 * worm.theta_bw + 2.0 * worm.theta_bg.unwrap() * worm.rw) * ARCSEC_PER_RAD;
    let step = w.step.size_arcsec.abs();
    eprintln!(
        "worm unbalance: step {:.2}″ at {:.1}° (lost motion {lost:.2}″), pp {:.2}″",
        w.step.size_arcsec, w.step.angle_deg, w.pp_arcsec
    );
    assert!(
        (step - lost).abs() < 0.15 * lost,
        "step {step:.2}″ vs {lost:.2}″"
    );
    // It happens where m·g·e·|sin θ| ≈ ft, i.e. within a few degrees of 0° or 180°.
    let from_axis = (w.step.angle_deg.rem_euclid(180.0) + 90.0).rem_euclid(180.0) - 90.0;
    assert!(from_axis.abs() < 5.0, "step at {:.1}°", w.step.angle_deg);

    let roller = presets::load("roller-gear-cam").unwrap();
    let r = evaluate(&run(&roller, &test, |_, _| {}).unwrap(), roller.ratio()).unwrap();
    // No free play: the deviation is the elastic wind-up m·g·e·sin θ / K (K = Kw in
    // series with Kb·r²), whose change across the window is at most m·g·e/K·window,
    // plus at most one table-encoder count either side.
    let k = 1.0 / (1.0 / roller.kw + 1.0 / (roller.kb * roller.r * roller.r));
    let bound = (10.0 * 9.81 * 0.1 / k * STEP_WINDOW
        + 2.0 * roller.controller.table_encoder_resolution)
        * ARCSEC_PER_RAD;
    eprintln!(
        "roller unbalance: step {:.2}″ (bound {bound:.2}″), pp {:.2}″",
        r.step.size_arcsec, r.pp_arcsec
    );
    assert!(r.step.size_arcsec.abs() < bound);
    assert!(r.step.size_arcsec.abs() < 0.05 * step);
}

#[test]
fn a_file_of_an_unknown_mechanism_without_ratio_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mine.json");
    let worm = presets::load("worm-gear").unwrap();
    let mut m = manifest(&worm, &FluctuationTest::default());
    m.mechanism = Some("my-own-table".into());
    m.conditions.ratio = None;
    m.data = Some("mine.csv".into());
    let record = Record {
        time: (0..100).map(|i| i as f64).collect(),
        motor_angle: (0..100).map(|i| i as f64 * 0.1).collect(),
        table_angle: (0..100).map(|i| i as f64 * 0.1 / 90.0).collect(),
    };
    experiment_file::write(&path, &m, &to_data(&record, Kind::Fluctuation)).unwrap();
    let exp = experiment_file::read(&path).unwrap();
    let err = evaluate_experiment(&exp).unwrap_err().to_string();
    assert!(
        err.contains("mine.json") && err.contains("my-own-table") && err.contains("ratio"),
        "{err}"
    );
    // With the ratio given it evaluates.
    let mut m = exp.manifest.clone();
    m.conditions.ratio = Some(1.0 / 90.0);
    experiment_file::write(&path, &m, &exp.data).unwrap();
    assert!(evaluate_experiment(&experiment_file::read(&path).unwrap()).is_ok());
}
