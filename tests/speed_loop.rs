//! The closed speed loop as a drive measures it (issue 60): a virtual measurement of
//! known truth (`rtid experiment speed-loop`, in the form `rtid import` writes a
//! drive's file in: no controller settings) identifies its gains and dead time back
//! within 1 % (`rtid identify`, the speed_loop objective); a fit of the inertia
//! together with the gains, which the response cannot separate, is said to be so.

use std::path::Path;

use crate::cli_support::{ok, rtid};

/// The virtual measurement of the direct-drive preset run at 125 µs with an encoder
/// dead time of one period, `noise` % complex noise on each line, into `dir/v`.
fn measure(dir: &Path, noise: &str) {
    ok(&rtid(
        &[
            "experiment",
            "speed-loop",
            "--preset",
            "direct-drive",
            "--set",
            "Tc=1.25e-4",
            "--set",
            "encoder_delay=1.25e-4",
            "--noise-percent",
            noise,
            "--out",
            "v",
            "--quiet",
        ],
        dir,
    ));
}

/// `rtid identify v/speed_loop.json` from `start`, one start, fitting `fit`; the
/// result file's JSON.
fn identify(dir: &Path, start: &[&str], fit: Option<&str>) -> (serde_json::Value, String) {
    let mut args = vec![
        "identify",
        "v/speed_loop.json",
        "--preset",
        "direct-drive",
        "--set",
        "Tc=1.25e-4",
        "--starts",
        "1",
        "--out",
        "fit.json",
    ];
    for s in start {
        args.extend(["--set", s]);
    }
    if let Some(f) = fit {
        args.extend(["--fit", f]);
    }
    let out = rtid(&args, dir);
    let stdout = ok(&out);
    let text = std::fs::read_to_string(dir.join("fit.json")).unwrap();
    (serde_json::from_str(&text).unwrap(), stdout)
}

/// The truth (the preset's Kvp 150, Kvi 9000 and the dead time 125 µs set) from 30
/// to 60 % off, with Jt held at its value: each within 1 % and within three of its
/// standard errors. 0.2 % noise: Kvi acts on the few lowest lines (3.9 Hz apart), its
/// standard error 0.24 % at this level (1.2 % at 1 %, where the fit still returns it
/// to 0.6 %).
#[test]
fn a_virtual_closed_loop_measurement_returns_its_truth_within_one_percent() {
    let dir = tempfile::tempdir().unwrap();
    measure(dir.path(), "0.2");
    let (v, _) = identify(
        dir.path(),
        &["Kvp=100", "Kvi=5000", "encoder_delay=2e-4"],
        None,
    );
    for (name, truth) in [("Kvp", 150.0), ("Kvi", 9000.0), ("encoder_delay", 1.25e-4)] {
        let x = v["parameters"][name].as_f64().unwrap();
        let se = standard_error(&v, name);
        let off = x / truth - 1.0;
        assert!(off.abs() < 0.01, "{name} = {x}, truth {truth}: {off:+.4}");
        assert!(
            (x - truth).abs() < 3.0 * se,
            "{name} = {x} ± {se}, truth {truth}"
        );
    }
    let rms = v["residuals"][0]["rms"].as_f64().unwrap_or(f64::NAN);
    assert!(
        (rms - 1.0).abs() < 0.1,
        "RMS scaled residual {rms}: the noise's own"
    );
}

/// Jt with Kvp and Kvi: T depends on Kvp/Jt and Kvi/Jt (and Ct/Jt) only, so the three
/// move together and the identification says the data cannot separate them.
#[test]
fn the_inertia_and_the_gains_are_not_separated() {
    let dir = tempfile::tempdir().unwrap();
    measure(dir.path(), "0.2");
    let (v, stdout) = identify(
        dir.path(),
        &["Kvp=100", "Kvi=5000", "Jt=0.3"],
        Some("Jt,Kvp,Kvi"),
    );
    let warnings = v["warnings"].to_string();
    assert!(
        warnings.contains("Jt") && warnings.contains("Kvp"),
        "{warnings}\n{stdout}"
    );
}

/// The standard error of `name` in a result file (pairs of name and value).
fn standard_error(v: &serde_json::Value, name: &str) -> f64 {
    v["uncertainty"]["standard_errors"]
        .as_array()
        .and_then(|pairs| pairs.iter().find(|p| p[0] == name))
        .and_then(|p| p[1].as_f64())
        .unwrap_or(f64::NAN)
}
