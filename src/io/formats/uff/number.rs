//! Numbers as Fortran writes them in fixed-width fields.

/// Reads a Fortran real from a field (blanks around it ignored): what Rust's `f64`
/// parser takes (`-1.23456E+00`, `5.0e-5`, `12`), and the two Fortran spellings it does
/// not:
/// - a `D` exponent, the double-precision one (`1.0D+03`, `1.0d-3`);
/// - an exponent without its letter, which `Ew.d` editing writes when the exponent has
///   three digits (`1.23456-100` for 1.23456E-100, `0.12345+120`).
///
/// `None` when the field holds anything else (blank included: the caller decides what
/// a blank field means).
pub fn parse_real(field: &[u8]) -> Option<f64> {
    let field = field.trim_ascii();
    if field.is_empty() || !field.is_ascii() {
        return None;
    }
    // ASCII, checked above
    let text = std::str::from_utf8(field).ok()?;
    if let Ok(v) = text.parse::<f64>() {
        return Some(v);
    }
    fortran_spelling(field)?.parse::<f64>().ok()
}

/// The field with a `D` exponent made an `E`, or an `E` put before a sign that follows
/// a digit or the decimal point; `None` when neither applies.
fn fortran_spelling(field: &[u8]) -> Option<String> {
    if let Some(i) = field.iter().position(|&b| b == b'D' || b == b'd') {
        let mut s = String::from_utf8(field.to_vec()).ok()?;
        s.replace_range(i..=i, "E");
        return Some(s);
    }
    let sign = field
        .iter()
        .enumerate()
        .skip(1)
        .find(|&(i, &b)| {
            (b == b'+' || b == b'-') && (field[i - 1].is_ascii_digit() || field[i - 1] == b'.')
        })
        .map(|(i, _)| i)?;
    let mut s = String::from_utf8(field.to_vec()).ok()?;
    s.insert(sign, 'E');
    Some(s)
}

/// Reads a Fortran integer field; a blank field is 0 (Fortran's reading of blanks).
pub fn parse_int(field: &str) -> Option<i64> {
    let field = field.trim();
    if field.is_empty() {
        return Some(0);
    }
    field.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_spellings_fortran_writes() {
        assert_eq!(parse_real(b" -1.23456E+00"), Some(-1.23456));
        assert_eq!(parse_real(b"  5.00000E-005"), Some(5e-5));
        assert_eq!(parse_real(b"   1.00000000000e-06"), Some(1e-6));
        assert_eq!(parse_real(b"1.0D+03"), Some(1000.0));
        assert_eq!(parse_real(b"-2.5d-1"), Some(-0.25));
        assert_eq!(parse_real(b" 1.23456-100"), Some(1.23456e-100));
        assert_eq!(parse_real(b" 0.12345+120"), Some(0.12345e120));
        assert_eq!(parse_real(b"12"), Some(12.0));
    }

    #[test]
    fn refuses_what_is_not_a_number() {
        for field in [
            &b""[..],
            b"   ",
            b"abc",
            b"1.0E+0x",
            b"1.2.3",
            b"--1",
            b"1.0 2.0",
            b"g\xb2",
        ] {
            assert_eq!(
                parse_real(field),
                None,
                "{:?}",
                String::from_utf8_lossy(field)
            );
        }
    }

    #[test]
    fn integers_read_blank_as_zero() {
        assert_eq!(parse_int("   58"), Some(58));
        assert_eq!(parse_int("  -3"), Some(-3));
        assert_eq!(parse_int("     "), Some(0));
        assert_eq!(parse_int(" 1.5"), None);
    }
}
