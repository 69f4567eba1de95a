//! Tests of the UFF reader on the fixtures of `fixtures/formats/uff/` (published
//! samples and files pyuff wrote; `expected.json` is what pyuff reads in them) and on
//! files made from them in the tests: quirks real writers produce, and broken files.

mod expected;
mod malformed;
mod quirks;

use std::path::{Path, PathBuf};

use crate::io::formats::{FormatError, Location, Recording, Samples};

/// A fixture of `fixtures/formats/uff/`.
fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/formats/uff")
        .join(name)
}

fn fixture_bytes(name: &str) -> Vec<u8> {
    std::fs::read(fixture(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Writes `bytes` to a file `name` in a fresh temporary folder and reads it.
fn read_bytes(
    name: &str,
    bytes: &[u8],
) -> (tempfile::TempDir, PathBuf, Result<Recording, FormatError>) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    let result = super::read(&path);
    (dir, path, result)
}

/// The samples of a real channel.
fn real(samples: &Samples) -> &[f64] {
    match samples {
        Samples::Real(v) => v,
        Samples::Complex { .. } => panic!("complex samples where real ones were expected"),
    }
}

/// Reads broken `bytes` and checks the one error: it names the file, is at
/// `location`, and says `words`.
fn assert_fault(bytes: &[u8], location: Location, words: &str) -> FormatError {
    let (_dir, path, result) = read_bytes("broken.uff", bytes);
    let err = match result {
        Ok(r) => panic!(
            "read a broken file: {} channels, notes {:?}",
            r.channels.len(),
            r.notes
        ),
        Err(e) => e,
    };
    let shown = err.to_string();
    assert_eq!(err.path, path, "{shown}");
    assert!(shown.starts_with(&path.display().to_string()), "{shown}");
    assert_eq!(err.location, location, "{shown}");
    match location {
        Location::Line(n) => assert!(shown.contains(&format!(", line {n}: ")), "{shown}"),
        Location::Byte(b) => assert!(shown.contains(&format!(", byte {b}: ")), "{shown}"),
        Location::File => {}
    }
    assert!(shown.contains(words), "'{words}' not in: {shown}");
    err
}

/// The lines of a text fixture, without their line ends.
fn text_lines(name: &str) -> Vec<String> {
    String::from_utf8(fixture_bytes(name))
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// Lines joined by `\n`, with a final line end.
fn joined(lines: &[String]) -> Vec<u8> {
    let mut text = lines.join("\n");
    text.push('\n');
    text.into_bytes()
}
