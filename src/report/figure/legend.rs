//! The legend: a strip under the plot (never over the data), one entry per named
//! series, each with the symbol its series is drawn with — a line, a dashed line or
//! a marker.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::Style;

/// Height of one row of entries, px.
const ROW: i32 = 22;
/// Where the entries start and must end, px from the left (the plot area's edges).
const LEFT: i32 = 86;
const RIGHT: i32 = 884;

/// One entry: the series' name, style and colour.
pub struct Entry {
    pub name: String,
    pub style: Style,
    /// Its markers too, where an unnamed series continues it with markers (a line
    /// through its points).
    pub marked: bool,
    pub colour: RGBColor,
}

/// The width of an entry, px: the symbol, the name (an estimate of the font's
/// advance) and a gap.
fn width(e: &Entry) -> i32 {
    30 + 8 * e.name.chars().count() as i32 + 24
}

/// Each entry's position (x, row), laid out left to right, wrapped at the right edge.
fn layout(entries: &[Entry]) -> Vec<(i32, i32)> {
    let (mut x, mut row) = (LEFT, 0);
    entries
        .iter()
        .map(|e| {
            if x > LEFT && x + width(e) > RIGHT {
                (x, row) = (LEFT, row + 1);
            }
            let at = (x, row);
            x += width(e);
            at
        })
        .collect()
}

/// The strip's height for `entries`, px (0 without any).
pub fn height(entries: &[Entry]) -> u32 {
    match layout(entries).last() {
        Some(&(_, rows)) => ((rows + 1) * ROW + 8) as u32,
        None => 0,
    }
}

/// Draws `entries` on `area` (the strip).
pub fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    for (e, (x, row)) in entries.iter().zip(layout(entries)) {
        let y = 4 + row * ROW + ROW / 2;
        match e.style {
            Style::Line => area.draw(&PathElement::new(
                vec![(x, y), (x + 22, y)],
                e.colour.stroke_width(2),
            ))?,
            Style::Dashed => {
                for x0 in [x, x + 8, x + 16] {
                    area.draw(&PathElement::new(
                        vec![(x0, y), (x0 + 5, y)],
                        e.colour.stroke_width(1),
                    ))?;
                }
            }
            Style::Markers => {}
        }
        if e.marked || e.style == Style::Markers {
            area.draw(&Circle::new((x + 11, y), 3, e.colour.filled()))?;
        }
        let font = ("sans-serif", 15).into_font().color(&BLACK);
        let style = font.pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(e.name.clone(), (x + 30, y), style))?;
    }
    Ok(())
}
