//! What a map that names no channel is told: the closest few names by edit distance
//! (a matrix's signals counted as one, spelled `rec.q(i,:), i = 1…6`) and how many
//! others there are — never the thousands a robot's MAT-file holds — or, for a
//! matrix indexed the other way round, how its signals are spelled.

use crate::io::formats::{Group, Recording};

/// Names listed whole when a file has at most this many; else the closest few.
const LIST_ALL: usize = 10;
/// How many of the closest names are given.
const CLOSEST: usize = 5;

/// The text after "no channel `wanted`": the matrix `wanted` indexes, or the names
/// nearest to it and the count of the rest.
pub fn suggestion(wanted: &str, recordings: &[&Recording]) -> String {
    let base = base_name(wanted);
    if let Some(group) = recordings
        .iter()
        .flat_map(|r| &r.groups)
        .find(|g| g.name == base)
    {
        return format!("; {}", describe(group));
    }
    let mut names = candidates(recordings);
    if names.is_empty() {
        return "; the file has none".to_string();
    }
    if names.len() > LIST_ALL {
        names.sort_by_cached_key(|c| {
            let compared = if c.is_array { base } else { wanted };
            strsim::levenshtein(compared, &c.name)
        });
    }
    let shown = names.len().min(if names.len() > LIST_ALL {
        CLOSEST
    } else {
        LIST_ALL
    });
    let listed: Vec<String> = names[..shown]
        .iter()
        .map(|c| format!("`{}`", c.shown))
        .collect();
    let rest = names.len() - shown;
    if rest == 0 {
        format!("; the file has {}", listed.join(", "))
    } else {
        format!(
            "; the closest: {} (and {rest} more: rtid import FILE --list --filter TEXT)",
            listed.join(", ")
        )
    }
}

/// `rec.q` is a 6×2501 matrix, one signal per row: `rec.q(i,:), i = 1…6`.
pub fn describe(group: &Group) -> String {
    let per = if group.signals_in_rows {
        "row"
    } else {
        "column"
    };
    format!(
        "`{}` is a {} matrix, one signal per {per}: {}",
        group.name,
        group.shape_text(),
        group.spelling()
    )
}

/// A name a map may have meant: a channel, or an array whose signals are channels.
struct Candidate {
    /// What the wanted name is compared with (an array's name without its index).
    name: String,
    is_array: bool,
    /// As the message shows it.
    shown: String,
}

/// Every channel not cut from an array, and every array once.
fn candidates(recordings: &[&Recording]) -> Vec<Candidate> {
    let mut out = Vec::new();
    for r in recordings {
        let in_group = |i: usize| r.groups.iter().any(|g| g.channels.contains(&i));
        for (i, c) in r.channels.iter().enumerate() {
            if !in_group(i) {
                out.push(Candidate {
                    name: c.name.clone(),
                    is_array: false,
                    shown: c.name.clone(),
                });
            }
        }
        out.extend(r.groups.iter().map(|g| Candidate {
            name: g.name.clone(),
            is_array: true,
            shown: g.spelling(),
        }));
    }
    out
}

/// The name before a trailing index `(…)`: `rec.q(1,:)` → `rec.q`.
pub fn base_name(name: &str) -> &str {
    match name.trim_end().strip_suffix(')').and_then(|s| s.rfind('(')) {
        Some(open) => name[..open].trim_end(),
        None => name,
    }
}
