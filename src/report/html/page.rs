//! The page around the sections: title, table of contents with anchors, and the
//! inline style sheet (screen and A4 print).

use super::markup::escape;
use super::Section;

/// Screen layout and A4 printing: each section starts a new printed page, charts
/// and tables are not split, colours of the heat map are printed as shown.
const CSS: &str = r#"
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, Helvetica, Arial, sans-serif;
       margin: 2em auto; max-width: 60em; padding: 0 1em; color: #111; line-height: 1.4; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.3em; border-bottom: 2px solid #ccc; padding-bottom: 0.2em; margin-top: 2em; }
h3 { font-size: 1.05em; margin-top: 1.4em; }
.meta { color: #555; font-size: 0.9em; }
nav ol { padding-left: 1.5em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.85em; }
th, td { border: 1px solid #bbb; padding: 0.2em 0.5em; text-align: right; }
th { background: #f0f0f0; }
td:first-child, th:first-child, td.text { text-align: left; }
td { white-space: nowrap; }
td.text { white-space: normal; overflow-wrap: anywhere; }
dl.facts { display: grid; grid-template-columns: max-content auto; gap: 0.1em 1em; font-size: 0.9em; }
dl.facts dt { font-weight: 600; }
dl.facts dd { margin: 0; overflow-wrap: anywhere; }
figure.chart { margin: 0.8em 0; }
figure.chart svg { max-width: 100%; height: auto; }
table.heat td { text-align: center; min-width: 4em; }
.verdict { font-size: 1.2em; font-weight: 700; padding: 0.3em 0.6em; display: inline-block; }
.pass { background: #d8f0d8; color: #135c13; }
.fail { background: #f6d5d5; color: #8a1010; }
.none { background: #eee; color: #444; }
code { overflow-wrap: anywhere; }
* { -webkit-print-color-adjust: exact; print-color-adjust: exact; }
@page { size: A4; margin: 14mm; }
@media print {
  body { margin: 0; max-width: none; font-size: 10pt; }
  table { font-size: 7.5pt; }
  nav { break-after: page; }
  section.report { break-before: page; }
  figure.chart, table, dl.facts { break-inside: avoid; }
  h2, h3 { break-after: avoid; }
}
"#;

/// The anchor of section `i` (from 0).
pub fn anchor(i: usize) -> String {
    format!("section-{}", i + 1)
}

/// The whole page: `title`, the table of contents and each section.
pub fn page(title: &str, sections: &[Section]) -> String {
    let mut html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"generator\" content=\"rtid {version}\">\n<title>{t}</title>\n\
         <style>{CSS}</style>\n</head>\n<body>\n<header>\n<h1>{t}</h1>\n\
         <p class=\"meta\">Written by rtid {version}; {n} section{s}.</p>\n</header>\n",
        t = escape(title),
        version = escape(crate::version::VERSION),
        n = sections.len(),
        s = if sections.len() == 1 { "" } else { "s" },
    );
    html.push_str(&contents(sections));
    for (i, s) in sections.iter().enumerate() {
        html.push_str(&format!(
            "<section class=\"report\" id=\"{}\">\n<h2>{}</h2>\n<p class=\"meta\">{}: <code>{}</code></p>\n{}</section>\n",
            anchor(i),
            escape(&s.title),
            s.kind.name(),
            escape(&s.file.display().to_string()),
            s.body
        ));
    }
    html.push_str("</body>\n</html>\n");
    html
}

/// The table of contents: one link per section.
fn contents(sections: &[Section]) -> String {
    let mut html = String::from("<nav>\n<h2>Contents</h2>\n<ol>\n");
    for (i, s) in sections.iter().enumerate() {
        html.push_str(&format!(
            "<li><a href=\"#{}\">{}</a> — {} (<code>{}</code>)</li>\n",
            anchor(i),
            escape(&s.title),
            s.kind.name(),
            escape(&s.file.display().to_string())
        ));
    }
    html.push_str("</ol>\n</nav>\n");
    html
}
