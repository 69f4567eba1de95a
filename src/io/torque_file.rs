//! A recorded motor torque for open-loop simulation: a CSV with columns `time_s` and
//! `motor_torque_nm` (more columns are ignored; `#` starts a comment line).

use std::path::{Path, PathBuf};

/// A torque file that cannot be used; names file, line and column.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TorqueFileError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}, line {line}: {message}")]
    Bad {
        path: PathBuf,
        line: u64,
        message: String,
    },
}

/// Reads the `time_s` and `motor_torque_nm` columns; times must increase strictly.
pub fn read(path: &Path) -> Result<(Vec<f64>, Vec<f64>), TorqueFileError> {
    let bad = |line: u64, message: String| TorqueFileError::Bad {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(
            super::open_input(path).map_err(|source| TorqueFileError::Io {
                path: path.to_path_buf(),
                source,
            })?,
        );
    let headers = reader.headers().map_err(|e| bad(1, e.to_string()))?.clone();
    let column = |name: &str| {
        headers.iter().position(|h| h == name).ok_or_else(|| {
            bad(
                1,
                format!(
                    "missing column `{name}` (header: {})",
                    headers.iter().collect::<Vec<_>>().join(",")
                ),
            )
        })
    };
    let (ti, qi) = (column("time_s")?, column("motor_torque_nm")?);
    let (mut time, mut torque) = (Vec::new(), Vec::new());
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            bad(line, e.to_string())
        })?;
        let line = record.position().map_or(0, |p| p.line());
        let cell = |i: usize, name: &str| -> Result<f64, TorqueFileError> {
            let text = record.get(i).unwrap_or("");
            let v: f64 = text
                .parse()
                .map_err(|_| bad(line, format!("column `{name}`: `{text}` is not a number")))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(bad(line, format!("column `{name}`: {text} is not finite")))
            }
        };
        let t = cell(ti, "time_s")?;
        if let Some(&prev) = time.last() {
            if t <= prev {
                return Err(bad(
                    line,
                    format!("column `time_s`: {t} does not increase (previous {prev})"),
                ));
            }
        }
        time.push(t);
        torque.push(cell(qi, "motor_torque_nm")?);
    }
    if time.is_empty() {
        return Err(bad(1, "no data rows".into()));
    }
    Ok((time, torque))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str) -> Result<(Vec<f64>, Vec<f64>), TorqueFileError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tq.csv");
        std::fs::write(&path, text).unwrap();
        read(&path)
    }

    #[test]
    fn reads_with_comments_and_extra_columns() {
        let (t, q) =
            read_text("# a comment\ntime_s,x,motor_torque_nm\n0,9,1.5\n0.1,9,-2\n").unwrap();
        assert_eq!((t, q), (vec![0.0, 0.1], vec![1.5, -2.0]));
    }

    #[test]
    fn errors_name_line_and_column() {
        for (text, expect) in [
            ("time_s,torque\n0,1\n", "missing column `motor_torque_nm`"),
            (
                "time_s,motor_torque_nm\n0,1\n0.1,abc\n",
                "line 3: column `motor_torque_nm`: `abc`",
            ),
            (
                "time_s,motor_torque_nm\n0,1\n0.1,NaN\n",
                "line 3: column `motor_torque_nm`: NaN is not finite",
            ),
            (
                "time_s,motor_torque_nm\n0,1\n0,2\n",
                "line 3: column `time_s`: 0 does not increase",
            ),
            ("time_s,motor_torque_nm\n", "no data rows"),
        ] {
            let err = read_text(text).unwrap_err().to_string();
            assert!(err.contains(expect), "{text:?}: {err}");
        }
    }
}
