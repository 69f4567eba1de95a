//! A dataset 58 as a [`Channel`]: its name, unit, abscissa and samples, and the note
//! that keeps what a channel has no field for (function type, response and
//! reference).

use std::collections::HashSet;

use super::header::{Axis, Header58, Point};
use crate::io::formats::{Abscissa, Channel, Samples};

/// The names given so far in a file, to make repeated ones unique.
#[derive(Debug, Default)]
pub struct Names {
    used: HashSet<String>,
}

impl Names {
    /// `base` the first time; then `base #2`, `base #3`… (the first of those not taken
    /// by a name in the file itself).
    pub fn unique(&mut self, base: &str) -> String {
        let mut name = base.to_string();
        let mut k = 1;
        while self.used.contains(&name) {
            k += 1;
            name = format!("{base} #{k}");
        }
        self.used.insert(name.clone());
        name
    }
}

/// True for a label the description marks unused: blank or `NONE`.
fn unused(label: &str) -> bool {
    label.is_empty() || label == "NONE"
}

/// A direction code (record 6 fields 7 and 10): `S` scalar, `+X` `-Y` `+Z` for
/// translations, `+RX` `-RY` `+RZ` for rotations, the number itself when none of these.
pub fn direction(code: i64) -> String {
    const AXES: [&str; 6] = ["X", "Y", "Z", "RX", "RY", "RZ"];
    let axis = usize::try_from(code.unsigned_abs())
        .ok()
        .and_then(|a| a.checked_sub(1))
        .and_then(|a| AXES.get(a));
    match (code, axis) {
        (0, _) => "S".to_string(),
        (c, Some(a)) if c > 0 => format!("+{a}"),
        (_, Some(a)) => format!("-{a}"),
        (c, None) => c.to_string(),
    }
}

/// `node:direction`, then the entity name in brackets when there is one.
fn point(p: &Point) -> String {
    let at = format!("{}:{}", p.node, direction(p.direction));
    if unused(&p.entity) {
        at
    } else {
        format!("{at} ({})", p.entity)
    }
}

/// The channel's name before it is made unique: ID line 1, or, when it is blank or
/// `NONE`, `resp NODE:DIR / ref NODE:DIR` from record 6.
pub fn base_name(header: &Header58) -> String {
    if unused(&header.id1) {
        let (r, f) = (&header.dof.response, &header.dof.reference);
        format!(
            "resp {}:{} / ref {}:{}",
            r.node,
            direction(r.direction),
            f.node,
            direction(f.direction)
        )
    } else {
        header.id1.clone()
    }
}

/// The ordinate's unit as the file spells it: record 9's units label, over record 10's
/// when that is given (`m/N`; `(N/m)` in brackets when it holds a `/`, `*`, `·` or a
/// blank; `1/N` without a numerator); empty when neither is given.
pub fn unit(numerator: &Axis, denominator: &Axis) -> String {
    let num = if unused(&numerator.unit) {
        ""
    } else {
        numerator.unit.as_str()
    };
    if unused(&denominator.unit) {
        return num.to_string();
    }
    let den = &denominator.unit;
    let den = if den.contains(['/', '*', '·', ' ']) {
        format!("({den})")
    } else {
        den.clone()
    };
    format!("{}/{den}", if num.is_empty() { "1" } else { num })
}

/// The note on a channel: the dataset's line, function type, response, reference and
/// ordinate type, e.g. `H11: dataset 58 at line 17, function type 4 (frequency
/// response function), response 1:+Z, reference 1:+Z, complex double-precision
/// ordinate`.
pub fn note(name: &str, header: &Header58, binary: bool, start: usize) -> String {
    let dof = &header.dof;
    format!(
        "{name}: dataset 58{} at line {start}, function type {} ({}), response {}, reference {}, {}",
        if binary { "b" } else { "" },
        dof.function_type,
        function_name(dof.function_type),
        point(&dof.response),
        point(&dof.reference),
        header.form.ordinate.describe()
    )
}

/// The channel of a dataset whose values are in `columns` (abscissa first for uneven
/// spacing, then real part, then imaginary part for complex data).
pub fn channel(name: String, header: &Header58, columns: Vec<Vec<f64>>) -> Channel {
    let form = &header.form;
    let abscissa_unit = abscissa_unit(&header.abscissa).0;
    let mut columns = columns.into_iter();
    let abscissa = if form.even {
        Abscissa::Uniform {
            start: form.start,
            step: form.step,
            unit: abscissa_unit,
        }
    } else {
        Abscissa::Values {
            values: columns.next().unwrap_or_default(),
            unit: abscissa_unit,
        }
    };
    let re = columns.next().unwrap_or_default();
    let samples = if form.ordinate.is_complex() {
        Samples::Complex {
            re,
            im: columns.next().unwrap_or_default(),
        }
    } else {
        Samples::Real(re)
    };
    Channel {
        name,
        unit: unit(&header.ordinate, &header.denominator),
        abscissa,
        samples,
        first_line: None,
    }
}

/// Record 8's units label, or, when it says nothing (blank or `NONE`, as pyuff writes
/// by default), the unit its specific data type (field 1) implies — 17 time: `s`, 18
/// frequency: `Hz` (the dataset 58 description's codes) — with the note to say so;
/// empty when neither tells.
pub fn abscissa_unit(axis: &Axis) -> (String, Option<String>) {
    if !unused(&axis.unit) {
        return (axis.unit.clone(), None);
    }
    let (unit, what) = match axis.specific_type {
        17 => ("s", "time"),
        18 => ("Hz", "frequency"),
        _ => return (String::new(), None),
    };
    let note = format!(
        "its abscissa's units label says nothing (`{}`); its data type {} ({what}) gives {unit}",
        axis.unit, axis.specific_type
    );
    (unit.to_string(), Some(note))
}

/// The name of a function type (record 6 field 1) in the dataset 58 description.
pub fn function_name(function_type: i64) -> &'static str {
    const NAMES: [&str; 28] = [
        "general or unknown",
        "time response",
        "auto spectrum",
        "cross spectrum",
        "frequency response function",
        "transmissibility",
        "coherence",
        "auto correlation",
        "cross correlation",
        "power spectral density",
        "energy spectral density",
        "probability density function",
        "spectrum",
        "cumulative frequency distribution",
        "peaks valley",
        "stress/cycles",
        "strain/cycles",
        "orbit",
        "mode indicator function",
        "force pattern",
        "partial power",
        "partial coherence",
        "eigenvalue",
        "eigenvector",
        "shock response spectrum",
        "finite impulse response filter",
        "multiple coherence",
        "order function",
    ];
    usize::try_from(function_type)
        .ok()
        .and_then(|i| NAMES.get(i))
        .copied()
        .unwrap_or("not in the dataset 58 description")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(unit: &str) -> Axis {
        Axis {
            specific_type: 0,
            label: String::new(),
            unit: unit.to_string(),
        }
    }

    #[test]
    fn repeated_names_are_numbered_from_the_second() {
        let mut names = Names::default();
        assert_eq!(names.unique("H11"), "H11");
        assert_eq!(names.unique("H11 #2"), "H11 #2");
        assert_eq!(names.unique("H11"), "H11 #3");
        assert_eq!(names.unique("H11"), "H11 #4");
    }

    #[test]
    fn directions_as_modal_software_writes_them() {
        let got: Vec<String> = [0, 1, -2, 3, 4, -6, 7, -9]
            .into_iter()
            .map(direction)
            .collect();
        assert_eq!(got, ["S", "+X", "-Y", "+Z", "+RX", "-RZ", "7", "-9"]);
    }

    #[test]
    fn an_abscissa_without_a_label_takes_its_data_types_unit() {
        let typed = |specific_type: i64, unit: &str| Axis {
            specific_type,
            label: "NONE".into(),
            unit: unit.into(),
        };
        assert_eq!(abscissa_unit(&typed(18, "NONE")).0, "Hz");
        assert_eq!(abscissa_unit(&typed(17, "")).0, "s");
        assert!(abscissa_unit(&typed(18, "NONE"))
            .1
            .unwrap()
            .contains("data type 18"));
        assert_eq!(abscissa_unit(&typed(18, "rad/s")), ("rad/s".into(), None));
        assert_eq!(abscissa_unit(&typed(0, "NONE")), (String::new(), None));
        assert_eq!(abscissa_unit(&typed(12, "NONE")), (String::new(), None));
    }

    #[test]
    fn units_over_a_denominator() {
        assert_eq!(unit(&axis("m/s²"), &axis("NONE")), "m/s²");
        assert_eq!(unit(&axis("m"), &axis("N")), "m/N");
        assert_eq!(unit(&axis("g"), &axis("N/m")), "g/(N/m)");
        assert_eq!(unit(&axis("NONE"), &axis("N")), "1/N");
        assert_eq!(unit(&axis(""), &axis("")), "");
    }
}
