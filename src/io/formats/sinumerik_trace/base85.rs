//! The base85 of the SAT library's `<raw>` arrays (format `base85` on their
//! `NumericArray`): not Ascii85 nor RFC 1924 but a third alphabet,
//!
//! ```text
//! 0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ!#$`()*+-/:;=?@[]^_{|}~
//! ```
//!
//! five characters, most significant first, giving one big-endian 32-bit word; a single
//! `.` stands for a zero word (as Ascii85's `z` does). Two words, high first, are one
//! big-endian IEEE-754 double; a complex array interleaves real and imaginary parts.
//! White space between groups is layout. Checked on the shared file: its frequency
//! vectors decode to 0, 3.9139 … 4000 Hz (the file's bandwidth over its lines) and its
//! time series to the offset ± the amplitude its own fields state.

/// The alphabet, digit 0 first.
const ALPHABET: &[u8; 85] =
    b"0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ!#$`()*+-/:;=?@[]^_{|}~";

/// Why a `<raw>` text is not base85: at which byte of the text, and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Fault {
    /// 0-based byte offset in the text.
    pub at: usize,
    pub message: String,
}

/// The digit of `c`, if it is one.
fn digit(c: u8) -> Option<u32> {
    ALPHABET.iter().position(|&a| a == c).map(|d| d as u32)
}

/// The 32-bit words of `text`. White space is layout wherever it falls: the files
/// break their lines every so many characters, inside a group as often as not.
fn words(text: &str) -> Result<Vec<u32>, Fault> {
    let mut out = Vec::with_capacity(text.len() / 5 + 1);
    let mut chars = text
        .bytes()
        .enumerate()
        .filter(|(_, c)| !c.is_ascii_whitespace());
    while let Some((at, c)) = chars.next() {
        if c == b'.' {
            out.push(0);
            continue;
        }
        out.push(group(at, c, &mut chars)?);
    }
    Ok(out)
}

/// The word of the five-character group whose first character `first` is at byte
/// `start`, the other four taken from `rest`.
fn group(
    start: usize,
    first: u8,
    rest: &mut impl Iterator<Item = (usize, u8)>,
) -> Result<u32, Fault> {
    let mut value: u64 = 0;
    let mut next = Some((start, first));
    for n in 0..5 {
        let Some((at, c)) = next else {
            return Err(Fault {
                at: start,
                message: format!(
                    "a group of {n} base85 characters where 5 make a word: the text is cut"
                ),
            });
        };
        let d = digit(c).ok_or_else(|| Fault {
            at,
            message: format!(
                "`{}` is not a base85 digit of this alphabet",
                char::from(c).escape_default()
            ),
        })?;
        value = value * 85 + u64::from(d);
        if n < 4 {
            next = rest.next();
        }
    }
    u32::try_from(value).map_err(|_| Fault {
        at: start,
        message: format!("a group of value {value}, beyond a 32-bit word"),
    })
}

/// The doubles of `text`: pairs of words, high word first.
pub fn doubles(text: &str) -> Result<Vec<f64>, Fault> {
    let w = words(text)?;
    if w.len() % 2 != 0 {
        return Err(Fault {
            at: text.trim_end().len(),
            message: format!("{} words: a double takes two, so the text is cut", w.len()),
        });
    }
    Ok(w.chunks_exact(2)
        .map(|p| f64::from_bits((u64::from(p[0]) << 32) | u64::from(p[1])))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The text of `values` in this encoding, zero words as `.`.
    fn encode(values: &[f64]) -> String {
        let mut out = String::new();
        for v in values {
            let bits = v.to_bits();
            for word in [(bits >> 32) as u32, bits as u32] {
                if word == 0 {
                    out.push('.');
                    continue;
                }
                let mut digits = [0u8; 5];
                let mut w = word;
                for d in digits.iter_mut().rev() {
                    *d = ALPHABET[(w % 85) as usize];
                    w /= 85;
                }
                out.push_str(std::str::from_utf8(&digits).unwrap());
            }
        }
        out
    }

    #[test]
    fn doubles_round_trip_through_the_alphabet() {
        let values = [0.0, 1.0, -0.20944, 4000.0, f64::MAX, 3.9e-300, -0.0];
        let text = encode(&values);
        // Layout spaces and line ends are ignored, inside a group too.
        let spaced = format!("\n   {}\n  {}  ", &text[..7], &text[7..]);
        let back = doubles(&spaced).unwrap();
        assert_eq!(back.len(), values.len());
        for (a, b) in back.iter().zip(&values) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }

    /// 4000.0 is 0x40AF4000_00000000: its low word is zero, written `.`.
    #[test]
    fn a_zero_word_is_a_dot() {
        assert_eq!(encode(&[4000.0]).matches('.').count(), 1);
        assert_eq!(doubles(&encode(&[4000.0])).unwrap(), [4000.0]);
    }

    #[test]
    fn faults_name_the_byte_of_the_text() {
        let text = encode(&[1.5, 2.5]);
        let mut bad = text.clone().into_bytes();
        bad[3] = b'"';
        let e = doubles(std::str::from_utf8(&bad).unwrap()).unwrap_err();
        assert_eq!(e.at, 3);
        assert!(e.message.contains("not a base85 digit"), "{}", e.message);
        let cut = doubles(&text[..text.len() - 2]).unwrap_err();
        assert!(cut.message.contains("cut"), "{}", cut.message);
        let odd = doubles(&text[..5]).unwrap_err();
        assert!(odd.message.contains("two"), "{}", odd.message);
        let big = doubles("~~~~~~~~~~").unwrap_err();
        assert!(
            big.message.contains("beyond a 32-bit word"),
            "{}",
            big.message
        );
    }
}
