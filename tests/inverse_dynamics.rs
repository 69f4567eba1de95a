//! IDIM-LS on the EMPS benchmark's estimation record (fixtures/real/emps), read through
//! the experiment-file reader, against the benchmark's published identification
//! (Janot, Gautier, Brunot, "Data Set and Reference Models of EMPS", 2019):
//! M = 95.1089 kg, Fv = 203.5034 N·s/m, Fc = 20.3935 N, OF = −3.1648 N.

use std::path::Path;

use rtid::estimation::inverse_dynamics::{identify, IdimFit, IdimSettings};
use rtid::io::experiment_file::{self, sample_period, Axis, Data};

const PUBLISHED: [f64; 4] = [95.1089, 203.5034, 20.3935, -3.1648];

fn emps(settings: &IdimSettings) -> IdimFit {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real/emps/emps_estimation.json");
    let e = experiment_file::read(&path).unwrap();
    let Data::ServoTrace(t) = e.data else {
        panic!("not a servo trace")
    };
    assert_eq!(t.axis, Axis::Linear);
    let ts = sample_period(&t.time_s).unwrap();
    identify(ts, &t.position, &t.effort, settings).unwrap()
}

fn values(f: &IdimFit) -> [f64; 4] {
    [
        f.inertia.value,
        f.viscous.value,
        f.coulomb.value,
        f.offset.value,
    ]
}

/// The brief's tolerances (2 % on M, Fv, Fc; 0.5 N on OF) and the agreement actually
/// reached with the default settings: M 95.11 kg, Fv 203.49 N·s/m, Fc 20.39 N,
/// OF −3.21 N — within 0.1 % and 0.05 N.
#[test]
fn the_default_settings_reproduce_the_published_identification() {
    let fit = emps(&IdimSettings::default());
    let got = values(&fit);
    for (i, name) in ["M", "Fv", "Fc"].iter().enumerate() {
        let relative = (got[i] / PUBLISHED[i] - 1.0).abs();
        assert!(relative < 0.02, "{name}: {} vs {}", got[i], PUBLISHED[i]);
        assert!(relative < 1e-3, "{name}: {} vs {}", got[i], PUBLISHED[i]);
    }
    assert!((got[3] - PUBLISHED[3]).abs() < 0.5, "OF {}", got[3]);
    assert!((got[3] - PUBLISHED[3]).abs() < 0.05, "OF {}", got[3]);
    // Well determined: M to 0.11 %, Fc to 0.5 %; the residual is the force's 2 N
    // of what a rigid model with Coulomb friction does not explain.
    assert!(
        fit.inertia.relative_error_percent() < 0.15,
        "{:?}",
        fit.inertia
    );
    assert!(
        fit.coulomb.relative_error_percent() < 0.6,
        "{:?}",
        fit.coulomb
    );
    assert!(
        fit.residual_rms > 1.5 && fit.residual_rms < 2.5,
        "{}",
        fit.residual_rms
    );
    assert_eq!(fit.settings, IdimSettings::default());
    assert_eq!(fit.decimation_cutoff_hz, Some(40.0));
    assert!((fit.sample_period_s - 1e-3).abs() < 1e-12);
    assert_eq!(fit.rows + fit.slow_rows, (200..24_641).step_by(10).count());
}

/// M moves with the position filter's cut-off below the decimation band and not above
/// it; Fv, Fc and OF hardly move. The independent computation in the record's README
/// (no speed threshold): 98.2 kg at 10 Hz, 96.19 kg at 20 Hz, 95.15 kg at 50 Hz.
#[test]
fn the_mass_moves_with_the_cut_off_below_the_decimation_band_only() {
    let at = |cutoff_hz: f64| {
        emps(&IdimSettings {
            cutoff_hz,
            min_speed: 0.0,
            ..IdimSettings::default()
        })
    };
    let fits: Vec<(f64, IdimFit)> = [10.0, 20.0, 50.0, 80.0, 100.0, 200.0]
        .into_iter()
        .map(|fc| (fc, at(fc)))
        .collect();
    for (fc, readme_m) in [(10.0, 98.2), (20.0, 96.19), (50.0, 95.15)] {
        let m = fits.iter().find(|(f, _)| *f == fc).unwrap().1.inertia.value;
        assert!(
            (m / readme_m - 1.0).abs() < 2e-3,
            "{fc} Hz: M {m} vs {readme_m}"
        );
    }
    let m: Vec<f64> = fits.iter().map(|(_, f)| f.inertia.value).collect();
    assert!(m[0] > m[1] + 1.5 && m[1] > m[2] + 0.8, "{m:?}");
    let plateau = &m[3..];
    for x in plateau {
        assert!((x / m[4] - 1.0).abs() < 1e-4, "{m:?}");
    }
    let reference = values(&fits[4].1);
    for (fc, fit) in &fits {
        let v = values(fit);
        for i in 1..4 {
            let change = (v[i] / reference[i] - 1.0).abs();
            assert!(
                change < 0.01,
                "{fc} Hz, parameter {i}: {v:?} vs {reference:?}"
            );
        }
    }
}
