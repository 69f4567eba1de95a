//! Fixtures shared by the tests and the benches: each returns the experiment and the
//! parameter set that made it (diffsol's `robertson() -> (problem, solution)`), so a
//! test states its truth once, from the preset behind the file
//! (`fixtures/make-identification-fixtures.sh` rebuilds the files from the presets).
#![allow(dead_code)]

use std::path::PathBuf;

use rtid::identify::ExperimentSpec;
use rtid::io::experiment_file;
use rtid::model::{presets, Params};

/// A fixture file's path (`worm-gear/frequency_response.json`).
pub fn fixture_path(relative: &str) -> PathBuf {
    root().join("fixtures").join(relative)
}

/// The repository's root: the package's folder, or its parent for the benches'
/// package (benches/, which includes this module as well).
pub fn root() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    if dir.join("fixtures").is_dir() {
        dir
    } else {
        dir.parent().expect("benches/ has a parent").to_path_buf()
    }
}

/// The experiment in a fixture file.
pub fn experiment(relative: &str) -> ExperimentSpec {
    let path = fixture_path(relative);
    let exp = experiment_file::read(&path)
        .unwrap_or_else(|e| panic!("fixture {relative} does not read: {e}"));
    ExperimentSpec::new(relative, exp)
}

/// An experiment and the parameters that made it.
pub struct Fixture {
    pub spec: ExperimentSpec,
    pub truth: Params,
}

fn fixture(relative: &str, preset: &str) -> Fixture {
    Fixture {
        spec: experiment(relative),
        truth: presets::load(preset).expect("a shipped preset"),
    }
}

/// The worm gear's frequency response: ±20 N·m with a 2000 N·m table brake, the
/// nonlinear virtual test (both meshes loaded, both resonances show).
pub fn worm_frequency_response() -> Fixture {
    fixture("worm-gear/frequency_response.json", "worm-gear")
}

/// The fixture's gain alone, its phase column dropped: the resonance fit (with phase
/// a frequency response feeds its whole complex curve by default).
pub fn gain_only(mut f: Fixture) -> Fixture {
    f.spec.experiment.data.drop_phase();
    f
}

/// As [`worm_frequency_response`] with 1 % Gaussian noise on the amplitude ratio.
pub fn worm_frequency_response_noisy() -> Fixture {
    fixture("worm-gear-noisy/frequency_response.json", "worm-gear")
}

/// The worm gear at the paper's ±5 N·m without preload or backlash, friction on, Kw
/// and Kg moved off the preset (3.6e5 N·m/rad, 760 N·m/rad), 1 % noise: made like an
/// independent simulator's record (issue 12). Friction flattens the second resonance.
pub fn worm_frequency_response_with_friction() -> Fixture {
    let mut f = fixture("worm-gear-friction/frequency_response.json", "worm-gear");
    for (name, value) in [
        ("theta_bw", 0.0),
        ("theta_bg", 0.0),
        ("Kw", 3.6e5),
        ("Kg", 760.0),
    ] {
        f.truth.set(name, value).expect("a worm parameter");
    }
    f
}

/// The worm gear's friction-torque curve (full-closed loop, 30°·sin(2πt/3 s)).
pub fn worm_torque_curve() -> Fixture {
    fixture("worm-gear/torque_curve.json", "worm-gear")
}

/// As [`worm_torque_curve`] with 1 % (of the RMS) Gaussian noise on the torque.
pub fn worm_torque_curve_noisy() -> Fixture {
    fixture("worm-gear-noisy/torque_curve.json", "worm-gear")
}

/// The worm gear's unbalance test (10 kg at 0.1 m, 360°/min).
pub fn worm_unbalance() -> Fixture {
    fixture("worm-gear/unbalance.json", "worm-gear")
}

/// As [`worm_unbalance`] with 2″ of Gaussian noise on the table angle.
pub fn worm_unbalance_noisy() -> Fixture {
    fixture("worm-gear-noisy/unbalance.json", "worm-gear")
}

/// The roller gear cam's frequency response, 10–1000 Hz.
pub fn roller_frequency_response() -> Fixture {
    fixture("roller-gear-cam/frequency_response.json", "roller-gear-cam")
}

/// The paper's measured worm resonances (230, 280 Hz); `truth` is only the preset
/// (the paper's table does not reproduce its own measurements).
pub fn paper_worm() -> Fixture {
    fixture("paper/worm-gear.json", "worm-gear")
}

/// `truth` with the named parameters multiplied by their factors: a start off the
/// truth.
pub fn off(truth: &Params, factors: &[(&str, f64)]) -> Params {
    let mut p = truth.clone();
    for (name, factor) in factors {
        let v = p.get(name).unwrap().expect("the parameter applies");
        p.set(name, v * factor).unwrap();
    }
    p
}

/// `(name, value)` of each of `names` in `p`.
pub fn values(p: &Params, names: &[&'static str]) -> Vec<(&'static str, f64)> {
    names
        .iter()
        .map(|n| (*n, p.get(n).unwrap().expect("the parameter applies")))
        .collect()
}

/// Byte spans of the JSON numbers in `text` (outside strings).
pub fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let (mut out, mut i, mut in_string) = (Vec::new(), 0, false);
    while i < bytes.len() {
        let c = bytes[i];
        if c == b'"' {
            in_string = !in_string;
            i += 1;
            continue;
        }
        if !in_string && (c == b'-' || c.is_ascii_digit()) {
            let start = i;
            while i < bytes.len()
                && (bytes[i].is_ascii_alphanumeric() || b"+-.".contains(&bytes[i]))
            {
                i += 1;
            }
            out.push((start, i));
            continue;
        }
        i += 1;
    }
    out
}

/// Whether a debug print holds a non-finite number: a token `NaN`, `inf` or `-inf`
/// outside the quoted strings (a column name may say anything).
pub fn non_finite(debug: &str) -> bool {
    let mut unquoted = String::with_capacity(debug.len());
    let (mut quoted, mut escaped) = (false, false);
    for c in debug.chars() {
        match (quoted, escaped, c) {
            (true, false, '\\') => escaped = true,
            (true, true, _) => escaped = false,
            (_, false, '"') => quoted = !quoted,
            (false, _, c) => unquoted.push(c),
            _ => {}
        }
    }
    unquoted
        .split(|c: char| !(c.is_alphanumeric() || c == '-'))
        .any(|t| matches!(t, "NaN" | "inf" | "-inf"))
}

/// The profiles of `names` at `fit` (`--profile`), and their warnings.
pub fn profiles(
    fit: &rtid::identify::Identified,
    names: &[&str],
) -> (
    std::collections::BTreeMap<String, rtid::identify::result::profile::Profile>,
    Vec<rtid::identify::Warning>,
) {
    use rtid::identify::intervals::profile;
    profile::profiles(&profile::Request {
        result: &fit.result,
        params: &fit.params,
        objective: fit.objective.as_ref(),
        settings: fit.settings,
        smoothness: fit.smoothness,
        names: names.iter().map(|n| n.to_string()).collect(),
        stop: &|| false,
        on_point: &|| {},
    })
    .unwrap()
}
