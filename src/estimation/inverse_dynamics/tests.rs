use std::f64::consts::PI;

use super::butterworth::Butterworth;
use super::*;

/// EMPS-like parameters: kg, N·s/m, N, N.
const M: f64 = 95.0;
const FV: f64 = 200.0;
const FC: f64 = 20.0;
const OF: f64 = -3.0;
const TS: f64 = 1e-3;

/// Samples of a trajectory given with its exact derivatives, and the effort
/// F = M·q'' + Fv·q' + Fc·sign(q') + OF it needs.
fn record(n: usize, q: impl Fn(f64) -> [f64; 3]) -> (Vec<f64>, Vec<f64>) {
    (0..n)
        .map(|k| {
            let [x, v, a] = q(k as f64 * TS);
            (x, M * a + FV * v + FC * v.signum() + OF)
        })
        .unzip()
}

/// A sine of `amplitude` at `f_hz` with a phase that keeps its zero crossings of
/// velocity off the sampling instants.
fn sine(amplitude: f64, f_hz: f64) -> impl Fn(f64) -> [f64; 3] {
    let w = 2.0 * PI * f_hz;
    move |t| {
        let p = w * t + 0.3;
        [
            amplitude * p.sin(),
            amplitude * w * p.cos(),
            -amplitude * w * w * p.sin(),
        ]
    }
}

/// On a pure sine at f every regressor column is exact but for a gain: q'' and q' come
/// out scaled by the position filter's |H(f)|² times the central differences' gains,
/// sign(q') is exact (zero phase keeps the zero crossings). So M and Fv are divided by
/// those gains and Fc and OF are exact — the filter's bias, known in closed form. (400
/// samples are trimmed: with 200, eight periods of the 20 Hz cut-off, the filters'
/// edge transients still leave 7e-6 of Fc; with 400, 1e-9.)
#[test]
fn a_sine_is_recovered_up_to_the_known_filter_and_difference_gains() {
    let (f, cutoff) = (8.0, 20.0);
    let (q, effort) = record(20_000, sine(0.05, f));
    let settings = IdimSettings {
        cutoff_hz: cutoff,
        min_speed: 0.0,
        trim: 400,
        ..IdimSettings::default()
    };
    let fit = identify(TS, &q, &effort, &settings).unwrap();
    let h2 = Butterworth::low_pass(4, cutoff, 1.0 / TS)
        .unwrap()
        .gain(f, 1.0 / TS)
        .powi(2);
    let wt = 2.0 * PI * f * TS;
    let velocity_gain = wt.sin() / wt;
    let acceleration_gain = (2.0 - 2.0 * wt.cos()) / (wt * wt);
    let m_expected = M / (h2 * acceleration_gain);
    let fv_expected = FV / (h2 * velocity_gain);
    // The bias is 0.087 % on M and 0.076 % on Fv here; what is left is < 1e-6.
    assert!((m_expected / M - 1.0 - 8.7e-4).abs() < 1e-5, "{m_expected}");
    for (name, got, want) in [
        ("M", fit.inertia.value, m_expected),
        ("Fv", fit.viscous.value, fv_expected),
        ("Fc", fit.coulomb.value, FC),
        ("OF", fit.offset.value, OF),
    ] {
        assert!(
            (got - want).abs() < 1e-6 * want.abs(),
            "{name}: {got} vs {want}"
        );
    }
    assert!(fit.residual_rms < 1e-5, "{}", fit.residual_rms);
}

/// A record like EMPS's (slow sweeps both ways with faster content) with the default
/// settings: everything within 0.01 %, the filters' bias being that small at 100 Hz.
#[test]
fn a_multi_frequency_record_is_recovered_with_the_default_settings() {
    let parts = [sine(0.1, 0.2), sine(0.01, 1.3), sine(0.002, 4.1)];
    let (q, effort) = record(25_000, |t| {
        parts
            .iter()
            .map(|p| p(t))
            .fold([0.0; 3], |s, x| [s[0] + x[0], s[1] + x[1], s[2] + x[2]])
    });
    let fit = identify(TS, &q, &effort, &IdimSettings::default()).unwrap();
    for (name, got, want) in [
        ("M", fit.inertia.value, M),
        ("Fv", fit.viscous.value, FV),
        ("Fc", fit.coulomb.value, FC),
        ("OF", fit.offset.value, OF),
    ] {
        assert!(
            (got - want).abs() < 1e-4 * want.abs(),
            "{name}: {got} vs {want}"
        );
    }
    assert_eq!(fit.decimation_cutoff_hz, Some(40.0));
    assert_eq!(fit.rows + fit.slow_rows, (200..24_800).step_by(10).count());
}

/// Noise on the effort: the estimates stay within a few standard errors, and the
/// standard errors shrink as the noise does.
#[test]
fn standard_errors_follow_the_noise() {
    let (q, clean) = record(25_000, sine(0.1, 0.7));
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut noise = || {
        // Sum of uniforms: roughly normal, zero mean, unit variance.
        (0..12)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            })
            .sum::<f64>()
            - 6.0
    };
    let noisy: Vec<f64> = clean.iter().map(|f| f + 5.0 * noise()).collect();
    let settings = IdimSettings::default();
    let fit = identify(TS, &q, &noisy, &settings).unwrap();
    for (name, e, want) in [
        ("M", fit.inertia, M),
        ("Fv", fit.viscous, FV),
        ("Fc", fit.coulomb, FC),
        ("OF", fit.offset, OF),
    ] {
        assert!(e.std_error > 0.0, "{name}");
        assert!((e.value - want).abs() < 4.0 * e.std_error, "{name}: {e:?}");
    }
    let quieter: Vec<f64> = clean
        .iter()
        .zip(&noisy)
        .map(|(c, n)| c + 0.1 * (n - c))
        .collect();
    let q_fit = identify(TS, &q, &quieter, &settings).unwrap();
    let ratio = q_fit.inertia.std_error / fit.inertia.std_error;
    assert!((ratio - 0.1).abs() < 1e-3, "{ratio}");
}

#[test]
fn bad_input_gives_one_error_naming_it() {
    let (q, f) = record(2_000, sine(0.1, 1.0));
    let s = IdimSettings::default();
    let err = |r: Result<IdimFit, IdimError>| r.unwrap_err().to_string();
    assert_eq!(
        err(identify(TS, &q, &f[1..], &s)),
        "the position has 2000 samples but the effort has 1999"
    );
    let mut nan = q.clone();
    nan[17] = f64::NAN;
    assert_eq!(
        err(identify(TS, &nan, &f, &s)),
        "position sample 17 is NaN: every sample must be a finite number"
    );
    for (settings, ts, expected) in [
        (
            IdimSettings {
                cutoff_hz: 600.0,
                ..s
            },
            TS,
            "`cutoff_hz` is 600",
        ),
        (
            IdimSettings {
                cutoff_hz: -1.0,
                ..s
            },
            TS,
            "`cutoff_hz` is -1",
        ),
        (
            IdimSettings {
                filter_order: 0,
                ..s
            },
            TS,
            "`filter_order` is 0",
        ),
        (IdimSettings { decimation: 0, ..s }, TS, "`decimation` is 0"),
        (
            IdimSettings {
                decimation: 800,
                ..s
            },
            TS,
            "2 rows are left for 4 parameters",
        ),
        (
            IdimSettings {
                min_speed: f64::NAN,
                ..s
            },
            TS,
            "`min_speed` is NaN",
        ),
        (s, 0.0, "`sample_period_s` is 0"),
        (
            IdimSettings { trim: 990, ..s },
            TS,
            "rows are left for 4 parameters",
        ),
    ] {
        let e = err(identify(ts, &q, &f, &settings));
        assert!(e.contains(expected), "{e}");
    }
    // No motion: every row too slow, or (with no threshold) a singular regressor.
    let still = vec![0.25; 2_000];
    let e = err(identify(TS, &still, &f, &s));
    assert!(
        e.contains("rows are left") && e.contains("(160 of them)"),
        "{e}"
    );
    let no_threshold = IdimSettings {
        min_speed: 0.0,
        ..s
    };
    let e = identify(TS, &still, &f, &no_threshold).unwrap_err();
    assert!(matches!(e, IdimError::Singular { .. }), "{e}");
}

/// Records whose derivatives or fit overflow (issue 28: the SVD never returned on
/// them) give one error saying so, at once.
#[test]
fn records_out_of_any_physical_range_are_refused_not_hung_on() {
    let (q, f) = record(2_000, sine(0.1, 1.0));
    let s = IdimSettings::default();
    let huge: Vec<f64> = (0..q.len())
        .map(|k| if k % 2 == 0 { 1e308 } else { -1e308 })
        .collect();
    let tiny = 1e-300;
    for (ts, position, effort, settings, expected) in [
        (TS, &huge, &f, s, "speed or acceleration"),
        (
            tiny,
            &q,
            &f,
            IdimSettings::for_sample_period(tiny),
            "speed or acceleration",
        ),
        (TS, &q, &huge, s, "filtered effort"),
    ] {
        let e = identify(ts, position, effort, &settings).unwrap_err();
        assert!(matches!(e, IdimError::Overflow { .. }), "{e}");
        assert!(e.to_string().contains(expected), "{e}");
    }
}

#[test]
fn the_result_states_its_settings_and_serialises() {
    let (q, f) = record(3_000, sine(0.1, 1.0));
    let s = IdimSettings {
        decimation: 1,
        ..IdimSettings::default()
    };
    let fit = identify(TS, &q, &f, &s).unwrap();
    assert_eq!(fit.settings, s);
    assert_eq!(fit.decimation_cutoff_hz, None);
    assert_eq!(fit.sample_period_s, TS);
    let json = serde_json::to_value(&fit).unwrap();
    assert_eq!(json["settings"]["cutoff_hz"], 100.0);
    assert!(json["inertia"]["std_error"].is_number());
}
