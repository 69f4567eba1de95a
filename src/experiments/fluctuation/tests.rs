//! Tests of the evaluation: synthetic records with known steps, orders and gaps.

use super::*;
use crate::experiments::positioning::iso230::ARCSEC_PER_RAD;
use crate::io::experiment_file::Direction;

/// A synthetic record: `revs` turns up then down at constant speed; the table
/// follows the motor with a fluctuation of order 72 and lags by `lag` in the
/// direction of motion.
fn synthetic(revs: f64, lag: f64) -> Record {
    let n = 20_000;
    let top = revs * TAU;
    let (mut time, mut motor, mut table) = (vec![], vec![], vec![]);
    for i in 0..2 * n {
        let (x, sense) = if i < n {
            (top * i as f64 / n as f64, 1.0)
        } else {
            (top * (2 * n - i) as f64 / n as f64, -1.0)
        };
        time.push(i as f64 * 1e-3);
        motor.push(x * 90.0);
        table.push(x + 1e-5 * (72.0 * x).sin() - sense * lag);
    }
    Record {
        time,
        motor_angle: motor,
        table_angle: table,
    }
}

#[test]
fn splits_the_directions_and_finds_order_72_and_the_gap() {
    let e = evaluate(&synthetic(1.2, 5e-5), 1.0 / 90.0).unwrap();
    assert_eq!(e.passes.len(), 2);
    assert_eq!(e.passes[0].direction, Direction::Up);
    assert_eq!(e.passes[1].direction, Direction::Down);
    assert!(e.passes.iter().all(|p| p.revolutions == 1));
    assert!((e.dominant[0].order - 72.0).abs() < 1e-9);
    let a = 1e-5 * ARCSEC_PER_RAD;
    assert!((e.dominant[0].amplitude - a).abs() < 0.01 * a);
    let gap = e.gap_arcsec.unwrap();
    assert!(
        (gap - 2.0 * 5e-5 * ARCSEC_PER_RAD).abs() < 0.01 * gap,
        "{gap}"
    );
}

#[test]
fn a_sharp_step_is_located_where_it_stands_and_its_size_kept() {
    // 33″ at x = 1.2345 rad on flat levels, sampled every 0.02°, the window off
    // centre by 2°: within half a sample interval (linear interpolation puts a
    // jump between two samples in their middle); with ±4″ of rattle over 1.5°
    // after the step: within 0.02°.
    let at = 1.2345;
    let x: Vec<f64> = (0..5000).map(|i| (i as f64 * 0.02).to_radians()).collect();
    let step = |v: f64| if v > at { 33.0 } else { 0.0 };
    let rattle = |v: f64| {
        let u = (v - at).to_degrees();
        if (0.0..1.5).contains(&u) {
            4.0 * (u * 40.0).sin()
        } else {
            0.0
        }
    };
    for (extra, tol) in [(false, 0.0101), (true, 0.02)] {
        let pass = PassSamples {
            sense: 1.0,
            deviation_arcsec: x
                .iter()
                .map(|&v| step(v) + if extra { rattle(v) } else { 0.0 })
                .collect(),
            x: x.clone(),
        };
        let (pos, size) =
            locate_step(&pass, at + 2f64.to_radians(), STEP_LOCATE_HALF_WIDTH).unwrap();
        assert!((pos - at).to_degrees().abs() < tol, "{pos} {extra}");
        assert!((size - 33.0).abs() < 1e-9, "{size}");
    }
}

#[test]
fn standstill_is_an_error_and_a_bad_ratio_too() {
    let still = Record {
        time: vec![0.0, 1.0, 2.0],
        motor_angle: vec![0.0; 3],
        table_angle: vec![0.0; 3],
    };
    assert!(matches!(
        evaluate(&still, 0.1),
        Err(FluctuationError::NoMotion { .. })
    ));
    assert!(matches!(
        evaluate(&synthetic(1.0, 0.0), -1.0),
        Err(FluctuationError::BadRatio { .. })
    ));
}

#[test]
fn windows_in_lanes_equal_each_set_s_lone_window() {
    // Three worm sets of one shape (a fourth lane padded), an unbalance test's
    // window through 3°: each record bit for bit the lone run's.
    let test = FluctuationTest::unbalance(10.0, 0.1);
    let base = crate::model::presets::load("worm-gear").unwrap();
    let sets: Vec<crate::model::Params> = [0.5, 1.0, 2.0]
        .iter()
        .map(|f| {
            let mut p = base.clone();
            p.ft *= f;
            p.fm *= f;
            p
        })
        .collect();
    let window = (-0.5f64.to_radians(), 3f64.to_radians());
    let batch = run_window_batch(&sets, &test, window);
    for (l, (p, got)) in sets.iter().zip(&batch).enumerate() {
        let alone = run_window(p, &test, window.0, window.1).unwrap();
        assert_eq!(got.as_ref().unwrap(), &alone, "set {l}");
    }
    assert_ne!(batch[0], batch[2], "the sets differ");
}
