//! `rtid identify --uncertain`: how the fit follows the held parameters' ranges,
//! computed after the fit, and its table.

use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};
use rtid::identify::intervals::held;
use rtid::identify::IdentifyResult;
use rtid::identify::Settings;
use rtid::model::Params;
use rtid::names::Num;
use rtid::objectives::Objective;

/// The fit's response to each held parameter's range (name, value, relative
/// half-width), added to `result` as `held`.
pub fn add_held(
    ranges: &[(String, f64, f64)],
    result: &mut IdentifyResult,
    params: &Params,
    fit: (&dyn Objective, Settings),
) -> anyhow::Result<()> {
    let fit = held::Fit {
        result,
        params,
        objective: fit.0,
        settings: fit.1,
    };
    result.held = held::shifts(&fit, ranges)?;
    Ok(())
}

/// Each fitted parameter's 95 % interval with the held parameters' spread added
/// (√(se² + Σ shift²/3)), and each held parameter's shift of it.
pub fn held_table(r: &IdentifyResult) -> Option<Table> {
    if r.held.is_empty() {
        return None;
    }
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    let mut header = vec![
        "parameter".to_string(),
        "identified".into(),
        "95 % with the held ranges".into(),
    ];
    header.extend(
        r.held
            .iter()
            .map(|h| format!("{} ±{} %: shift", h.name, Num(100.0 * h.half_width))),
    );
    t.set_header(header);
    for (name, &v) in &r.parameters {
        let held: f64 = r.held.iter().map(|h| h.spread(name).powi(2)).sum();
        let se = r.standard_error(name);
        let mut row = vec![
            name.clone(),
            format!("{v:.5e}"),
            se.map_or("— (no standard error)".into(), |se| {
                let s = (se * se + held).sqrt();
                format!(
                    "{:.4e} … {:.4e} (±{:.2} %)",
                    v - 1.96 * s,
                    v + 1.96 * s,
                    196.0 * s / v.abs()
                )
            }),
        ];
        row.extend(r.held.iter().map(|h| {
            let s = h.shifts.get(name).copied().unwrap_or(0.0);
            format!("{s:+.3e} ({:+.2} %)", 100.0 * s / v.abs())
        }));
        t.add_row(row);
    }
    Some(t)
}
