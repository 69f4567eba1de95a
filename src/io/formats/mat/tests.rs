//! The reader against scipy's reading of the fixtures (`expected.json`, written by
//! `fixtures/formats/matlab/make_expected.py`), against the EMPS record's CSV, and
//! against files cut or corrupted from the real one.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::{parse, read, FORMAT};
use crate::io::formats::{Abscissa, Channel, FormatError, Location, Recording, Samples};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/formats/matlab")
}

fn emps_bytes() -> Vec<u8> {
    std::fs::read(fixtures().join("DATA_EMPS.mat")).expect("the EMPS fixture")
}

#[derive(Deserialize)]
struct Expected {
    files: Vec<ExpectedFile>,
}

#[derive(Deserialize)]
struct ExpectedFile {
    file: String,
    channels: Vec<ExpectedChannel>,
    skipped: Vec<String>,
}

#[derive(Deserialize)]
struct ExpectedChannel {
    name: String,
    complex: bool,
    count: usize,
    first: f64,
    last: f64,
    mean: f64,
    first_im: Option<f64>,
    last_im: Option<f64>,
    mean_im: Option<f64>,
}

fn expected() -> Expected {
    let text = std::fs::read_to_string(fixtures().join("expected.json")).expect("expected.json");
    serde_json::from_str(&text).expect("expected.json parses")
}

/// Equal to 1e-12 relative (exactly, where scipy's value is 0).
fn close(got: f64, want: f64) -> bool {
    got == want || (got - want).abs() <= 1e-12 * want.abs()
}

/// The mean with Neumaier's compensated sum (the generator's is `math.fsum`, exact).
fn mean(values: &[f64]) -> f64 {
    let (mut sum, mut carry) = (0.0f64, 0.0f64);
    for &v in values {
        let t = sum + v;
        carry += if sum.abs() >= v.abs() {
            (sum - t) + v
        } else {
            (v - t) + sum
        };
        sum = t;
    }
    (sum + carry) / values.len() as f64
}

/// What differs between a channel and scipy's reading of it.
fn differences(channel: &Channel, want: &ExpectedChannel) -> Vec<String> {
    let mut out = Vec::new();
    let (re, im) = match &channel.samples {
        Samples::Real(re) => (re, None),
        Samples::Complex { re, im } => (re, Some(im)),
    };
    if im.is_some() != want.complex {
        out.push(format!("complex {} , scipy {}", im.is_some(), want.complex));
    }
    if re.len() != want.count {
        out.push(format!("{} samples, scipy {}", re.len(), want.count));
        return out;
    }
    let mut compare = |what: &str, got: f64, wanted: f64| {
        if !close(got, wanted) {
            out.push(format!("{what} {got:e}, scipy {wanted:e}"));
        }
    };
    compare("first", re[0], want.first);
    compare("last", re[re.len() - 1], want.last);
    compare("mean", mean(re), want.mean);
    if let (Some(im), Some(first), Some(last), Some(m)) =
        (im, want.first_im, want.last_im, want.mean_im)
    {
        compare("first im", im[0], first);
        compare("last im", im[im.len() - 1], last);
        compare("mean im", mean(im), m);
    }
    out
}

#[test]
fn every_fixture_matches_scipy() {
    let expected = expected();
    let mut listed: Vec<&str> = expected.files.iter().map(|f| f.file.as_str()).collect();
    let mut present: Vec<String> = std::fs::read_dir(fixtures())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".mat"))
        .collect();
    listed.sort_unstable();
    present.sort_unstable();
    assert_eq!(listed, present, "expected.json must cover every fixture");

    let mut problems = Vec::new();
    for file in &expected.files {
        let recording = read(&fixtures().join(&file.file)).expect(&file.file);
        let names: Vec<&str> = recording.channels.iter().map(|c| c.name.as_str()).collect();
        let wanted: Vec<&str> = file.channels.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, wanted, "{}: channel names", file.file);
        for (channel, want) in recording.channels.iter().zip(&file.channels) {
            for d in differences(channel, want) {
                problems.push(format!("{} `{}`: {d}", file.file, channel.name));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn every_fixture_notes_each_array_it_skips_by_name() {
    for file in &expected().files {
        let recording = read(&fixtures().join(&file.file)).unwrap();
        let skip_notes: Vec<&String> = recording
            .notes
            .iter()
            .filter(|n| n.ends_with("skipped"))
            .collect();
        for name in &file.skipped {
            let prefix = format!("`{name}`: ");
            assert!(
                skip_notes.iter().any(|n| n.starts_with(&prefix)),
                "{}: no note on `{name}` in {:?}",
                file.file,
                recording.notes
            );
        }
        assert_eq!(
            skip_notes.len(),
            file.skipped.len(),
            "{}: {skip_notes:?}",
            file.file
        );
    }
}

#[test]
fn skipped_arrays_say_what_they_are() {
    let recording = read(&fixtures().join("arrays_v5.mat")).unwrap();
    let note = |name: &str| {
        let prefix = format!("`{name}`: ");
        recording
            .notes
            .iter()
            .find(|n| n.starts_with(&prefix))
            .cloned()
            .unwrap_or_default()
    };
    assert!(note("label").contains("char array"), "{}", note("label"));
    assert!(note("c").contains("cell array"), "{}", note("c"));
    assert!(note("S").contains("sparse matrix"), "{}", note("S"));
    assert!(note("empty").contains("empty 0×0"), "{}", note("empty"));
}

#[test]
fn sixty_four_bit_integers_beyond_2_pow_53_are_noted() {
    let recording = read(&fixtures().join("classes.mat")).unwrap();
    for name in ["v_int64", "v_uint64"] {
        let prefix = format!("`{name}`: 64-bit integers");
        assert!(
            recording.notes.iter().any(|n| n.starts_with(&prefix)),
            "{:?}",
            recording.notes
        );
    }
    assert!(!recording.notes.iter().any(|n| n.starts_with("`v_int32`")));
}

fn channels_of(file: &str) -> Vec<Channel> {
    read(&fixtures().join(file)).expect(file).channels
}

#[test]
fn big_endian_files_read_as_their_little_endian_originals() {
    assert_eq!(channels_of("arrays_be.mat"), channels_of("arrays_v5.mat"));
    assert_eq!(
        channels_of("struct_be_compressed.mat"),
        channels_of("struct_compressed.mat")
    );
    let bytes = std::fs::read(fixtures().join("arrays_be.mat")).unwrap();
    assert_eq!(&bytes[126..128], b"MI", "the fixture must be big-endian");
}

#[test]
fn compressed_files_read_as_uncompressed_ones() {
    assert_eq!(
        channels_of("arrays_v7_compressed.mat"),
        channels_of("arrays_v5.mat")
    );
    assert_eq!(
        channels_of("struct_compressed.mat"),
        channels_of("struct_v5.mat")
    );
}

fn channel<'a>(recording: &'a Recording, name: &str) -> &'a [f64] {
    let channel = recording
        .channels
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no channel `{name}`"));
    match &channel.samples {
        Samples::Real(v) => v,
        Samples::Complex { .. } => panic!("`{name}` is complex"),
    }
}

/// `fixtures/real/emps/emps_estimation.csv` was written from DATA_EMPS.mat at full
/// precision (its README): time_s = t, motor_position_m = qm, reference_position_m =
/// qg, controller_output_v = vir, force_n = gtau·vir, all in SI units as the MAT-file
/// holds them. The columns must be the MAT-file's values bit for bit.
#[test]
fn emps_record_equals_the_shipped_csv() {
    let recording = read(&fixtures().join("DATA_EMPS.mat")).unwrap();
    assert_eq!(recording.format, FORMAT);
    assert!(recording.notes.is_empty(), "{:?}", recording.notes);
    for c in &recording.channels {
        assert_eq!(
            (c.unit.as_str(), &c.abscissa, c.first_line),
            ("", &Abscissa::Index, None)
        );
    }
    let csv_path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/real/emps/emps_estimation.csv");
    let text = std::fs::read_to_string(csv_path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "time_s",
            "motor_position_m",
            "reference_position_m",
            "controller_output_v",
            "force_n"
        ]
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let gtau = channel(&recording, "gtau");
    assert_eq!(gtau.len(), 1);
    for (column, name) in ["t", "qm", "qg", "vir"].iter().enumerate() {
        let values = channel(&recording, name);
        assert_eq!(values.len(), rows.len(), "`{name}`");
        for (i, (row, &v)) in rows.iter().zip(values).enumerate() {
            assert_eq!(row[column].to_bits(), v.to_bits(), "`{name}` sample {i}");
        }
    }
    for (row, &vir) in rows.iter().zip(channel(&recording, "vir")) {
        assert_eq!(row[4].to_bits(), (gtau[0] * vir).to_bits());
    }
}

// --- refusals ---------------------------------------------------------------------

/// Writes `bytes` to a file, reads it, and returns the error, after checking that
/// it names the file and a byte offset.
fn refusal(bytes: &[u8]) -> (FormatError, u64) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.mat");
    std::fs::write(&path, bytes).unwrap();
    let error = read(&path).expect_err("must be refused");
    assert_eq!(error.path, path);
    let Location::Byte(at) = error.location else {
        panic!("no byte offset: {error}");
    };
    let text = error.to_string();
    assert!(text.starts_with(&path.display().to_string()), "{text}");
    assert!(text.contains(&format!(", byte {at}: ")), "{text}");
    (error, at)
}

/// The offsets of the top-level elements of a little-endian file whose elements need
/// no padding (compressed ones, as DATA_EMPS.mat's gtau, kp, kv, qg, qm, t, vir, or
/// scipy's miMATRIX, whose lengths are multiples of 8).
fn element_offsets(bytes: &[u8]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut at = 128;
    while at + 8 <= bytes.len() {
        out.push(at);
        at += 8 + u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
    }
    out
}

/// The offset of DATA_EMPS.mat's compressed `qg`, the first long vector.
fn qg_at(bytes: &[u8]) -> usize {
    element_offsets(bytes)[3]
}

fn set_u32(bytes: &mut [u8], at: usize, value: u32) {
    bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
}

/// `bytes` with the compressed element at `at` inflated, edited and recompressed.
fn with_inflated(bytes: &[u8], at: usize, edit: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let len = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
    let mut inflated = Vec::new();
    flate2::read::ZlibDecoder::new(&bytes[at + 8..at + 8 + len])
        .read_to_end(&mut inflated)
        .unwrap();
    edit(&mut inflated);
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    encoder.write_all(&inflated).unwrap();
    let compressed = encoder.finish().unwrap();
    let mut out = bytes[..at].to_vec();
    out.extend_from_slice(&15u32.to_le_bytes());
    out.extend_from_slice(&(compressed.len() as u32).to_le_bytes());
    out.extend_from_slice(&compressed);
    out.extend_from_slice(&bytes[at + 8 + len..]);
    out
}

// Inside DATA_EMPS.mat's inflated `qg` (MATLAB's layout): the miMATRIX tag at 0,
// array flags at 8, dimensions at 24 (24841, 1, values at 32), the name as a small
// element at 40, the real part's tag at 48.
const DIMS_TAG: usize = 24;
const DIMS: usize = 32;
const REAL_TAG: usize = 48;

#[test]
fn the_inflated_layout_the_corruptions_rely_on() {
    let bytes = emps_bytes();
    let qg = qg_at(&bytes);
    let unchanged = with_inflated(&bytes, qg, |inflated| {
        assert_eq!(
            u32::from_le_bytes(inflated[DIMS_TAG..DIMS_TAG + 4].try_into().unwrap()),
            5
        );
        assert_eq!(
            i32::from_le_bytes(inflated[DIMS..DIMS + 4].try_into().unwrap()),
            24841
        );
        assert_eq!(
            u32::from_le_bytes(inflated[REAL_TAG..REAL_TAG + 4].try_into().unwrap()),
            9
        );
    });
    let a = read_bytes_as_recording(&unchanged);
    assert_eq!(channel(&a, "qg").len(), 24841);
}

fn read_bytes_as_recording(bytes: &[u8]) -> Recording {
    parse(Path::new("x.mat"), bytes, crate::io::MAX_INPUT_BYTES).unwrap()
}

#[test]
fn an_empty_file_is_refused() {
    let (error, at) = refusal(&[]);
    assert_eq!(at, 0);
    assert!(error.message.contains("empty file"), "{error}");
}

#[test]
fn a_file_shorter_than_the_header_is_refused() {
    let (error, at) = refusal(&emps_bytes()[..100]);
    assert_eq!(at, 100);
    assert!(error.message.contains("128-byte header"), "{error}");
}

#[test]
fn a_header_alone_is_a_file_without_variables() {
    let recording = read_bytes_as_recording(&emps_bytes()[..128]);
    assert!(recording.channels.is_empty() && recording.notes.is_empty());
}

#[test]
fn a_file_cut_inside_a_variable_is_refused_at_that_variable() {
    let bytes = emps_bytes();
    let offsets = element_offsets(&bytes);
    let cut = offsets[4] + 1000;
    let (error, at) = refusal(&bytes[..cut]);
    assert_eq!(at, offsets[4] as u64);
    assert!(
        error.message.contains("runs past the end of the file"),
        "{error}"
    );
}

#[test]
fn a_file_cut_inside_a_tag_is_refused_at_the_tag() {
    let bytes = emps_bytes();
    let (error, at) = refusal(&bytes[..128 + 5]);
    assert_eq!(at, 128);
    assert!(
        error
            .message
            .contains("too few for an 8-byte data element tag"),
        "{error}"
    );
}

#[test]
fn a_length_past_the_end_of_the_file_is_refused() {
    let mut bytes = emps_bytes();
    let last = *element_offsets(&bytes).last().unwrap();
    set_u32(&mut bytes, last + 4, 0x7FFF_FFFF);
    let (error, at) = refusal(&bytes);
    assert_eq!(at, last as u64);
    assert!(
        error
            .message
            .contains("2147483647 bytes runs past the end of the file"),
        "{error}"
    );
}

#[test]
fn a_length_past_the_end_of_its_parent_is_refused() {
    let bytes = emps_bytes();
    let qg = qg_at(&bytes);
    let bad = with_inflated(&bytes, qg, |inflated| {
        set_u32(inflated, REAL_TAG + 4, 24841 * 8 + 8)
    });
    let (error, at) = refusal(&bad);
    assert_eq!(at, qg as u64);
    let text = error.to_string();
    assert!(
        text.contains(&format!("at byte {REAL_TAG} of its inflated data")),
        "{text}"
    );
    assert!(
        text.contains("runs past the end of the element holding it"),
        "{text}"
    );
}

#[test]
fn dimensions_beyond_what_the_element_holds_are_refused() {
    let bytes = emps_bytes();
    let qg = qg_at(&bytes);
    let bad = with_inflated(&bytes, qg, |inflated| {
        set_u32(inflated, DIMS, 100_000_000);
        set_u32(inflated, DIMS + 4, 100_000_000);
    });
    let (error, at) = refusal(&bad);
    assert_eq!(at, qg as u64);
    let text = error.to_string();
    assert!(
        text.contains(
            "100000000×100000000 declare 10000000000000000 values, its real part holds 24841"
        ),
        "{text}"
    );
}

#[test]
fn dimensions_whose_product_overflows_are_refused() {
    let bytes = emps_bytes();
    let qg = qg_at(&bytes);
    // Three dimensions of 2^31 - 1: the dimensions element grows by 8 bytes (three
    // values and padding), and so does the miMATRIX holding it.
    let bad = with_inflated(&bytes, qg, |inflated| {
        let mut dims = Vec::new();
        dims.extend_from_slice(&5u32.to_le_bytes());
        dims.extend_from_slice(&12u32.to_le_bytes());
        for _ in 0..3 {
            dims.extend_from_slice(&i32::MAX.to_le_bytes());
        }
        dims.extend_from_slice(&[0; 4]);
        inflated.splice(DIMS_TAG..DIMS_TAG + 16, dims);
        let len = u32::from_le_bytes(inflated[4..8].try_into().unwrap());
        set_u32(inflated, 4, len + 8);
    });
    let (error, at) = refusal(&bad);
    assert_eq!(at, qg as u64);
    let text = error.to_string();
    assert!(
        text.contains(&format!("at byte {DIMS_TAG} of its inflated data")),
        "{text}"
    );
    assert!(text.contains("declare more than 2^64 values"), "{text}");
}

#[test]
fn a_negative_dimension_is_refused() {
    let bytes = emps_bytes();
    let qg = qg_at(&bytes);
    let bad = with_inflated(&bytes, qg, |inflated| set_u32(inflated, DIMS + 4, u32::MAX));
    let (error, _) = refusal(&bad);
    assert!(
        error.message.contains("24841×-1 include a negative one"),
        "{error}"
    );
}

/// Deterministic noise (a 64-bit linear congruential generator, Knuth's MMIX
/// constants).
fn garbage(len: usize) -> Vec<u8> {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    (0..len)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 56) as u8
        })
        .collect()
}

#[test]
fn binary_garbage_is_refused_at_the_byte_order_indicator() {
    let (error, at) = refusal(&garbage(4096));
    assert_eq!(at, 126);
    assert!(error.message.contains("not a level 5 MAT-file"), "{error}");
}

#[test]
fn garbage_after_a_valid_header_is_refused() {
    let mut bytes = emps_bytes()[..128].to_vec();
    bytes.extend(garbage(4096));
    let (_, at) = refusal(&bytes);
    assert!(at >= 128);
}

#[test]
fn a_compressed_element_that_does_not_inflate_is_refused() {
    let mut bytes = emps_bytes();
    let qg = qg_at(&bytes);
    for b in &mut bytes[qg + 8 + 1000..qg + 8 + 1016] {
        *b ^= 0xA5;
    }
    let (error, at) = refusal(&bytes);
    assert_eq!(at, qg as u64);
    assert!(error.message.contains("does not inflate"), "{error}");
}

#[test]
fn a_cut_zlib_stream_is_refused() {
    let bytes = emps_bytes();
    let qg = qg_at(&bytes);
    let mut cut = bytes[..qg + 8 + 1000].to_vec();
    set_u32(&mut cut, qg + 4, 1000);
    let (error, at) = refusal(&cut);
    assert_eq!(at, qg as u64);
    assert!(
        error.message.contains("stops after 1000 of its 1000 bytes"),
        "{error}"
    );
}

#[test]
fn inflating_past_the_limit_is_refused() {
    let bytes = emps_bytes();
    // gtau, kp and kv inflate to 64 bytes each; qg to 198 784.
    let limit = 3 * 64 + 100_000;
    let error = parse(Path::new("x.mat"), &bytes, limit).unwrap_err();
    assert_eq!(error.location, Location::Byte(qg_at(&bytes) as u64));
    assert!(
        error
            .message
            .contains(&format!("more than {} bytes", 100_000)),
        "{error}"
    );
    assert!(parse(Path::new("x.mat"), &bytes, 7 * 198_784).is_ok());
}

#[test]
fn stray_bytes_at_the_end_are_refused() {
    let mut bytes = emps_bytes();
    let len = bytes.len();
    bytes.extend_from_slice(&[1, 2, 3]);
    let (error, at) = refusal(&bytes);
    assert_eq!(at, len as u64);
    assert!(
        error
            .message
            .contains("3 bytes left before the end of the file"),
        "{error}"
    );
}

#[test]
fn a_version_7_3_file_is_refused_with_how_to_save_version_7() {
    let mut bytes = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 .".to_vec();
    bytes.resize(116, b' ');
    bytes.extend_from_slice(&[0; 8]);
    bytes.extend_from_slice(&0x0200u16.to_le_bytes());
    bytes.extend_from_slice(b"IM");
    bytes.resize(512, 0);
    bytes.extend_from_slice(b"\x89HDF\r\n\x1a\n");
    bytes.resize(1024, 0);
    let (error, at) = refusal(&bytes);
    assert_eq!(at, 0);
    assert!(error.message.contains("MATLAB 7.3"), "{error}");
    assert!(error.message.contains("save(FILE, '-v7')"), "{error}");
    assert!(error.message.contains("scipy.io.savemat"), "{error}");
}

/// Every cut of an uncompressed and a compressed fixture, and every byte of the
/// uncompressed ones flipped in turn: each gives a recording or one error at a byte,
/// never a panic. A cut gives a recording only where a variable ends.
#[test]
fn no_cut_or_flipped_byte_panics() {
    for file in ["arrays_v5.mat", "struct_v5.mat", "struct_compressed.mat"] {
        let bytes = std::fs::read(fixtures().join(file)).unwrap();
        let boundaries = element_offsets(&bytes);
        for cut in 0..bytes.len() {
            match parse(Path::new(file), &bytes[..cut], crate::io::MAX_INPUT_BYTES) {
                Ok(_) => assert!(boundaries.contains(&cut), "{file} cut at {cut}"),
                Err(e) => assert!(matches!(e.location, Location::Byte(_)), "{e}"),
            }
        }
        if file.ends_with("_v5.mat") {
            for at in 0..bytes.len() {
                let mut flipped = bytes.clone();
                flipped[at] ^= 0xFF;
                if let Err(e) = parse(Path::new(file), &flipped, crate::io::MAX_INPUT_BYTES) {
                    assert!(matches!(e.location, Location::Byte(_)), "{e}");
                }
            }
        }
    }
}

// --- synthetic structs -------------------------------------------------------------

/// A little-endian data element, padded to 8 bytes.
fn element(data_type: u32, data: &[u8]) -> Vec<u8> {
    let mut out = data_type.to_le_bytes().to_vec();
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(out.len().next_multiple_of(8), 0);
    out
}

fn int32s(values: &[i32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// An miMATRIX of class `class`, dimensions `dims`, name `name`, then `rest`.
fn matrix(class: u32, dims: &[i32], name: &str, rest: &[u8]) -> Vec<u8> {
    let mut body = element(6, &int32s(&[class as i32, 0]));
    body.extend(element(5, &int32s(dims)));
    body.extend(element(1, name.as_bytes()));
    body.extend_from_slice(rest);
    element(14, &body)
}

/// A 1×1 struct of one field `a` holding `child`, `depth` times, around a scalar 1.5.
fn nested(depth: usize, name: &str) -> Vec<u8> {
    if depth == 0 {
        return matrix(6, &[1, 1], name, &element(9, &1.5f64.to_le_bytes()));
    }
    let mut rest = element(5, &int32s(&[4]));
    rest.extend(element(1, b"a\0\0\0"));
    rest.extend(nested(depth - 1, ""));
    matrix(2, &[1, 1], name, &rest)
}

fn file_of(variables: &[u8]) -> Vec<u8> {
    let mut bytes = emps_bytes()[..128].to_vec();
    bytes.extend_from_slice(variables);
    bytes
}

#[test]
fn nested_structs_name_their_fields_by_path() {
    let recording = read_bytes_as_recording(&file_of(&nested(3, "s")));
    assert_eq!(recording.channels.len(), 1);
    assert_eq!(recording.channels[0].name, "s.a.a.a");
    assert_eq!(recording.channels[0].samples, Samples::Real(vec![1.5]));
}

#[test]
fn structs_nested_too_deep_are_refused() {
    let bytes = file_of(&nested(super::matrix::MAX_DEPTH + 5, "s"));
    let (error, at) = refusal(&bytes);
    assert!(at > 128);
    assert!(error.message.contains("nested more than"), "{error}");
}

#[test]
fn a_struct_declaring_more_elements_than_the_file_holds_is_refused_at_once() {
    let mut rest = element(5, &int32s(&[4]));
    rest.extend(element(1, b"a\0\0\0"));
    rest.extend(matrix(6, &[1, 1], "", &element(9, &1.5f64.to_le_bytes())));
    let bytes = file_of(&matrix(2, &[100_000_000, 100_000_000], "s", &rest));
    let (error, _) = refusal(&bytes);
    assert!(
        error
            .message
            .contains("10000000000000000 elements of 1 fields"),
        "{error}"
    );
}
