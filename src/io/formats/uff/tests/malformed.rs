//! Broken files made from the fixtures: each gives one error naming the file
//! and the line (or, in a 58b binary block, the byte), without a panic, a hang or an
//! allocation of what a broken count declares.

use super::{assert_fault, fixture_bytes, joined, text_lines};
use crate::io::formats::uff::read;
use crate::io::formats::Location;

const TIME_HISTORY: &str = "time-history-not-all-columns-filled.uff";
const BINARY_SAMPLE: &str = "Sample_UFF58b_bin.first4000.uff";

/// The 1-based line of record 7 (data form) in a dataset starting on line 1.
const RECORD7: usize = 9;

/// The time-history sample (16 lines: -1, 58, records 1-11, 3 data lines, -1) with its
/// 1-based line `n` replaced by `f(line)`.
fn time_history_edited(n: usize, f: impl Fn(&str) -> String) -> Vec<u8> {
    let mut lines = text_lines(TIME_HISTORY);
    lines[n - 1] = f(&lines[n - 1]);
    joined(&lines)
}

fn time_history_lines(range: std::ops::Range<usize>) -> Vec<u8> {
    joined(&text_lines(TIME_HISTORY)[range])
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
fn the_samples_themselves_read() {
    // the broken files below differ from these in one point each
    assert_eq!(text_lines(TIME_HISTORY).len(), 17);
    assert!(read(&super::fixture(TIME_HISTORY)).is_ok());
    assert!(read(&super::fixture(BINARY_SAMPLE)).is_ok());
}

#[test]
fn a_file_cut_in_the_data() {
    let err = assert_fault(
        &time_history_lines(0..15),
        Location::Line(15),
        "the file ends in the data",
    );
    assert!(err.message.contains("12 of the 13 values"), "{err}");
}

#[test]
fn a_file_cut_in_the_header() {
    assert_fault(
        &time_history_lines(0..8),
        Location::Line(8),
        "record 7 (data form) is missing",
    );
}

#[test]
fn a_file_cut_after_the_opening_minus_one() {
    assert_fault(
        &time_history_lines(0..1),
        Location::Line(1),
        "before its number",
    );
}

#[test]
fn a_dataset_without_its_closing_minus_one_at_the_end() {
    assert_fault(
        &time_history_lines(0..16),
        Location::Line(16),
        "without the -1 closing the dataset 58 begun at line 1",
    );
}

#[test]
fn a_dataset_without_its_closing_minus_one_before_the_next() {
    let mut lines = text_lines(TIME_HISTORY);
    lines.pop();
    let first = lines.len();
    lines.extend(text_lines(TIME_HISTORY));
    // the next dataset's opening -1 closes the first; its number is then out of place
    assert_fault(
        &joined(&lines),
        Location::Line(first + 2),
        "did the dataset before lack its closing -1?",
    );
}

#[test]
fn a_dataset_ending_before_its_count() {
    let bytes = time_history_edited(16, |_| "    -1".to_string());
    assert_fault(
        &bytes,
        Location::Line(16),
        "ends (-1) after 12 of the 13 values",
    );
}

#[test]
fn more_values_than_record_7_declares() {
    let bytes = time_history_edited(RECORD7, |l| l.replacen("        13", "        12", 1));
    assert_fault(&bytes, Location::Line(16), "should follow its 12 values");
    let bytes = time_history_edited(RECORD7, |l| l.replacen("        13", "        10", 1));
    assert_fault(
        &bytes,
        Location::Line(15),
        "6 values on a line where 4 complete the 10",
    );
}

#[test]
fn a_count_the_file_cannot_hold_is_refused_before_allocating() {
    for count in ["100000000", "9999999999"] {
        let bytes = time_history_edited(RECORD7, |l| {
            l.replacen("        13", &format!("{count:>10}"), 1)
        });
        assert_fault(
            &bytes,
            Location::Line(RECORD7),
            &format!("declares {count} points"),
        );
    }
}

#[test]
fn a_58b_count_the_file_cannot_hold_is_refused_before_allocating() {
    let mut bytes = fixture_bytes(BINARY_SAMPLE);
    let record7 = nth_line_end(&bytes, 8);
    assert_eq!(&bytes[record7 + 10..record7 + 20], b"      4000");
    bytes.splice(record7 + 10..record7 + 20, *b" 100000000");
    let data = nth_line_end(&bytes, 13);
    assert_fault(
        &bytes,
        Location::Byte(data as u64),
        "400000000 bytes of binary data",
    );
}

#[test]
fn a_58b_file_cut_in_its_binary_block() {
    let bytes = fixture_bytes(BINARY_SAMPLE);
    let data = nth_line_end(&bytes, 13);
    let cut = &bytes[..data + 1000];
    let err = assert_fault(
        cut,
        Location::Byte(data as u64),
        "16000 bytes of binary data, and 1000 bytes follow",
    );
    assert!(err.message.contains("record 7 (line 9)"), "{err}");
}

#[test]
fn a_58b_block_longer_than_record_7_declares() {
    let mut bytes = fixture_bytes(BINARY_SAMPLE);
    let record7 = nth_line_end(&bytes, 8);
    bytes.splice(record7 + 10..record7 + 20, *b"      3999");
    let end = nth_line_end(&bytes, 13) + 3999 * 4;
    assert_fault(
        &bytes,
        Location::Byte(end as u64),
        "should follow the 15996 bytes of binary data",
    );
}

#[test]
fn a_58b_without_its_closing_minus_one() {
    let bytes = fixture_bytes(BINARY_SAMPLE);
    let end = bytes.len() - "    -1\r\n".len();
    assert_fault(
        &bytes[..end],
        Location::Byte(end as u64),
        "without the -1 closing the dataset 58b",
    );
}

#[test]
fn a_58b_in_another_floating_point_format() {
    let mut bytes = fixture_bytes(BINARY_SAMPLE);
    let format = nth_line_end(&bytes, 1) + 18;
    assert_eq!(bytes[format], b'2');
    bytes[format] = b'1';
    assert_fault(
        &bytes,
        Location::Line(2),
        "format 1 (DEC VMS) is not supported",
    );
}

#[test]
fn a_missing_header_record() {
    // without record 10, the first data line is read as record 11
    let mut lines = text_lines(TIME_HISTORY);
    lines.remove(11);
    let err = assert_fault(
        &joined(&lines),
        Location::Line(13),
        "record 11 (z-axis data characteristics)",
    );
    assert!(err.message.contains("is not an integer"), "{err}");
}

#[test]
fn a_record_7_cut_short() {
    let bytes = time_history_edited(RECORD7, |l| l[..20].to_string());
    assert_fault(
        &bytes,
        Location::Line(RECORD7),
        "the abscissa spacing (columns 21-30) is blank",
    );
}

#[test]
fn an_unknown_ordinate_data_type() {
    let bytes = time_history_edited(RECORD7, |l| l.replacen("         2", "         3", 1));
    assert_fault(
        &bytes,
        Location::Line(RECORD7),
        "the ordinate data type 3 is not 2, 4, 5 or 6",
    );
}

#[test]
fn a_letter_in_a_node_field() {
    let bytes = time_history_edited(8, |l| format!("{}x{}", &l[..50], &l[51..]));
    assert_fault(
        &bytes,
        Location::Line(8),
        "record 6 (DOF identification): response node (columns 42-51)",
    );
}

#[test]
fn a_word_that_is_no_number_in_a_data_line() {
    let bytes = time_history_edited(15, |l| l.replacen("-3.69214E+00", "-3.69214E+0x", 1));
    assert_fault(
        &bytes,
        Location::Line(15),
        "'-3.69214E+0x' in a data line is not a number",
    );
}

#[test]
fn binary_garbage() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let garbage: Vec<u8> = (0..4096)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 24) as u8
        })
        .collect();
    assert_fault(
        &garbage,
        Location::Line(1),
        "where a -1 opening a dataset should be",
    );
}

#[test]
fn garbage_after_a_dataset() {
    let mut bytes = fixture_bytes(TIME_HISTORY);
    bytes.extend_from_slice(b"\x7fELF\x02\x01\x01\n");
    assert_fault(
        &bytes,
        Location::Line(18),
        "where a -1 opening a dataset should be",
    );
}

#[test]
fn no_dataset_number() {
    assert_fault(
        b"    -1\n  abc\n",
        Location::Line(2),
        "where the number of the dataset opened at line 1 should be",
    );
}

#[test]
fn an_empty_file() {
    assert_fault(b"", Location::File, "the file is empty");
    assert_fault(b"\n  \n", Location::File, "the file is empty");
}

/// The header (151, lines 1-10) and units (164, lines 11-16) datasets pyuff wrote
/// before the frequency responses of `pyuff_frf_even.uff`, as lines.
fn header_and_units_lines() -> Vec<String> {
    let lines = text_lines("pyuff_frf_even.uff");
    assert_eq!(
        (lines[1].trim(), lines[9].trim(), lines[11].trim()),
        ("151", "-1", "164")
    );
    assert_eq!((lines[15].trim(), lines[17].trim()), ("-1", "58"));
    lines[..16].to_vec()
}

#[test]
fn a_file_without_a_dataset_58() {
    assert_fault(
        &joined(&header_and_units_lines()),
        Location::File,
        "no dataset 58 (function at nodal DOF) among its 2 datasets: 151 (line 1), 164 (line 11)",
    );
}

#[test]
fn an_other_dataset_without_its_closing_minus_one() {
    assert_fault(
        &joined(&header_and_units_lines()[..9]),
        Location::Line(9),
        "without the -1 closing the dataset 151 begun at line 1",
    );
}

#[test]
fn a_binary_dataset_of_another_number_is_skipped_by_its_byte_count() {
    // the 58b sample renumbered 59b: its block holds line ends a line-by-line skip
    // would stumble on
    let mut bytes = fixture_bytes(BINARY_SAMPLE);
    let id = nth_line_end(&bytes, 1);
    assert_eq!(&bytes[id..id + 7], b"    58b");
    bytes[id + 5] = b'9';
    let block = &bytes[nth_line_end(&bytes, 13)..];
    assert!(block.iter().filter(|&&b| b == b'\n').count() > 1);
    bytes.extend_from_slice(&fixture_bytes(TIME_HISTORY));
    let (_dir, _path, result) = super::read_bytes("skip.uff", &bytes);
    let got = result.unwrap();
    assert_eq!(got.channels.len(), 1);
    assert_eq!(got.channels[0].samples.len(), 13);
    assert!(
        got.notes
            .iter()
            .any(|n| n.starts_with("dataset 59 at line 1 skipped")),
        "{:?}",
        got.notes
    );
}

#[test]
fn a_folder_is_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let err = read(dir.path()).unwrap_err();
    assert_eq!(
        (err.path.as_path(), err.location),
        (dir.path(), Location::File)
    );
    assert!(err.to_string().contains("cannot open"), "{err}");
}

/// An uneven abscissa that is NaN, or that overflows (an exponent of 99999), cannot
/// place its point: refused at the dataset's opening line (issue 28; it read as an
/// infinite frequency). The ordinates may hold NaN.
#[test]
fn an_uneven_abscissa_that_is_not_finite() {
    let text = String::from_utf8(fixture_bytes("pyuff_frf_uneven.uff")).unwrap();
    for (field, shown) in [("          NaN", "NaN"), ("   1.0e+99999", "inf")] {
        let broken = text.replacen("  1.00000e+01", field, 1);
        assert_ne!(broken, text);
        let words = format!("abscissa of point 1 of the dataset opened here is {shown}");
        assert_fault(broken.as_bytes(), Location::Line(1), &words);
    }
}
