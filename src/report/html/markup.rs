//! Small HTML building blocks: escaping, number formats, tables and figures.

use crate::report::figure::{Figure, FigureError};

/// `text` safe inside HTML elements and quoted attributes: file names, warnings and
/// titles come from users and must never become markup.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A parameter value as `rtid identify` prints it (six significant digits,
/// exponent form), so the page can be checked against the terminal.
pub fn sci(v: f64) -> String {
    format!("{v:.5e}")
}

/// A value to two decimals (ISO 230-2 tables, arc-seconds or µm).
pub fn fixed(v: f64) -> String {
    format!("{v:.2}")
}

/// A table with a header row; every cell is escaped.
pub fn table<S: AsRef<str>>(header: &[S], rows: &[Vec<String>]) -> String {
    let mut html = String::from("<table>\n<thead><tr>");
    for h in header {
        html.push_str(&format!("<th>{}</th>", escape(h.as_ref())));
    }
    html.push_str("</tr></thead>\n<tbody>\n");
    for row in rows {
        html.push_str("<tr>");
        for cell in row {
            // Words read from the left, numbers line up on the right.
            let numeric = cell.trim_end_matches(" %").parse::<f64>().is_ok() || cell == "–";
            let class = if numeric { "" } else { " class=\"text\"" };
            html.push_str(&format!("<td{class}>{}</td>", escape(cell)));
        }
        html.push_str("</tr>\n");
    }
    html.push_str("</tbody>\n</table>\n");
    html
}

/// A definition list of (term, value) pairs; every text is escaped.
pub fn facts(pairs: &[(&str, String)]) -> String {
    let mut html = String::from("<dl class=\"facts\">\n");
    for (term, value) in pairs {
        html.push_str(&format!(
            "<dt>{}</dt><dd>{}</dd>\n",
            escape(term),
            escape(value)
        ));
    }
    html.push_str("</dl>\n");
    html
}

/// A rendered figure inside a `<figure>`.
pub fn figure(f: &Figure) -> Result<String, FigureError> {
    Ok(svg_block(&f.render()?))
}

/// An SVG document as an inline block. The XML namespace is dropped (HTML parsers
/// give inline `<svg>` its namespace) so the page names no URL at all, and a viewBox
/// is added where missing so the chart scales to the printed page instead of being
/// cut off.
pub fn svg_block(svg: &str) -> String {
    let mut svg = svg
        .replace(" xmlns=\"http://www.w3.org/2000/svg\"", "")
        .replace(" xmlns:xlink=\"http://www.w3.org/1999/xlink\"", "");
    if !svg.contains("viewBox") {
        if let Some((w, h)) = size(&svg) {
            svg = svg.replacen("<svg ", &format!("<svg viewBox=\"0 0 {w} {h}\" "), 1);
        }
    }
    format!("<figure class=\"chart\">\n{svg}\n</figure>\n")
}

/// The `width` and `height` attributes of an SVG's root element.
fn size(svg: &str) -> Option<(String, String)> {
    let root = &svg[svg.find("<svg")?..];
    let root = &root[..root.find('>')?];
    let attr = |name: &str| -> Option<String> {
        let start = root.find(&format!("{name}=\""))? + name.len() + 2;
        let len = root[start..].find('"')?;
        Some(root[start..start + len].to_string())
    };
    Some((attr("width")?, attr("height")?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markup_in_text_stays_text() {
        assert_eq!(
            escape("<script>\"a\" & 'b'</script>"),
            "&lt;script&gt;&quot;a&quot; &amp; &#39;b&#39;&lt;/script&gt;"
        );
    }

    #[test]
    fn an_svg_loses_its_namespace_url_and_gains_a_view_box() {
        let html = svg_block(
            "<svg width=\"900\" height=\"560\" xmlns=\"http://www.w3.org/2000/svg\"></svg>",
        );
        assert!(!html.contains("http"), "{html}");
        assert!(html.contains("viewBox=\"0 0 900 560\""), "{html}");
    }
}
