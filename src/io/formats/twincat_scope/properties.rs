//! The property rows of a TwinCAT Scope channel header, split into one cell per
//! channel, and what rtid takes from them: names, units, sample times, and the
//! declared scaling (reported, not applied; see the module docs of
//! [`super`](crate::io::formats::twincat_scope)).

/// One property row: its key and its cells, grouped by time column.
#[derive(Debug)]
pub(super) struct Property<'a> {
    pub line: usize,
    pub key: &'a str,
    pub groups: Vec<Vec<&'a str>>,
}

/// The keys TwinCAT 3.4 writes (pytcs `helpers._channel_meta_keys` and the shared
/// exports). Needed to find a key containing the separator (`Unit ScaleFactor` in a
/// space-separated export); any other key is the row's first cell.
const KNOWN_KEYS: &[&str] = &[
    "Name",
    "SymbolComment",
    "Data-Type",
    "SampleTime[ms]",
    "SampleTime",
    "VariableSize",
    "SymbolBased",
    "IndexGroup",
    "IndexOffset",
    "SymbolName",
    "NetID",
    "Port",
    "Offset",
    "ScaleFactor",
    "BitMask",
    "Unit",
    "Unit ScaleFactor",
    "Unit Offset",
];

/// Rows whose values never contain a separator, so that their cells give the number
/// of channels in each group even when a name contains the separator.
const LAYOUT_KEYS: &[&str] = &[
    "Data-Type",
    "VariableSize",
    "SymbolBased",
    "IndexGroup",
    "IndexOffset",
    "Port",
    "BitMask",
    "NetID",
    "SymbolName",
];

/// The rows rtid reads; a note lists the others.
const USED_KEYS: &[&str] = &[
    "Name",
    "Unit",
    "SampleTime[ms]",
    "SampleTime",
    "Offset",
    "ScaleFactor",
    "Unit ScaleFactor",
    "Unit Offset",
];

pub(super) fn parse(line: usize, text: &str, sep: u8) -> Property<'_> {
    let key = key_of(text, sep);
    Property {
        line,
        key,
        groups: split_groups(text, key, char::from(sep)),
    }
}

/// The longest known key the row starts with, else its first cell.
fn key_of(text: &str, sep: u8) -> &str {
    let sep = char::from(sep);
    let known = KNOWN_KEYS
        .iter()
        .filter(|k| {
            text.strip_prefix(**k)
                .is_some_and(|r| r.is_empty() || r.starts_with(sep))
        })
        .max_by_key(|k| k.len());
    match known {
        Some(k) => &text[..k.len()],
        None => text.split(sep).next().unwrap_or(""),
    }
}

/// The cells after each repetition of the key.
fn split_groups<'a>(text: &'a str, key: &str, sep: char) -> Vec<Vec<&'a str>> {
    let tokens: Vec<&str> = text.split(sep).collect();
    let key_tokens: Vec<&str> = key.split(sep).collect();
    let k = key_tokens.len();
    let mut groups: Vec<Vec<&str>> = Vec::new();
    let mut i = 0;
    while i < tokens.len() {
        if tokens.len() - i >= k && tokens[i..i + k] == key_tokens[..] {
            groups.push(Vec::new());
            i += k;
            continue;
        }
        if let Some(g) = groups.last_mut() {
            g.push(tokens[i]);
        }
        i += 1;
    }
    groups
}

/// The number of channels in each group: from a row whose values cannot contain the
/// separator when there is one, else from the `Name` row.
pub(super) fn layout(
    names: &Property,
    props: &[Property],
    sep: u8,
) -> Result<Vec<usize>, (usize, String)> {
    let reference = props.iter().find(|p| LAYOUT_KEYS.contains(&p.key));
    let row = reference.unwrap_or(names);
    let mut counts: Vec<usize> = row.groups.iter().map(Vec::len).collect();
    if let (Some(last), Some(cells)) = (counts.last_mut(), row.groups.last()) {
        if *last > 0 && cells.last().is_some_and(|c| c.trim().is_empty()) {
            *last -= 1; // a separator ending the row
        }
    }
    if counts.is_empty() || counts.iter().all(|&c| c == 0) {
        return Err((names.line, "the `Name` row names no channel".into()));
    }
    if counts.len() != names.groups.len() {
        let msg = format!(
            "the `Name` row has {} time columns, the `{}` row (line {}) has {} (separator {:?})",
            names.groups.len(),
            row.key,
            row.line,
            counts.len(),
            char::from(sep)
        );
        return Err((names.line, msg));
    }
    Ok(counts)
}

/// One cell per channel, or why the row does not split into that.
pub(super) fn fit<'a>(
    prop: &Property<'a>,
    counts: &[usize],
    sep: u8,
) -> Result<Vec<&'a str>, String> {
    if prop.groups.len() != counts.len() {
        return Err(format!(
            "the `{}` row has {} time columns where the `Name` row has {}",
            prop.key,
            prop.groups.len(),
            counts.len()
        ));
    }
    let mut cells = Vec::with_capacity(counts.iter().sum());
    for (g, (group, &n)) in prop.groups.iter().zip(counts).enumerate() {
        let trailing = g + 1 == counts.len()
            && group.len() == n + 1
            && group.last().is_some_and(|c| c.trim().is_empty());
        let group = if trailing { &group[..n] } else { &group[..] };
        if group.len() != n {
            return Err(format!(
                "the `{}` row has {} cells for the {} channels of time column {}: \
                 a value contains the separator {:?}, so the values cannot be told apart \
                 (export again with another separator)",
                prop.key,
                group.len(),
                n,
                g + 1,
                char::from(sep)
            ));
        }
        cells.extend_from_slice(group);
    }
    Ok(cells)
}

/// The units as the file spells them; `(None)` or nothing is "".
pub(super) fn units(
    props: &[Property],
    counts: &[usize],
    sep: u8,
    notes: &mut Vec<String>,
) -> Result<Vec<String>, (usize, String)> {
    let total = counts.iter().sum();
    let Some(row) = props.iter().find(|p| p.key == "Unit") else {
        return Ok(vec![String::new(); total]);
    };
    match fit(row, counts, sep) {
        Ok(cells) => Ok(cells.iter().map(|c| unit_text(c)).collect()),
        Err(msg) if sep == b' ' => {
            let joined = join_units(row, counts).ok_or((row.line, msg))?;
            notes.push(format!(
                "line {}: the units of this space-separated export were split after each \
                 word in parentheses, as TwinCAT writes a unit (`V (Voltage)`, `(None)`)",
                row.line
            ));
            Ok(joined)
        }
        Err(msg) => Err((row.line, msg)),
    }
}

fn unit_text(cell: &str) -> String {
    match cell.trim() {
        "(None)" => String::new(),
        t => t.to_string(),
    }
}

/// Units of a space-separated row: each ends with a word in parentheses
/// (`dV (Voltage)`, `(None)`); an empty word is an empty unit.
fn join_units(row: &Property, counts: &[usize]) -> Option<Vec<String>> {
    if row.groups.len() != counts.len() {
        return None;
    }
    let mut units = Vec::new();
    for (group, &n) in row.groups.iter().zip(counts) {
        let before = units.len();
        let mut words: Vec<&str> = Vec::new();
        for w in group {
            match (words.is_empty(), w.is_empty()) {
                (true, true) => units.push(String::new()),
                (false, true) => return None,
                _ => {
                    words.push(w);
                    if w.ends_with(')') {
                        units.push(unit_text(&words.join(" ")));
                        words.clear();
                    }
                }
            }
        }
        if !words.is_empty() || units.len() - before != n {
            return None;
        }
    }
    Some(units)
}

/// One number per channel from the first of `keys` present, or `None` (with a note
/// when the row is there but unreadable). A decimal comma is read as a point: TwinCAT
/// writes `SampleTime[ms]` with the comma whatever the export's decimal mark.
pub(super) fn numbers(
    props: &[Property],
    keys: &[&str],
    counts: &[usize],
    sep: u8,
    notes: &mut Vec<String>,
) -> Option<Vec<f64>> {
    let row = props.iter().find(|p| keys.contains(&p.key))?;
    let parsed = fit(row, counts, sep).and_then(|cells| {
        cells
            .iter()
            .map(|c| {
                let t = c.trim().replace(',', ".");
                t.parse::<f64>()
                    .map_err(|_| format!("`{c}` is not a number"))
            })
            .collect::<Result<Vec<f64>, String>>()
    });
    match parsed {
        Ok(v) => Some(v),
        Err(m) => {
            notes.push(format!("line {}: not used: {m}", row.line));
            None
        }
    }
}

/// A note naming the channels whose header declares a scaling.
pub(super) fn note_scaling(
    props: &[Property],
    counts: &[usize],
    sep: u8,
    names: &[&str],
    notes: &mut Vec<String>,
) {
    let factors = [
        ("ScaleFactor", 1.0),
        ("Offset", 0.0),
        ("Unit ScaleFactor", 1.0),
        ("Unit Offset", 0.0),
    ];
    let rows: Vec<Option<Vec<f64>>> = factors
        .iter()
        .map(|(k, _)| numbers(props, &[k], counts, sep, notes))
        .collect();
    let mut scaled = Vec::new();
    for (i, name) in names.iter().enumerate() {
        let parts: Vec<String> = factors
            .iter()
            .zip(&rows)
            .filter_map(|((key, identity), row)| {
                let v = row.as_ref()?[i];
                (v != *identity).then(|| format!("{key} {v}"))
            })
            .collect();
        if !parts.is_empty() {
            scaled.push(format!("`{name}` ({})", parts.join(", ")));
        }
    }
    if !scaled.is_empty() {
        notes.push(format!(
            "values returned as written for the channels declaring a scaling: {}. TwinCAT \
             applies y = ScaleFactor·x + Offset, then Unit ScaleFactor·y + Unit Offset, at \
             export only when \"Scale values before export\" is set, which the file does not \
             record: the values may be raw or scaled",
            scaled.join(", ")
        ));
    }
}

/// A note listing the header rows rtid does not use.
pub(super) fn note_unused(props: &[Property], notes: &mut Vec<String>) {
    let unused: Vec<&str> = props
        .iter()
        .map(|p| p.key)
        .filter(|k| !USED_KEYS.contains(k))
        .collect();
    if !unused.is_empty() {
        notes.push(format!("header properties not used: {}", unused.join(", ")));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_with_a_space_in_a_space_separated_row() {
        let p = parse(22, "Unit ScaleFactor 1 Unit ScaleFactor -10 1", b' ');
        assert_eq!(p.key, "Unit ScaleFactor");
        assert_eq!(p.groups, vec![vec!["1"], vec!["-10", "1"]]);
    }

    #[test]
    fn units_of_a_space_separated_row_split_after_parentheses() {
        let p = parse(21, "Unit (None) Unit dV (Voltage)  V (Voltage)", b' ');
        let mut notes = Vec::new();
        let got = units(&[p], &[1, 3], b' ', &mut notes).unwrap();
        assert_eq!(got, vec!["", "dV (Voltage)", "", "V (Voltage)"]);
        assert_eq!(notes.len(), 1);
    }

    #[test]
    fn a_name_containing_the_separator_is_refused() {
        let names = parse(7, "Name a b Name c", b' ');
        let types = parse(9, "Data-Type REAL32 Data-Type REAL32", b' ');
        let counts = layout(&names, &[types], b' ').unwrap();
        assert_eq!(counts, vec![1, 1]);
        let err = fit(&names, &counts, b' ').unwrap_err();
        assert!(
            err.contains("2 cells for the 1 channels of time column 1"),
            "{err}"
        );
    }
}
