//! The readers of the formats labs export, on files of about 100 MB built from the
//! fixtures' own layouts (a TwinCAT export's header with its rows repeated, an EPOS
//! run's header over 4.5 M rows, a UFF dataset 58 of 5 M points, a MAT-file of one
//! 12.5 M-sample double vector, a three-column CSV). `cargo bench --bench import`;
//! figures in docs/performance.md.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rtid::io::formats::detect::{self, Format};

/// About how large each file is, bytes.
const SIZE: usize = 100 << 20;

fn fixture(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fixtures/formats")
        .join(relative)
}

/// Text lines appended until the file holds about [`SIZE`] bytes.
fn grow(path: &Path, head: &str, mut row: impl FnMut(usize, &mut String)) {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    out.write_all(head.as_bytes()).unwrap();
    let (mut written, mut line, mut k) = (head.len(), String::new(), 0);
    while written < SIZE {
        line.clear();
        row(k, &mut line);
        out.write_all(line.as_bytes()).unwrap();
        written += line.len();
        k += 1;
    }
}

fn twincat(dir: &Path) -> PathBuf {
    let text =
        std::fs::read_to_string(fixture("twincat-scope/tc3_scope_3_4_3145_3-default.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let start = lines.iter().rposition(|l| l.trim().is_empty()).unwrap() + 1;
    let head = lines[..start].join("\n") + "\n";
    // The rows where every channel has a sample (not the shorter channels' blank
    // tails, nor the `EOF` marker), repeated with every time column (even cells)
    // carried on so that time grows.
    let rows: Vec<&str> = lines[start..]
        .iter()
        .filter(|l| l.split('\t').all(|c| !c.trim().is_empty()) && l.contains('\t'))
        .copied()
        .collect();
    let path = dir.join("scope.csv");
    grow(&path, &head, |k, out| {
        let cells: Vec<&str> = rows[k % rows.len()].split('\t').collect();
        let block = (k / rows.len()) as f64 * rows.len() as f64;
        for (i, c) in cells.iter().enumerate() {
            if i > 0 {
                out.push('\t');
            }
            match (i % 2, c.trim().replace(',', ".").parse::<f64>()) {
                (0, Ok(t)) => write!(out, "{}", t + block).unwrap(),
                _ => out.push_str(c),
            }
        }
        out.push('\n');
    });
    path
}

fn epos(dir: &Path) -> PathBuf {
    let rows = 4_500_000;
    let path = dir.join("epos.csv");
    let mut out = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    write!(
        out,
        "Date:;2020-07-08 21:30:14\nFirmware Version:;0x0120;0x6150;0x0000;0x0000\n\
         EPOS Studio Version:;3.6.1.0\nMax. samples:;{rows}\nRecorded samples:;{rows}\n\
         Sampling period:;128.000\n;Velocity actual value averaged;Torque actual value averaged\n\
         ms;rpm;%\n"
    )
    .unwrap();
    for k in 0..rows {
        write!(
            out,
            "{:.3};{};{:.1}\r\n",
            k as f64 * 128.0,
            50 + k % 3,
            -9.0 + (k % 7) as f64 * 0.1
        )
        .unwrap();
    }
    path
}

fn uff(dir: &Path) -> PathBuf {
    let points = SIZE / 20;
    let template = std::fs::read_to_string(fixture("uff/pyuff_time.uff")).unwrap();
    let mut head: Vec<String> = template.lines().take(13).map(str::to_string).collect();
    // Record 7: the number of points is columns 11–20.
    head[8] = format!("{}{points:10}{}", &head[8][..10], &head[8][20..]);
    let path = dir.join("time.uff");
    let mut out = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    writeln!(out, "{}", head.join("\n")).unwrap();
    for chunk in (0..points).collect::<Vec<_>>().chunks(4) {
        for &k in chunk {
            write!(out, "{:20.11e}", (k as f64 * 1e-3).sin()).unwrap();
        }
        writeln!(out).unwrap();
    }
    writeln!(out, "    -1").unwrap();
    path
}

fn mat(dir: &Path) -> PathBuf {
    let n = SIZE / 8;
    let mut bytes = Vec::with_capacity(SIZE + 256);
    let mut header = b"MATLAB 5.0 MAT-file, written by the rtid import bench".to_vec();
    header.resize(116, b' ');
    bytes.extend_from_slice(&header);
    bytes.extend_from_slice(&[0; 8]);
    bytes.extend_from_slice(&0x0100u16.to_le_bytes());
    bytes.extend_from_slice(b"IM");
    // miMATRIX: flags, dimensions n×1, name "x", miDOUBLE data.
    let data = 8 * n;
    let body = 16 + 16 + 8 + 8 + data;
    bytes.extend_from_slice(&14u32.to_le_bytes());
    bytes.extend_from_slice(&(body as u32).to_le_bytes());
    bytes.extend_from_slice(&[6, 0, 0, 0, 8, 0, 0, 0, 6, 0, 0, 0, 0, 0, 0, 0]);
    bytes.extend_from_slice(&[5, 0, 0, 0, 8, 0, 0, 0]);
    bytes.extend_from_slice(&(n as u32).to_le_bytes());
    bytes.extend_from_slice(&1u32.to_le_bytes());
    bytes.extend_from_slice(&[1, 0, 1, 0, b'x', 0, 0, 0]);
    bytes.extend_from_slice(&9u32.to_le_bytes());
    bytes.extend_from_slice(&(data as u32).to_le_bytes());
    for k in 0..n {
        bytes.extend_from_slice(&(k as f64 * 1e-3).to_le_bytes());
    }
    let path = dir.join("x.mat");
    std::fs::write(&path, bytes).unwrap();
    path
}

fn delimited(dir: &Path) -> PathBuf {
    let path = dir.join("table.csv");
    grow(&path, "time [s],position [mm],force [N]\n", |k, out| {
        let t = k as f64 * 1e-3;
        writeln!(out, "{t},{},{}", t.sin() * 100.0, t.cos() * 30.0).unwrap()
    });
    path
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let files = [
        (
            "twincat-scope",
            Format::parse("twincat-scope").unwrap(),
            twincat(dir.path()),
        ),
        (
            "epos-studio",
            Format::parse("epos-studio").unwrap(),
            epos(dir.path()),
        ),
        ("uff58", Format::parse("uff").unwrap(), uff(dir.path())),
        ("mat", Format::parse("mat").unwrap(), mat(dir.path())),
        (
            "sinumerik-trace",
            Format::parse("sinumerik-trace").unwrap(),
            fixture("sinumerik/freq_trace.XML"),
        ),
        (
            "delimited",
            Format::parse("delimited").unwrap(),
            delimited(dir.path()),
        ),
    ];
    let mut group = c.benchmark_group("import");
    group.sample_size(10);
    for (name, format, path) in &files {
        let bytes = std::fs::metadata(path).unwrap().len();
        group.throughput(Throughput::Bytes(bytes));
        group.bench_function(*name, |b| {
            b.iter(|| {
                let r = detect::read(path, Some(*format)).unwrap();
                assert!(r.channels.iter().all(|c| !c.samples.is_empty()));
                r
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
