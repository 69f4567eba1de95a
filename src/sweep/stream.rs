//! The sweep's CSV file: streamed row by row, resumed, sharded and merged.
//!
//! Layout: comment lines (`#`) naming the sweep — `# rtid sweep 1`, `# config {JSON}`
//! (method, seed, factors, outputs, test length and the full base parameter set), and
//! in a shard's file `# shard I/N` — then the header `index,<factors>,<outputs>,error`
//! and one row per design point.
//!
//! While a sweep runs, each finished row is appended and flushed at once, in the
//! order the rows finish. When every row of the file's design (or shard) is there, the
//! file is rewritten atomically ([`crate::io::atomic`]) with the rows sorted by index:
//! the same bytes whatever the order, the interruptions or the shards. A file cut off
//! mid-row (the process killed while writing) loses only that row: resuming drops the
//! incomplete last line.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// First line of every sweep file (format version).
pub const MAGIC: &str = "# rtid sweep 1";

/// A slice of a design: the points whose index ≡ `index` (mod `count`). `index`
/// counts from 0; the text form `I/N` from 1 (I = index + 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// Whether design point `i` belongs to this shard.
    pub fn contains(&self, i: usize) -> bool {
        i % self.count == self.index
    }
}

impl std::str::FromStr for Shard {
    type Err = crate::names::BadForm;
    /// `I/N` with 1 ≤ I ≤ N, counted from 1 like nextest, jest and Playwright
    /// (Slurm: `--array=1-N`, `$SLURM_ARRAY_TASK_ID/N`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || crate::names::BadForm {
            given: s.to_string(),
            expected: "I/N with 1 ≤ I ≤ N, e.g. 3/16",
        };
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (number, count): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if number == 0 || number > count {
            return Err(bad());
        }
        Ok(Shard {
            index: number - 1,
            count,
        })
    }
}

impl std::fmt::Display for Shard {
    /// `I/N`, counted from 1.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index + 1, self.count)
    }
}

/// A problem with a sweep file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StreamError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path} exists: use --resume to continue it, or --overwrite to start again")]
    Exists { path: PathBuf },
    #[error("{path} was written by a different sweep ({what} differs): remove it or choose another --out")]
    DifferentSweep { path: PathBuf, what: &'static str },
    #[error("{path}: not a sweep file (it does not start with `{MAGIC}`)")]
    NotASweep { path: PathBuf },
    #[error("{path}, line {line}: {reason}")]
    BadRow {
        path: PathBuf,
        line: usize,
        reason: String,
    },
    #[error("{path}: {reason}")]
    BadFile { path: PathBuf, reason: String },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> StreamError + '_ {
    move |source| StreamError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The parsed content of a sweep file.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepFile {
    /// The `# config` JSON text.
    pub config: String,
    /// The shard it holds, if it is a shard's file.
    pub shard: Option<Shard>,
    /// The column names.
    pub columns: Vec<String>,
    /// Rows by design index: every field as written (index first).
    pub rows: BTreeMap<usize, Vec<String>>,
}

/// The header text of a file: comment lines and the column line.
pub fn header(config: &str, shard: Option<Shard>, columns: &[String]) -> String {
    let mut h = format!("{MAGIC}\n# config {config}\n");
    if let Some(s) = shard {
        h.push_str(&format!("# shard {s}\n"));
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    // Invariant: one record written to a Vec cannot fail (no I/O, no other record's
    // length to differ from), and CSV of Strings is UTF-8.
    w.write_record(columns).expect("writing to memory");
    h.push_str(&String::from_utf8(w.into_inner().expect("memory")).expect("UTF-8 names"));
    h
}

/// Reads a sweep file. An incomplete last line (no newline) is ignored and reported
/// as `true` in the second value.
pub fn read(path: &Path) -> Result<(SweepFile, bool), StreamError> {
    let bytes = std::fs::read(path).map_err(io(path))?;
    let complete = match bytes.iter().rposition(|&b| b == b'\n') {
        Some(i) => i + 1,
        None => 0,
    };
    let text = std::str::from_utf8(&bytes[..complete]).map_err(|e| StreamError::BadFile {
        path: path.into(),
        reason: format!("not UTF-8 text: {e}"),
    })?;
    let mut lines = text.lines();
    if lines.next() != Some(MAGIC) {
        return Err(StreamError::NotASweep { path: path.into() });
    }
    let bad = |line: usize, reason: String| StreamError::BadRow {
        path: path.into(),
        line,
        reason,
    };
    let config = lines
        .next()
        .and_then(|l| l.strip_prefix("# config "))
        .ok_or_else(|| bad(2, "expected `# config {…}`".into()))?
        .to_string();
    let mut skip = 2;
    let mut shard = None;
    let rest: Vec<&str> = lines.collect();
    if let Some(s) = rest.first().and_then(|l| l.strip_prefix("# shard ")) {
        shard = Some(
            s.parse()
                .map_err(|e: crate::names::BadForm| bad(3, e.to_string()))?,
        );
        skip += 1;
    }
    let body = rest[skip - 2..].join("\n");
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(body.as_bytes());
    let columns: Vec<String> = reader
        .headers()
        .map_err(|e| bad(skip + 1, e.to_string()))?
        .iter()
        .map(String::from)
        .collect();
    if columns.first().map(String::as_str) != Some("index") {
        return Err(bad(skip + 1, "the header must start with `index`".into()));
    }
    let mut rows = BTreeMap::new();
    for (n, record) in reader.records().enumerate() {
        let line = skip + 2 + n;
        let record = record.map_err(|e| bad(line, e.to_string()))?;
        let fields: Vec<String> = record.iter().map(String::from).collect();
        let index: usize = fields[0]
            .parse()
            .map_err(|_| bad(line, format!("index `{}` is not a whole number", fields[0])))?;
        check_numbers(&columns, &fields).map_err(|reason| bad(line, reason))?;
        if let Some(old) = rows.insert(index, fields) {
            if old != rows[&index] {
                return Err(bad(
                    line,
                    format!("index {index} appears twice with different values"),
                ));
            }
        }
    }
    Ok((
        SweepFile {
            config,
            shard,
            columns,
            rows,
        },
        complete < bytes.len(),
    ))
}

/// Checks that every cell of a row but the index and the `error` text is a finite
/// number or empty (an output that could not be computed): a NaN or a stray word in
/// a resumed or merged file would otherwise reach the analysis.
fn check_numbers(columns: &[String], fields: &[String]) -> Result<(), String> {
    let numbers = columns
        .iter()
        .zip(fields)
        .skip(1)
        .filter(|(c, _)| c.as_str() != "error");
    for (column, cell) in numbers {
        let finite = cell.parse::<f64>().is_ok_and(f64::is_finite);
        if !(cell.is_empty() || finite) {
            return Err(format!(
                "column `{column}`: `{cell}` is not a finite number"
            ));
        }
    }
    Ok(())
}

/// An open sweep file receiving rows as they finish.
pub struct Journal {
    path: PathBuf,
    writer: csv::Writer<File>,
}

impl Journal {
    /// Opens `path` for the sweep with header `header`. A new file gets the header.
    /// With `resume`, an existing file must carry the same header; its rows are
    /// returned and an incomplete last line is cut off. Without `resume` an existing
    /// file is an error unless `overwrite`.
    pub fn open(
        path: &Path,
        header: &str,
        resume: bool,
        overwrite: bool,
    ) -> Result<(Journal, BTreeMap<usize, Vec<String>>), StreamError> {
        let mut done = BTreeMap::new();
        let exists = path.exists();
        let file = if exists && resume {
            let (old, partial) = read(path)?;
            let config_line = format!("# config {}", old.config);
            let what = if header.lines().nth(1) != Some(config_line.as_str()) {
                Some("configuration")
            } else if header != self::header(&old.config, old.shard, &old.columns) {
                Some("shard or columns")
            } else {
                None
            };
            if let Some(what) = what {
                return Err(StreamError::DifferentSweep {
                    path: path.into(),
                    what,
                });
            }
            let file = OpenOptions::new()
                .append(true)
                .open(path)
                .map_err(io(path))?;
            if partial {
                let bytes = std::fs::read(path).map_err(io(path))?;
                let keep = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
                file.set_len(keep as u64).map_err(io(path))?;
            }
            done = old.rows;
            file
        } else {
            if exists && !overwrite {
                return Err(StreamError::Exists { path: path.into() });
            }
            let mut file = File::create(path).map_err(io(path))?;
            file.write_all(header.as_bytes()).map_err(io(path))?;
            file.flush().map_err(io(path))?;
            file
        };
        let writer = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(file);
        Ok((
            Journal {
                path: path.into(),
                writer,
            },
            done,
        ))
    }

    /// Appends one row and flushes it to the operating system.
    pub(crate) fn append(&mut self, fields: &[String]) -> Result<(), StreamError> {
        let path = self.path.clone();
        self.writer
            .write_record(fields)
            .map_err(|e| io(&path)(e.into()))?;
        self.writer.flush().map_err(io(&path))
    }
}

/// Writes the final file atomically: `header`, then `rows` in index order.
pub fn finish(
    path: &Path,
    header: &str,
    rows: &BTreeMap<usize, Vec<String>>,
) -> Result<(), StreamError> {
    crate::io::atomic::write_with(path, |w| {
        w.write_all(header.as_bytes())?;
        let mut csv = csv::WriterBuilder::new().has_headers(false).from_writer(w);
        for fields in rows.values() {
            csv.write_record(fields)?;
        }
        csv.flush()?;
        Ok::<(), std::io::Error>(())
    })
    .map_err(io(path))
}

/// Reads the shard files `paths` and checks that they are the n shards of one sweep:
/// same configuration and columns, each shard once. Returns the config, the columns
/// and every row, and the file of each shard (by shard index).
pub fn merge(paths: &[PathBuf]) -> Result<(SweepFile, Vec<PathBuf>), StreamError> {
    let mut merged: Option<SweepFile> = None;
    let mut seen: Vec<Option<PathBuf>> = Vec::new();
    for path in paths {
        let (file, partial) = read(path)?;
        let bad = |reason: String| StreamError::BadFile {
            path: path.clone(),
            reason,
        };
        if partial {
            return Err(bad(
                "the last line is incomplete: the shard did not finish; rerun it with --resume"
                    .into(),
            ));
        }
        let shard = file.shard.unwrap_or(Shard { index: 0, count: 1 });
        if seen.is_empty() {
            seen = vec![None; shard.count];
        }
        if shard.count != seen.len() {
            return Err(bad(format!(
                "shard {shard} does not belong to a sweep of {} shards",
                seen.len()
            )));
        }
        if let Some(other) = &seen[shard.index] {
            return Err(bad(format!("shard {shard} is also in {}", other.display())));
        }
        seen[shard.index] = Some(path.clone());
        if let Some(row) = file.rows.keys().find(|&&i| !shard.contains(i)) {
            return Err(bad(format!("row {row} does not belong to shard {shard}")));
        }
        match &mut merged {
            None => {
                merged = Some(SweepFile {
                    shard: None,
                    ..file
                })
            }
            Some(m) => {
                if m.config != file.config {
                    return Err(StreamError::DifferentSweep {
                        path: path.clone(),
                        what: "configuration",
                    });
                }
                if m.columns != file.columns {
                    return Err(StreamError::DifferentSweep {
                        path: path.clone(),
                        what: "columns",
                    });
                }
                m.rows.extend(file.rows);
            }
        }
    }
    let merged = merged.ok_or_else(|| StreamError::BadFile {
        path: PathBuf::from("sweep merge"),
        reason: "no shard files given".into(),
    })?;
    let missing: Vec<String> = seen
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_none())
        .map(|(index, _)| {
            Shard {
                index,
                count: seen.len(),
            }
            .to_string()
        })
        .collect();
    if !missing.is_empty() {
        let given: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
        return Err(StreamError::BadFile {
            path: PathBuf::from(given.join(", ")),
            reason: format!("missing shard {}", missing.join(", ")),
        });
    }
    Ok((merged, seen.into_iter().flatten().collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_partition() {
        let s: Shard = "3/4".parse().unwrap();
        assert!(s.contains(6) && !s.contains(7));
        assert_eq!(s.to_string(), "3/4");
        assert_eq!("4/4".parse::<Shard>().unwrap().index, 3);
        for bad in ["0/4", "5/4", "1", "a/2", "0/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn a_cut_off_row_is_dropped_on_resume() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        let h = header("{}", None, &["index".into(), "y_hz".into(), "error".into()]);
        let (mut j, done) = Journal::open(&path, &h, false, false).unwrap();
        assert!(done.is_empty());
        j.append(&["1".into(), "2.5".into(), "".into()]).unwrap();
        drop(j);
        let mut f = OpenOptions::new().append(true).open(&path).unwrap();
        f.write_all(b"0,3.").unwrap();
        drop(f);
        let (mut j, done) = Journal::open(&path, &h, true, false).unwrap();
        assert_eq!(done.keys().copied().collect::<Vec<_>>(), vec![1]);
        j.append(&["0".into(), "3.5".into(), "".into()]).unwrap();
        let (file, partial) = read(&path).unwrap();
        assert!(!partial && file.rows.len() == 2 && file.rows[&0][1] == "3.5");
        let err = Journal::open(&path, &h.replace("y_hz", "z_hz"), true, false)
            .err()
            .unwrap();
        assert!(err.to_string().contains("different sweep"), "{err}");
        let err = Journal::open(&path, &h, false, false).err().unwrap();
        assert!(err.to_string().contains("--resume"), "{err}");
    }
}
