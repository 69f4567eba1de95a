//! The units labs write, by the quantity they measure, and their factor to SI: what
//! `--map ROLE=CHANNEL[*SCALE][:UNIT]` accepts as UNIT, and what a file's own unit
//! label is read as when the map gives none.

use std::f64::consts::PI;

/// What a unit measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    Time,
    Angle,
    Length,
    AngularVelocity,
    Velocity,
    Torque,
    Force,
    Current,
    Voltage,
    Frequency,
    /// A gain in decibels.
    Decibel,
    /// Per cent of a nominal value not given: only as `%(NOMINAL UNIT)`.
    Percent,
    /// Encoder increments without a resolution: only as `inc(N/UNIT)`.
    Increments,
    /// A plain number (a ratio, a count).
    Number,
}

impl Quantity {
    /// In words, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Time => "a time",
            Quantity::Angle => "an angle",
            Quantity::Length => "a length",
            Quantity::AngularVelocity => "an angular velocity",
            Quantity::Velocity => "a velocity",
            Quantity::Torque => "a torque",
            Quantity::Force => "a force",
            Quantity::Current => "a current",
            Quantity::Voltage => "a voltage",
            Quantity::Frequency => "a frequency",
            Quantity::Decibel => "a gain in dB",
            Quantity::Percent => "a per cent value",
            Quantity::Increments => "encoder increments",
            Quantity::Number => "a plain number",
        }
    }
}

/// A unit: how it is spelled, what it measures, SI per unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unit {
    pub symbol: &'static str,
    pub quantity: Quantity,
    pub si: f64,
}

const fn unit(symbol: &'static str, quantity: Quantity, si: f64) -> Unit {
    Unit {
        symbol,
        quantity,
        si,
    }
}

const DEG: f64 = PI / 180.0;
const RPM: f64 = 2.0 * PI / 60.0;

/// Every unit accepted, with the other spellings files use. Matched ignoring case
/// only where case cannot change the meaning (see [`lookup`]).
pub const UNITS: &[(Unit, &[&str])] = &[
    (unit("s", Quantity::Time, 1.0), &["sec"]),
    (unit("ms", Quantity::Time, 1e-3), &[]),
    (unit("µs", Quantity::Time, 1e-6), &["us", "μs"]),
    (unit("rad", Quantity::Angle, 1.0), &[]),
    (
        unit("deg", Quantity::Angle, DEG),
        &["°", "degree", "degrees"],
    ),
    (unit("arcsec", Quantity::Angle, DEG / 3600.0), &["″", "\""]),
    (
        unit("rev", Quantity::Angle, 2.0 * PI),
        &["r", "turn", "turns"],
    ),
    (unit("m", Quantity::Length, 1.0), &[]),
    (unit("mm", Quantity::Length, 1e-3), &[]),
    (unit("µm", Quantity::Length, 1e-6), &["um", "μm"]),
    (unit("nm", Quantity::Length, 1e-9), &[]),
    (unit("rad/s", Quantity::AngularVelocity, 1.0), &[]),
    (unit("deg/s", Quantity::AngularVelocity, DEG), &["°/s"]),
    (
        unit("rpm", Quantity::AngularVelocity, RPM),
        &["1/min", "min-1", "min^-1"],
    ),
    (unit("m/s", Quantity::Velocity, 1.0), &[]),
    (unit("mm/s", Quantity::Velocity, 1e-3), &[]),
    (unit("mm/min", Quantity::Velocity, 1e-3 / 60.0), &[]),
    (
        unit("N·m", Quantity::Torque, 1.0),
        &["Nm", "N.m", "N*m", "N m"],
    ),
    (
        unit("mN·m", Quantity::Torque, 1e-3),
        &["mNm", "mN.m", "mN*m", "mN m"],
    ),
    (unit("N", Quantity::Force, 1.0), &[]),
    (unit("A", Quantity::Current, 1.0), &[]),
    (unit("mA", Quantity::Current, 1e-3), &[]),
    (unit("V", Quantity::Voltage, 1.0), &[]),
    (unit("Hz", Quantity::Frequency, 1.0), &[]),
    (unit("dB", Quantity::Decibel, 1.0), &[]),
    (unit("%", Quantity::Percent, 0.01), &[]),
    (unit("inc", Quantity::Increments, 1.0), &[]),
    (unit("1", Quantity::Number, 1.0), &["-", ""]),
];

/// The unit spelled `text` (trimmed; `mN·m`, `mNm` and `mN.m` alike; a TwinCAT label
/// such as `V (Voltage)` by its first word), or `None`. Per cent and increments are
/// returned as such: [`parse`] resolves them against their nominal or resolution.
pub fn lookup(text: &str) -> Option<Unit> {
    let text = text.trim();
    let first = text.split(" (").next().unwrap_or(text).trim();
    for candidate in [text, first] {
        for (unit, aliases) in UNITS {
            if unit.symbol == candidate || aliases.contains(&candidate) {
                return Some(*unit);
            }
        }
    }
    None
}

/// Why a unit as `--map` writes it is refused: each message quotes the text given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum UnitError {
    #[error("`{text}`: write the nominal as %(VALUE UNIT), e.g. %(9.84 mN·m)")]
    NominalNotWritten { text: String },
    #[error(
        "`{text}`: write the resolution as inc(COUNT/UNIT), e.g. inc(4096/rev) or inc(1000/mm)"
    )]
    ResolutionNotWritten { text: String },
    #[error("`{text}`: increments per {}, an angle or a length expected", quantity.name())]
    IncrementsPerWhat { text: String, quantity: Quantity },
    #[error(
        "`{text}`: per cent of what? Write the nominal value: %(VALUE UNIT), e.g. %(9.84 mN·m)"
    )]
    PercentWithoutNominal { text: String },
    #[error(
        "`{text}`: increments need the encoder's resolution: inc(COUNT/UNIT), e.g. inc(4096/rev)"
    )]
    IncrementsWithoutResolution { text: String },
    /// A unit inside `%(…)` or `inc(…)` that is not a physical one.
    #[error("`{whole}`: unknown unit `{inner}` inside; accepted: {}", accepted())]
    UnknownInside { whole: String, inner: String },
    #[error("unknown unit `{text}`; accepted: {}", accepted())]
    Unknown { text: String },
}

/// A unit as `--map` writes it: a plain unit ([`lookup`]), `%(NOMINAL UNIT)` — per
/// cent of a nominal value, e.g. `%(9.84 mN·m)` for a drive's torque in per cent of
/// its nominal torque — or `inc(N/UNIT)` — encoder increments, N per UNIT of angle or
/// length, e.g. `inc(4096/rev)`, `inc(1000/mm)`. Returns the quantity measured and
/// SI per unit written.
pub fn parse(text: &str) -> Result<Unit, UnitError> {
    let text = text.trim();
    if let Some(inner) = bracketed(text, "%") {
        let (value, unit) = split_number(inner)
            .ok_or_else(|| UnitError::NominalNotWritten { text: text.into() })?;
        let nominal = physical(unit, text)?;
        return Ok(Unit {
            symbol: "%",
            quantity: nominal.quantity,
            si: value * nominal.si / 100.0,
        });
    }
    if let Some(inner) = bracketed(text, "inc") {
        let (count, unit) = inner
            .split_once('/')
            .and_then(|(n, u)| Some((n.trim().parse::<f64>().ok()?, u)))
            .filter(|(n, _)| n.is_finite() && *n > 0.0)
            .ok_or_else(|| UnitError::ResolutionNotWritten { text: text.into() })?;
        let per = physical(unit, text)?;
        if !matches!(per.quantity, Quantity::Angle | Quantity::Length) {
            return Err(UnitError::IncrementsPerWhat {
                text: text.into(),
                quantity: per.quantity,
            });
        }
        return Ok(Unit {
            symbol: "inc",
            quantity: per.quantity,
            si: per.si / count,
        });
    }
    match lookup(text) {
        Some(u) if u.quantity == Quantity::Percent => {
            Err(UnitError::PercentWithoutNominal { text: text.into() })
        }
        Some(u) if u.quantity == Quantity::Increments => {
            Err(UnitError::IncrementsWithoutResolution { text: text.into() })
        }
        Some(u) => Ok(u),
        None => Err(UnitError::Unknown { text: text.into() }),
    }
}

/// `INNER` of `NAME(INNER)`, or `None`.
fn bracketed<'a>(text: &'a str, name: &str) -> Option<&'a str> {
    text.strip_prefix(name)?
        .trim_start()
        .strip_prefix('(')?
        .strip_suffix(')')
}

/// A leading number and the rest: `9.84 mN·m` → (9.84, "mN·m").
fn split_number(text: &str) -> Option<(f64, &str)> {
    let text = text.trim();
    let end = text
        .char_indices()
        .find(|&(i, c)| {
            !(c.is_ascii_digit()
                || c == '.'
                || c == 'e'
                || c == 'E'
                || ((c == '-' || c == '+') && (i == 0 || text[..i].ends_with(['e', 'E']))))
        })
        .map_or(text.len(), |(i, _)| i);
    let value: f64 = text[..end].parse().ok()?;
    (value.is_finite() && value > 0.0).then_some((value, &text[end..]))
}

/// A plain physical unit inside a `%(…)` or `inc(…)`.
fn physical(text: &str, whole: &str) -> Result<Unit, UnitError> {
    match lookup(text) {
        Some(u)
            if !matches!(
                u.quantity,
                Quantity::Percent | Quantity::Increments | Quantity::Number
            ) =>
        {
            Ok(u)
        }
        _ => Err(UnitError::UnknownInside {
            whole: whole.into(),
            inner: text.trim().into(),
        }),
    }
}

/// The accepted units, for a message.
pub fn accepted() -> String {
    UNITS
        .iter()
        .map(|(u, _)| u.symbol)
        .filter(|s| *s != "1")
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spellings_of_one_unit_agree() {
        for text in ["mN·m", "mNm", "mN.m", " mNm "] {
            let u = lookup(text).unwrap();
            assert_eq!(u.quantity, Quantity::Torque);
            assert_eq!(u.si, 1e-3);
        }
        assert_eq!(lookup("V (Voltage)").unwrap().quantity, Quantity::Voltage);
        assert_eq!(lookup("rpm").unwrap().si, 2.0 * PI / 60.0);
        assert!(lookup("furlong").is_none());
    }

    #[test]
    fn per_cent_and_increments_carry_their_reference() {
        let torque = parse("%(9.84 mN·m)").unwrap();
        assert_eq!(torque.quantity, Quantity::Torque);
        assert!((torque.si - 9.84e-5).abs() < 1e-18);
        let angle = parse("inc(4096/rev)").unwrap();
        assert_eq!(angle.quantity, Quantity::Angle);
        assert!((angle.si - 2.0 * PI / 4096.0).abs() < 1e-18);
        let length = parse("inc(1000 / mm)").unwrap();
        assert_eq!(length.quantity, Quantity::Length);
        assert!((length.si - 1e-6).abs() < 1e-21);
        let message = |text: &str| parse(text).unwrap_err().to_string();
        assert!(message("%").contains("per cent of what"));
        assert!(message("inc").contains("resolution"));
        assert!(message("inc(4096/V)").contains("angle or a length"));
        assert_eq!(
            parse("%(0 N)"),
            Err(UnitError::NominalNotWritten {
                text: "%(0 N)".into()
            })
        );
        assert!(message("furlong").contains("accepted"));
    }

    #[test]
    fn case_matters_where_it_changes_the_meaning() {
        // mm is a millimetre, Mm would be a megametre: not accepted for it.
        assert!(lookup("Mm").is_none());
        assert_eq!(lookup("mm").unwrap().quantity, Quantity::Length);
        assert_eq!(lookup("ms").unwrap().quantity, Quantity::Time);
    }
}
