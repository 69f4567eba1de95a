//! What real writers do that the description does not, and what the fixtures alone do
//! not hold, made from the fixtures (the published samples and pyuff's files): each
//! variant must read as the file it was made from does.

use super::{fixture, fixture_bytes, joined, read_bytes, real, text_lines};
use crate::io::formats::uff::{read, sniff};
use crate::io::formats::{Abscissa, Recording, Samples};

const TIME_HISTORY: &str = "time-history-not-all-columns-filled.uff";
const ASCII_SAMPLE: &str = "Sample_UFF58_ascii.first4000.uff";
const BINARY_SAMPLE: &str = "Sample_UFF58b_bin.first4000.uff";
const SINGLE: &str = "pyuff_single.uff";

/// The first data line of the time-history sample (1-based line 14, after the
/// opening -1, the number and records 1-11).
const FIRST_DATA_LINE: usize = 13;

fn read_variant(bytes: &[u8]) -> Recording {
    let (_dir, _path, result) = read_bytes("variant.uff", bytes);
    result.unwrap_or_else(|e| panic!("{e}"))
}

fn samples_of(name: &str) -> Vec<f64> {
    real(&read(&fixture(name)).unwrap().channels[0].samples).to_vec()
}

/// The time-history sample with each data line rewritten by `f`.
fn time_history_with(f: impl Fn(&str) -> String) -> Vec<u8> {
    let mut lines = text_lines(TIME_HISTORY);
    let last = lines.iter().rposition(|l| l.trim() == "-1").unwrap();
    for line in &mut lines[FIRST_DATA_LINE..last] {
        *line = f(line);
    }
    joined(&lines)
}

#[test]
fn fortran_d_exponents_read_as_e() {
    let variant = time_history_with(|l| l.replace("E+", "D+").replace("E-", "d-"));
    assert!(String::from_utf8_lossy(&variant).contains("D+00"));
    let got = read_variant(&variant);
    assert_eq!(real(&got.channels[0].samples), samples_of(TIME_HISTORY));
}

#[test]
fn fields_that_run_together_are_read_by_their_columns() {
    // " -3.81956E+00" becomes "-3.81956E+000": 13 characters, no blank between fields
    let variant = time_history_with(|l| {
        l.split_whitespace()
            .map(|w| format!("{:>13}", w.replace("E+", "E+0").replace("E-", "E-0")))
            .collect()
    });
    assert!(String::from_utf8_lossy(&variant).contains("E+000-"));
    let got = read_variant(&variant);
    assert_eq!(real(&got.channels[0].samples), samples_of(TIME_HISTORY));
    assert!(
        !got.notes.iter().any(|n| n.contains("blank-separated")),
        "{:?}",
        got.notes
    );
}

#[test]
fn data_lines_out_of_their_columns_are_read_between_blanks_and_told() {
    // three blanks before and two between the numbers: the columns of 6E13.5 cut them
    let variant = time_history_with(|l| {
        format!("   {}", l.split_whitespace().collect::<Vec<_>>().join("  "))
    });
    let got = read_variant(&variant);
    assert_eq!(real(&got.channels[0].samples), samples_of(TIME_HISTORY));
    let note = got
        .notes
        .iter()
        .find(|n| n.contains("blank-separated"))
        .expect("a note");
    assert!(
        note.contains("3 data line(s)") && note.contains("first: line 14"),
        "{note}"
    );
}

#[test]
fn the_published_samples_follow_the_columns() {
    for name in [TIME_HISTORY, ASCII_SAMPLE, "sample_dataset58_psd.uff"] {
        let got = read(&fixture(name)).unwrap();
        assert!(
            !got.notes.iter().any(|n| n.contains("blank-separated")),
            "{name}: {:?}",
            got.notes
        );
    }
}

/// The 58b sample with a CR LF between its binary block and its closing `-1`, as
/// some writers put it, and the offset of that CR LF.
fn binary_sample_with_line_end_before_closing() -> (Vec<u8>, usize) {
    let mut bytes = fixture_bytes(BINARY_SAMPLE);
    let closing = bytes.len() - "    -1\r\n".len();
    assert_eq!(&bytes[closing..], b"    -1\r\n");
    bytes.splice(closing..closing, *b"\r\n");
    (bytes, closing)
}

#[test]
fn a_line_end_before_the_closing_minus_one_of_58b_is_skipped_and_told() {
    let (bytes, closing) = binary_sample_with_line_end_before_closing();
    let got = read_variant(&bytes);
    assert_eq!(real(&got.channels[0].samples), samples_of(BINARY_SAMPLE));
    let note = format!("a line end between the binary data and the closing -1 (byte {closing})");
    assert!(
        got.notes.iter().any(|n| n.contains(&note)),
        "{:?}",
        got.notes
    );
}

#[test]
fn line_ends_before_the_closings_of_two_58b_datasets_are_each_told() {
    // two such datasets in a row: the second starts right after the first's -1
    let (one, first) = binary_sample_with_line_end_before_closing();
    let second = one.len() + first;
    let got = read_variant(&[one.as_slice(), one.as_slice()].concat());
    let names: Vec<&str> = got.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["Mic 01.0Scalar", "Mic 01.0Scalar #2"]);
    for ch in &got.channels {
        assert_eq!(real(&ch.samples), samples_of(BINARY_SAMPLE));
    }
    let told: Vec<&String> = got
        .notes
        .iter()
        .filter(|n| n.contains("a line end between the binary data"))
        .collect();
    assert_eq!(told.len(), 2, "{:?}", got.notes);
    for (note, at) in told.iter().zip([first, second]) {
        assert!(note.contains(&format!("(byte {at})")), "{at}: {note}");
    }
}

#[test]
fn float64_58b_reads_as_the_float32_it_was_made_from() {
    // the 58b sample re-encoded: ordinate data type 4 (real double) in record 7, each
    // float32 written as the float64 of the same value, twice the bytes in the ID
    // line; ID line 1 NONE, so the name comes from record 6
    let single = fixture_bytes(BINARY_SAMPLE);
    let id = nth_line_end(&single, 1);
    let id1 = nth_line_end(&single, 2);
    let record7 = nth_line_end(&single, 8);
    let data_start = nth_line_end(&single, 13);
    let data_end = data_start + 16000;
    assert_eq!(&single[id + 31..id + 43], b"       16000");
    assert_eq!(&single[id1..id1 + 16], b"Mic 01.0Scalar\r\n");
    assert_eq!(&single[record7..record7 + 20], b"         2      4000");
    let mut double = Vec::with_capacity(single.len() + 16000);
    double.extend_from_slice(&single[..id + 31]);
    double.extend_from_slice(b"       32000");
    double.extend_from_slice(&single[id + 43..id1]);
    double.extend_from_slice(b"NONE");
    double.extend_from_slice(&single[id1 + 14..record7]);
    double.extend_from_slice(b"         4");
    double.extend_from_slice(&single[record7 + 10..data_start]);
    for value in single[data_start..data_end].chunks_exact(4) {
        let v = f32::from_le_bytes(value.try_into().unwrap());
        double.extend_from_slice(&f64::from(v).to_le_bytes());
    }
    double.extend_from_slice(&single[data_end..]);

    let got = read_variant(&double);
    let want = read(&fixture(BINARY_SAMPLE)).unwrap();
    let (ch, was) = (&got.channels[0], &want.channels[0]);
    assert_eq!(ch.name, "resp 0:+X / ref 0:S");
    assert_eq!((&ch.unit, &ch.abscissa), (&was.unit, &was.abscissa));
    assert_eq!(real(&ch.samples), real(&was.samples));
    assert!(
        got.notes[0].contains("real double-precision"),
        "{:?}",
        got.notes
    );
    assert!(
        !got.notes.iter().any(|n| n.contains("ID line declares")),
        "{:?}",
        got.notes
    );
}

#[test]
fn a_58b_byte_count_record_7_contradicts_is_told_and_record_7_read() {
    // pyuff writes points × 8 in the ID line, half the block of complex data
    let got = read(&fixture("pyuff_58b.uff")).unwrap();
    let note = got
        .notes
        .iter()
        .find(|n| n.starts_with("H11 binary: the 58b ID line"))
        .expect("a note");
    assert!(note.contains("declares 512 bytes, record 7 1024"), "{note}");
    assert_eq!(got.channels[0].samples.len(), 64);
    let told = got
        .notes
        .iter()
        .filter(|n| n.contains("the 58b ID line declares"))
        .count();
    assert_eq!(
        told, 3,
        "the complex and the uneven datasets: {:?}",
        got.notes
    );
}

#[test]
fn big_endian_58b_reads_as_little_endian() {
    let little = fixture_bytes(BINARY_SAMPLE);
    let data_start = nth_line_end(&little, 13);
    let data_end = data_start + 16000;
    let mut big = little.clone();
    // field 3 of the ID line (line 2), columns 8-13
    let byte_order = nth_line_end(&little, 1) + 12;
    assert_eq!(big[byte_order], b'1');
    big[byte_order] = b'2';
    for value in big[data_start..data_end].chunks_exact_mut(4) {
        value.reverse();
    }
    let got = read_variant(&big);
    assert_eq!(real(&got.channels[0].samples), samples_of(BINARY_SAMPLE));
}

/// The offset after the `n`-th line end.
fn nth_line_end(bytes: &[u8], n: usize) -> usize {
    bytes
        .iter()
        .enumerate()
        .filter(|(_, &b)| b == b'\n')
        .nth(n - 1)
        .unwrap()
        .0
        + 1
}

#[test]
fn ascii_and_binary_of_one_recording_agree_to_six_digits() {
    // the same microphone record published as 6E13.5 text and as float32: the text has
    // six significant digits, so |text - binary| <= 5e-6 |binary|
    let text = read(&fixture(ASCII_SAMPLE)).unwrap();
    let binary = read(&fixture(BINARY_SAMPLE)).unwrap();
    let (t, b) = (&text.channels[0], &binary.channels[0]);
    assert_eq!(
        (&t.name, &t.unit, &t.abscissa),
        (&b.name, &b.unit, &b.abscissa)
    );
    let (t, b) = (real(&t.samples), real(&b.samples));
    assert_eq!(t.len(), b.len());
    assert_ne!(t, b, "the two encodings differ in the seventh digit");
    for (i, (x, y)) in t.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= 5e-6 * (1.0 + 1e-9) * y.abs(),
            "sample {i}: {x} text, {y} binary"
        );
    }
}

#[test]
fn latin1_and_utf8_labels_as_the_files_spell_them() {
    let psd = read(&fixture("sample_dataset58_psd.uff")).unwrap();
    assert_eq!(psd.channels[0].unit, "g²/Hz");
    // "Beschl. a²" is 10 characters and 11 UTF-8 bytes in record 9's label columns
    let time = read(&fixture("pyuff_time.uff")).unwrap();
    assert_eq!(time.channels[0].unit, "m/s²");
}

#[test]
fn a_latin1_unit_label_of_a_complex_frf_beside_utf8_ones() {
    // pyuff's complex single-precision FRF "H11 single" with record 9's units label
    // (columns 48-67) `m` made `m/s²` in Latin-1, ² as the one byte 0xB2; the time
    // responses before it keep their UTF-8 `m/s²`
    let mut lines = text_lines(SINGLE);
    let at = lines.iter().position(|l| l.trim() == "H11 single").unwrap();
    let record9 = &lines[at + 8];
    assert_eq!(
        &record9[..47],
        "         8    0    0    0 NONE                 "
    );
    assert_eq!(&record9[47..67], format!("{:<20}", "m"));
    lines[at + 8] = format!("{}{:<20}{}", &record9[..47], "m/s@", &record9[67..]);
    let mut bytes = joined(&lines);
    let label = bytes.windows(4).position(|w| w == b"m/s@").unwrap();
    bytes[label + 3] = 0xb2;
    assert!(std::str::from_utf8(&bytes).is_err());

    let got = read_variant(&bytes);
    let was = read(&fixture(SINGLE)).unwrap();
    let units: Vec<&str> = got.channels.iter().map(|c| c.unit.as_str()).collect();
    assert_eq!(units, ["m/s²", "m/s²", "m/s²/N", "m/N"]);
    let (ch, before) = (&got.channels[2], &was.channels[2]);
    assert_eq!(
        (ch.name.as_str(), before.unit.as_str()),
        ("H11 single", "m/N")
    );
    assert!(matches!(ch.samples, Samples::Complex { .. }));
    assert_eq!(
        (&ch.abscissa, &ch.samples),
        (&before.abscissa, &before.samples)
    );
}

#[test]
fn even_and_uneven_abscissae() {
    let even = read(&fixture(TIME_HISTORY)).unwrap();
    assert_eq!(
        even.channels[0].abscissa,
        Abscissa::Uniform {
            start: 0.0,
            step: 5e-5,
            unit: "s".to_string()
        }
    );
    let psd = read(&fixture("sample_dataset58_psd.uff")).unwrap();
    let ch = &psd.channels[0];
    match (&ch.abscissa, &ch.samples) {
        (Abscissa::Values { values, unit }, Samples::Complex { re, im }) => {
            assert_eq!(
                (values.len(), re.len(), im.len(), unit.as_str()),
                (3201, 3201, 3201, "Hz")
            );
            assert!(values.windows(2).all(|w| w[1] - w[0] == 1.0));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn other_datasets_are_skipped_with_their_number_and_line() {
    let got = read(&fixture("pyuff_frf_even.uff")).unwrap();
    let lines = text_lines("pyuff_frf_even.uff");
    for number in ["151", "164"] {
        let line = lines.iter().position(|l| l.trim() == number).unwrap();
        let note = format!("dataset {number} at line {line} skipped");
        assert!(
            got.notes.iter().any(|n| n.starts_with(&note)),
            "{note}: {:?}",
            got.notes
        );
    }
}

#[test]
fn sniff_knows_universal_files_from_others() {
    for entry in std::fs::read_dir(fixture("")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|x| x == "uff") {
            let bytes = std::fs::read(&path).unwrap();
            assert!(sniff(&bytes[..bytes.len().min(256)]), "{}", path.display());
        }
    }
    let others: [&[u8]; 7] = [
        b"",
        b"    -1\n",
        b"time;speed\n0;1\n",
        b"MATLAB 5.0 MAT-file, Platform: GLNXA64",
        b"\x00\x01\x02\x03\xff\xfe\n-1\n",
        b"    -1\n  abc\n",
        b"-1.0 2.0\n3.0 4.0\n",
    ];
    for head in others {
        assert!(!sniff(head), "{:?}", String::from_utf8_lossy(head));
    }
}
