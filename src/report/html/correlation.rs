//! The correlation matrix of a fit as a coloured table (a heat map that prints and
//! copies as text): red for positive, blue for negative, the stronger the darker.

use super::markup::escape;

/// A cell's background: white at 0, full red at +1, full blue at −1.
fn colour(r: f64) -> String {
    let r = if r.is_finite() {
        r.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let (base, a) = if r >= 0.0 {
        ((214.0, 39.0, 40.0), r)
    } else {
        ((31.0, 119.0, 180.0), -r)
    };
    let mix = |c: f64| (255.0 + (c - 255.0) * a).round() as u8;
    format!("rgb({},{},{})", mix(base.0), mix(base.1), mix(base.2))
}

/// The heat map of `correlation` (rows and columns in the order of `names`).
pub fn heat_map(names: &[String], correlation: &[Vec<f64>]) -> String {
    let mut html = String::from("<table class=\"heat\">\n<thead><tr><th></th>");
    for n in names {
        html.push_str(&format!("<th>{}</th>", escape(n)));
    }
    html.push_str("</tr></thead>\n<tbody>\n");
    for (name, row) in names.iter().zip(correlation) {
        html.push_str(&format!("<tr><th>{}</th>", escape(name)));
        for &r in row {
            let ink = if r.abs() > 0.6 { "#fff" } else { "#000" };
            html.push_str(&format!(
                "<td style=\"background:{};color:{ink}\">{r:.3}</td>",
                colour(r)
            ));
        }
        html.push_str("</tr>\n");
    }
    html.push_str("</tbody>\n</table>\n");
    html
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sign_picks_the_hue_and_the_size_its_strength() {
        assert_eq!(colour(0.0), "rgb(255,255,255)");
        assert_eq!(colour(1.0), "rgb(214,39,40)");
        assert_eq!(colour(-1.0), "rgb(31,119,180)");
        assert_eq!(colour(f64::NAN), "rgb(255,255,255)");
    }
}
