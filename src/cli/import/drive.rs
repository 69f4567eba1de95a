//! `rtid import FILE --out DIR` for a drive's own measurement (a SINUMERIK/SINAMICS
//! measuring-function file), which says what it measured: no `--kind` or maps. Writes
//! the response from the drive's stored spectra (`NAME.json`) and, as a check, the
//! same recomputed from the file's time series with rtid's periodic estimator
//! (`NAME_time_series.json`), and says how the two agree.

use std::path::Path;

use anyhow::Context;
use serde_json::json;

use rtid::io::experiment_file::{self, Conditions, Manifest};
use rtid::io::formats::sinumerik_trace::response;
use rtid::io::import::{drive_measurement, Imported, Source};
use rtid::tuning::speed_loop::time_series;

/// The stored coherence above which the two responses are compared.
const COMPARED_ABOVE: f64 = 0.9;

/// Writes the experiments of the one drive measurement `source` into `out`.
pub fn write(
    source: &Source,
    out: &Path,
    name: Option<&str>,
    asked: (&Conditions, &[String], Option<String>),
    (json, quiet): (bool, bool),
) -> anyhow::Result<()> {
    let m = drive_measurement::measurement(&source.path)?;
    let (conditions, given, mechanism) = asked;
    let mut stored = drive_measurement::build(source, &m, conditions, given, mechanism)?;
    let r = response::stored_response(&m).map_err(|e| anyhow::anyhow!("{e}"))?;
    let estimate = time_series::recompute(&m).with_context(|| {
        format!(
            "{}: recomputing from the time series",
            source.path.display()
        )
    })?;
    let agreement = time_series::agreement(&r, &estimate, COMPARED_ABOVE);
    stored.findings.push(format!(
        "recomputed from the time series (rtid's periodic H1, the two directions as two \
         periods): on the {} lines of coherence ≥ {COMPARED_ABOVE}, within {:.2e} dB \
         (at {:.1} Hz) and {:.2e}° (at {:.1} Hz) of the drive's spectra",
        agreement.lines,
        agreement.max_gain_db,
        agreement.at_gain_hz,
        agreement.max_phase_deg,
        agreement.at_phase_hz
    ));
    if let Some(serde_json::Value::Object(import)) = stored.manifest.extra.get_mut("import") {
        import.insert("findings".into(), json!(stored.findings));
    }
    let name = name.unwrap_or("speed_loop");
    let paths = [
        out.join(format!("{name}.json")),
        out.join(format!("{name}_time_series.json")),
    ];
    for p in &paths {
        super::refuse_overwriting_inputs(p, std::slice::from_ref(&source.path))?;
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let recomputed = Imported {
        data: time_series::to_data(&estimate),
        manifest: recomputed_manifest(&stored.manifest),
        findings: Vec::new(),
    };
    for (path, imported) in paths.iter().zip([&stored, &recomputed]) {
        experiment_file::write(path, &imported.manifest, &imported.data)?;
    }
    report(&paths, [&stored, &recomputed], &agreement, json, quiet)
}

/// The stored response's manifest, noted as recomputed from the time series.
fn recomputed_manifest(stored: &Manifest) -> Manifest {
    let mut m = stored.clone();
    m.data = None;
    m.notes = Some(
        "recomputed by rtid from the file's time series (periodic H1 over the two \
         directions' periods), as a check of the drive's stored spectra"
            .into(),
    );
    m
}

fn report(
    paths: &[std::path::PathBuf; 2],
    imported: [&Imported; 2],
    agreement: &time_series::Agreement,
    json: bool,
    quiet: bool,
) -> anyhow::Result<()> {
    if json {
        let out = json!({
            "manifests": paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "kind": imported[0].manifest.kind.to_string(),
            "rows": imported[0].data.len(),
            "agreement": agreement,
            "findings": imported[0].findings,
        });
        println!("{}", rtid::io::json::pretty(&out)?);
        return Ok(());
    }
    for (p, i) in paths.iter().zip(imported) {
        println!(
            "wrote {} ({}, {} rows)",
            p.display(),
            i.manifest.kind,
            i.data.len()
        );
    }
    if !quiet {
        for f in &imported[0].findings {
            eprintln!("note: {f}");
        }
    }
    Ok(())
}
