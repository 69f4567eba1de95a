//! `rtid evaluate` of a complex frequency response: the modal parameters of its
//! resonances (src/experiments/frequency_response/modal.rs) against the exact ones of
//! the linear two-mass model, and the phase and Nyquist plots; without a phase, the
//! gain's peaks only.

use std::path::Path;

use serde_json::Value;

use crate::cli_support::{ok, rtid};

/// The two-mass preset (fixtures/presets/two-mass.json): Jt 2e-4 kg·m², Kw 23 N·m/rad,
/// Ciw 1.92e-3 and Ct 1e-4 N·m·s/rad. The table's equation with the motor angle
/// imposed, Jt·θt'' + Ct·θt' + Ciw·(θt' − θm') + Kw·(θt − θm) = 0, gives the table over
/// the motor (Rg·Rw = 1) H = (Kw + s·Ciw)/(Jt·s² + (Ciw + Ct)·s + Kw): one pole pair
/// with ω₀² = Kw/Jt and 2ζω₀ = (Ciw + Ct)/Jt — 53.972 Hz and ζ = 0.014892.
fn exact_mode() -> (f64, f64) {
    let (jt, kw, ciw, ct) = (2.0e-4_f64, 23.0_f64, 1.92e-3_f64, 1.0e-4_f64);
    let w0 = (kw / jt).sqrt();
    (w0 / std::f64::consts::TAU, (ciw + ct) / jt / (2.0 * w0))
}

fn virtual_frf(dir: &Path) {
    ok(&rtid(
        &[
            "experiment",
            "frequency-response",
            "--preset",
            "two-mass",
            "--linear",
            "--complex-noise-percent",
            "1",
            "--from-hz",
            "10",
            "--to-hz",
            "150",
            "--step-hz",
            "0.5",
            "--out",
            "frf",
            "--quiet",
        ],
        dir,
    ));
}

#[test]
fn the_motor_held_mode_of_a_virtual_complex_frf_is_its_exact_pole_within_three_se() {
    let (f0, zeta) = exact_mode();
    assert!((f0 - 53.972).abs() < 1e-3 && (zeta - 0.014892).abs() < 1e-6);
    let dir = tempfile::tempdir().unwrap();
    virtual_frf(dir.path());
    let out = ok(&rtid(
        &["evaluate", "frf/frequency_response.json", "--json"],
        dir.path(),
    ));
    let v: Value = serde_json::from_str(&out).unwrap();
    let modes = v["modes"].as_array().expect("modes");
    assert_eq!(modes.len(), 1, "{out}");
    let pole = &modes[0]["pole"];
    let num = |k: &str| pole[k].as_f64().unwrap_or_else(|| panic!("{k}: {out}"));
    let (f, f_se) = (num("frequency_hz"), num("frequency_se_hz"));
    let (z, z_se) = (num("damping_ratio"), num("damping_se"));
    eprintln!("f = {f} ± {f_se} Hz (exact {f0}), ζ = {z} ± {z_se} (exact {zeta})");
    assert!((f - f0).abs() < 3.0 * f_se, "{f} ± {f_se} against {f0}");
    assert!((z - zeta).abs() < 3.0 * z_se, "{z} ± {z_se} against {zeta}");
    // The standard errors are those of 1 % noise, not vacuous.
    assert!(f_se < 0.02 && z_se < 5e-4, "{out}");
    // The table over the motor has no zero pair.
    assert!(modes[0]["zero"].is_null(), "{out}");
    for svg in ["", "_phase", "_nyquist"] {
        let path = dir.path().join(format!("frf/frequency_response{svg}.svg"));
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("<svg"), "{}", path.display());
    }
    let phase = std::fs::read_to_string(dir.path().join("frf/frequency_response_phase.svg"));
    assert!(phase.unwrap().contains("unwrapped"));
    // The table names the mode.
    let text = ok(&rtid(
        &["evaluate", "frf/frequency_response.json"],
        dir.path(),
    ));
    assert!(text.contains("ζ = 0.01"), "{text}");
}

#[test]
fn without_a_phase_only_the_gain_peaks_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    virtual_frf(dir.path());
    // The same file with its phase column taken out.
    let csv = dir.path().join("frf/frequency_response.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut phase_column = None;
    let kept: Vec<String> = text
        .lines()
        .map(|line| {
            if line.starts_with('#') {
                return line.to_string();
            }
            let cells: Vec<&str> = line.split(',').collect();
            let k = *phase_column
                .get_or_insert_with(|| cells.iter().position(|c| *c == "phase_deg").unwrap());
            let mut cells = cells;
            cells.remove(k);
            cells.join(",")
        })
        .collect();
    std::fs::write(&csv, kept.join("\n") + "\n").unwrap();
    for svg in ["_phase", "_nyquist"] {
        let _ = std::fs::remove_file(dir.path().join(format!("frf/frequency_response{svg}.svg")));
    }
    let out = ok(&rtid(
        &["evaluate", "frf/frequency_response.json", "--json"],
        dir.path(),
    ));
    let v: Value = serde_json::from_str(&out).unwrap();
    assert!(v.get("modes").is_none(), "{out}");
    assert!(!v["peaks"].as_array().unwrap().is_empty(), "{out}");
    let text = ok(&rtid(
        &["evaluate", "frf/frequency_response.json"],
        dir.path(),
    ));
    assert!(text.contains("modal damping needs the phase"), "{text}");
    assert!(!dir.path().join("frf/frequency_response_phase.svg").exists());
}

/// A gain of pure noise (6 dB, phase uniform) over 100 000 lines is no drive's
/// response: its peaks above the curve's own noise are counted and said, its highest
/// few fitted, and the output fits a screen (before: a "resonance" per local maximum,
/// 15 MB for 400 000 lines).
#[test]
fn a_noise_like_curve_lists_a_few_modes_and_says_why() {
    use rand::{rngs::StdRng, Rng, SeedableRng};
    use rand_distr::{Distribution, Normal};
    let dir = tempfile::tempdir().unwrap();
    let mut rng = StdRng::seed_from_u64(11);
    let gain = Normal::new(0.0, 6.0).unwrap();
    let mut csv = String::from("frequency_hz,gain_db,phase_deg\n");
    for k in 0..100_000 {
        let phase: f64 = rng.random_range(-180.0..180.0);
        let line = format!(
            "{},{},{phase}\n",
            1.0 + 0.01 * k as f64,
            gain.sample(&mut rng)
        );
        csv.push_str(&line);
    }
    std::fs::write(dir.path().join("noise.csv"), csv).unwrap();
    let manifest = r#"{"kind": "frequency_response", "data": "noise.csv", "conditions": {}}"#;
    std::fs::write(dir.path().join("noise.json"), manifest).unwrap();
    let text = ok(&rtid(&["evaluate", "noise.json"], dir.path()));
    assert!(text.len() < 5000, "{} bytes:\n{text}", text.len());
    assert!(text.contains("noise-like"), "{text}");
    let out = ok(&rtid(&["evaluate", "noise.json", "--json"], dir.path()));
    let v: Value = serde_json::from_str(&out).unwrap();
    let prominent = v["prominent_peaks"].as_u64().expect("prominent_peaks");
    let fitted = v["modes"].as_array().expect("modes").len() as u64;
    assert!(
        prominent > 100 && fitted == 12,
        "{prominent} prominent, {fitted} fitted"
    );
}
