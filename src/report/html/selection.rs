//! The model-selection part of a page with several identifications: AIC, AICc, BIC,
//! Akaike weights and the F-tests of nested fits, as `rtid select` computes them
//! (`identify::selection`) — or why the fits cannot be compared.

use super::markup::{escape, sci, table};
use super::{Kind, Section};
use crate::identify::selection::{self, Selection};
use crate::identify::IdentifyResult;

/// The section comparing `fits` (label, result); `None` for fewer than two.
pub fn section(fits: &[(String, IdentifyResult)]) -> Option<Section> {
    if fits.len() < 2 {
        return None;
    }
    let body = match selection::select(fits) {
        Ok(s) => compared(&s),
        Err(e) => format!(
            "<p>The identifications on this page are not compared: {}.</p>\n",
            escape(&e.to_string())
        ),
    };
    Some(Section {
        kind: Kind::Selection,
        file: "(the identifications above)".into(),
        title: "Model selection".into(),
        body,
    })
}

/// The ranking and the F-tests.
fn compared(s: &Selection) -> String {
    let name = if s.criterion == "aicc" { "AICc" } else { "AIC" };
    let rows: Vec<Vec<String>> = s
        .candidates
        .iter()
        .map(|c| {
            vec![
                c.label.clone(),
                c.fitted.join(", "),
                c.n.to_string(),
                c.k.to_string(),
                sci(c.cost),
                format!("{:.2}", c.aic),
                c.aicc.map_or("—".into(), |v| format!("{v:.2}")),
                format!("{:.2}", c.bic),
                format!("{:.2}", c.delta),
                format!("{:.3}", c.weight),
            ]
        })
        .collect();
    let header = [
        "result", "fitted", "n", "k", "cost", "AIC", "AICc", "BIC", "Δ", "weight",
    ];
    let mut html = format!(
        "<p>Ranked by {name}, best first: Δ below 2 is no real preference, above 10 is \
         decisive; the weight is each fit's relative support.</p>\n{}",
        table(&header, &rows)
    );
    for n in &s.nested {
        html.push_str(&format!(
            "<p>F-test: {} adds {} to {}: F({}, {}) = {:.3}, p = {:.3e} — {}.</p>\n",
            escape(&n.full),
            escape(&n.added.join(", ")),
            escape(&n.restricted),
            n.df.0,
            n.df.1,
            n.f,
            n.p_value,
            escape(n.verdict())
        ));
    }
    html
}
