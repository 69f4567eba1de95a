//! The SINUMERIK/SINAMICS measuring-function file (issue 60,
//! fixtures/formats/sinumerik/): listed as what it holds, imported without maps as
//! the closed speed loop's response, which agrees with an independent FFT of the
//! file's own time series (fixtures/formats/sinumerik/make_expected.py), and refused
//! where damaged, naming the element and the byte.

use std::path::{Path, PathBuf};

use crate::cli_support::{err, ok, root, rtid};
use rtid::io::experiment_file::{Data, Response};

fn xml() -> PathBuf {
    root().join("fixtures/formats/sinumerik/freq_trace.XML")
}

/// (line, frequency, gain dB, phase deg, coherence) of expected.csv.
fn expected() -> Vec<[f64; 5]> {
    let text =
        std::fs::read_to_string(root().join("fixtures/formats/sinumerik/expected.csv")).unwrap();
    text.lines()
        .filter(|l| l.starts_with(|c: char| c.is_ascii_digit()))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4]]
        })
        .collect()
}

#[test]
fn the_listing_names_the_loop_the_excitation_and_both_directions() {
    let dir = tempfile::tempdir().unwrap();
    let out = ok(&rtid(
        &["import", xml().to_str().unwrap(), "--list", "--json"],
        dir.path(),
    ));
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["format"], "sinumerik-trace");
    let names: Vec<&str> = v["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    for name in [
        "speed setpoint, positive",
        "speed setpoint, negative",
        "actual speed, positive",
        "actual speed, negative",
        "autospectrum of speed setpoint",
        "cross spectrum of actual speed and speed setpoint",
        "actual speed / speed setpoint",
    ] {
        assert!(names.contains(&name), "{name} not in {names:?}");
    }
    let notes = v["notes"].to_string();
    for said in [
        "the speed loop closed: speed setpoint → actual speed",
        "a PRBS of order 11 (period 2047 samples)",
        "sampled every 125 µs",
        "offset 0.4189 rad/s (4.000 rpm), excitation ±0.2094 rad/s (2.000 rpm)",
        "one per direction of the offset",
        "no speed-controller settings",
    ] {
        assert!(notes.contains(said), "`{said}` not in {notes}");
    }
}

#[test]
fn the_imported_response_is_an_independent_fft_of_its_time_series() {
    let dir = tempfile::tempdir().unwrap();
    let out = rtid(
        &["import", xml().to_str().unwrap(), "--out", "sl"],
        dir.path(),
    );
    ok(&out);
    let notes = String::from_utf8_lossy(&out.stderr);
    assert!(notes.contains("recomputed from the time series"), "{notes}");
    let expected = expected();
    assert_eq!(expected.len(), 1022);
    for name in ["speed_loop.json", "speed_loop_time_series.json"] {
        let exp = rtid::read_experiment(&dir.path().join("sl").join(name)).unwrap();
        let c = &exp.manifest.conditions;
        assert_eq!(c.response, Some(Response::SpeedLoop));
        assert_eq!((c.loop_period_s, c.averages), (Some(125e-6), Some(2)));
        assert!(c.controller.is_none(), "the file carries no settings");
        compare(name, &exp.data, &expected);
    }
}

/// Every line's frequency, and gain, phase and coherence where the coherence is at
/// least 0.9 (the issue asks 1.5 dB and 12°; both are transforms of the same numbers,
/// so they agree to rounding — measured 8e-12 dB, 1e-10°).
fn compare(name: &str, data: &Data, expected: &[[f64; 5]]) {
    let Data::FrequencyResponse {
        frequency_hz,
        gain_db,
        phase_rad: Some(phase),
        extra,
    } = data
    else {
        panic!("{name}: not a frequency response with phase");
    };
    let coherence = &extra["coherence"];
    assert_eq!(frequency_hz.len(), expected.len(), "{name}");
    let mut compared = 0;
    for (i, [_, f, g, ph, gamma]) in expected.iter().enumerate() {
        assert!((frequency_hz[i] / f - 1.0).abs() < 1e-12, "{name} line {i}");
        assert!((coherence[i] - gamma).abs() < 1e-9, "{name} line {i}");
        if *gamma < 0.9 {
            continue;
        }
        compared += 1;
        let dphase = rtid::angle::wrap((phase[i].to_degrees() - ph).to_radians()).to_degrees();
        assert!(
            (gain_db[i] - g).abs() < 1e-6,
            "{name} {f} Hz: {} vs {g} dB",
            gain_db[i]
        );
        assert!(dphase.abs() < 1e-5, "{name} {f} Hz: {dphase}°");
    }
    assert_eq!(compared, 472, "{name}: lines of coherence ≥ 0.9");
}

/// The file with `edit` applied, written into `dir`.
fn damaged(dir: &Path, edit: impl Fn(&mut Vec<u8>)) -> PathBuf {
    let mut bytes = std::fs::read(xml()).unwrap();
    edit(&mut bytes);
    let path = dir.join("damaged.XML");
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn a_damaged_file_is_refused_naming_the_element_and_the_byte() {
    let dir = tempfile::tempdir().unwrap();
    let original = std::fs::read(xml()).unwrap();
    let cdata = original.windows(9).position(|w| w == b"<![CDATA[").unwrap();
    // A character outside the alphabet inside the first array.
    let at = cdata + 9 + 20;
    let bad = damaged(dir.path(), |b| b[at] = b'"');
    let e = err(&rtid(
        &["import", bad.to_str().unwrap(), "--list"],
        dir.path(),
    ));
    assert!(e.contains(&format!("byte {at}")), "{e}");
    assert!(e.contains("<raw name=\"m_pNumberArray\">"), "{e}");
    assert!(e.contains("not a base85 digit"), "{e}");
    // A declared length the text does not hold.
    let bad = damaged(dir.path(), |b| {
        let text = String::from_utf8(b.clone()).unwrap();
        *b = text
            .replacen(
                "<unsigned_int name=\"m_length\">2047</unsigned_int>",
                "<unsigned_int name=\"m_length\">2046</unsigned_int>",
                1,
            )
            .into_bytes();
    });
    let e = err(&rtid(
        &["import", bad.to_str().unwrap(), "--list"],
        dir.path(),
    ));
    assert!(e.contains("m_length declares 2046 values"), "{e}");
    assert!(e.contains(", byte "), "{e}");
    // Cut in the middle: the XML ends before its elements close.
    let bad = damaged(dir.path(), |b| b.truncate(100_000));
    let e = err(&rtid(
        &["import", bad.to_str().unwrap(), "--list"],
        dir.path(),
    ));
    assert!(e.contains("not well-formed XML"), "{e}");
    assert!(e.contains(", byte "), "{e}");
    // A member missing.
    let bad = damaged(dir.path(), |b| {
        let text = String::from_utf8(b.clone()).unwrap();
        *b = text
            .replacen(
                "name=\"m_dProcessUpdateTime\"",
                "name=\"m_dSomethingElse\"",
                1,
            )
            .into_bytes();
    });
    let e = err(&rtid(
        &["import", bad.to_str().unwrap(), "--list"],
        dir.path(),
    ));
    assert!(
        e.contains("<ResponseTestCustom>: no member <float name=\"m_dProcessUpdateTime\">"),
        "{e}"
    );
}

#[test]
fn a_recording_that_needs_maps_is_not_imported_without_a_kind() {
    let dir = tempfile::tempdir().unwrap();
    let mat = root().join("fixtures/formats/matlab/DATA_EMPS.mat");
    let e = err(&rtid(
        &["import", mat.to_str().unwrap(), "--out", "x"],
        dir.path(),
    ));
    assert!(e.contains("give --kind and --map"), "{e}");
}
