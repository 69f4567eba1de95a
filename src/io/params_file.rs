//! Reading and writing parameter files (the JSON of [`Params`]), with errors that name
//! the file, the line and the field.

use std::path::{Path, PathBuf};

use crate::model::params::{ParamError, Params};

/// A parameter file that cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ParamsFileError {
    #[error("cannot read parameter file {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("parameter file {path}, line {line}, column {column}: {message}")]
    Syntax {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("parameter file {path}: {source}")]
    Invalid { path: PathBuf, source: ParamError },
    #[error(
        "parameter file {path}: `{field}` is null: give a number, or leave the field out \
         (for its default, where it has one)"
    )]
    Null { path: PathBuf, field: String },
    #[error("cannot write parameter file {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Reads and validates a parameter file.
pub fn read(path: &Path) -> Result<Params, ParamsFileError> {
    let text = super::read_input(path).map_err(|source| ParamsFileError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse(&text, path)
}

/// Parses and validates parameter JSON; `path` is only used in error messages.
pub fn parse(text: &str, path: &Path) -> Result<Params, ParamsFileError> {
    let syntax = |e: serde_json::Error| ParamsFileError::Syntax {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: e
            .to_string()
            .split(" at line ")
            .next()
            .unwrap_or("")
            .to_string(),
    };
    let value: serde_json::Value =
        serde_json::from_str(super::without_bom(text)).map_err(syntax)?;
    if let Some(field) = null_field(&value, "") {
        return Err(ParamsFileError::Null {
            path: path.to_path_buf(),
            field,
        });
    }
    let params: Params = serde_json::from_str(super::without_bom(text)).map_err(syntax)?;
    params
        .validate()
        .map_err(|source| ParamsFileError::Invalid {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(params)
}

/// The first field whose value is null (a parameter's `Option` would read it as
/// absent: the default taken silently), dotted below the top level.
fn null_field(v: &serde_json::Value, prefix: &str) -> Option<String> {
    let serde_json::Value::Object(map) = v else {
        return None;
    };
    map.iter().find_map(|(k, v)| {
        let name = format!("{prefix}{k}");
        match v {
            serde_json::Value::Null => Some(name),
            _ => null_field(v, &format!("{name}.")),
        }
    })
}

/// Writes a parameter file atomically (temporary file in the same folder, then rename).
pub fn write(path: &Path, params: &Params) -> Result<(), ParamsFileError> {
    let write_error = |source| ParamsFileError::Write {
        path: path.to_path_buf(),
        source,
    };
    let text =
        crate::io::json::pretty(params).map_err(|e| write_error(std::io::Error::other(e)))?;
    crate::io::atomic::write(path, text.as_bytes()).map_err(write_error)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    fn worm_json() -> serde_json::Value {
        serde_json::to_value(presets::load("worm-gear").unwrap()).unwrap()
    }

    fn parse_value(v: &serde_json::Value) -> Result<Params, ParamsFileError> {
        parse(
            &serde_json::to_string_pretty(v).unwrap(),
            Path::new("p.json"),
        )
    }

    #[test]
    fn a_written_file_reads_back_equal() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.json");
        let p = presets::load("roller-gear-cam").unwrap();
        write(&path, &p).unwrap();
        assert_eq!(read(&path).unwrap(), p);
    }

    #[test]
    fn a_null_parameter_is_refused_naming_it_not_read_as_absent() {
        for (path, field) in [
            (&["Cw"][..], "Cw"),
            (&["theta_bw"], "theta_bw"),
            (&["controller", "Kpp"], "controller.Kpp"),
        ] {
            let mut v = worm_json();
            let mut at = &mut v;
            for k in path {
                at = &mut at[*k];
            }
            *at = serde_json::Value::Null;
            let e = parse_value(&v).unwrap_err().to_string();
            assert!(e.contains(&format!("p.json: `{field}` is null")), "{e}");
        }
    }

    #[test]
    fn invalid_values_give_the_typed_error_naming_the_field() {
        let mut v = worm_json();
        v["Kw"] = serde_json::json!(-3.1e5);
        match parse_value(&v) {
            Err(ParamsFileError::Invalid {
                source: ParamError::NotPositive { name: "Kw", .. },
                ..
            }) => {}
            other => panic!("{other:?}"),
        }
        let mut v = worm_json();
        v["Rw"] = serde_json::json!(0.0);
        assert!(matches!(
            parse_value(&v),
            Err(ParamsFileError::Invalid {
                source: ParamError::Zero { name: "Rw", .. },
                ..
            })
        ));
        let mut v = worm_json();
        v["theta_bg"] = serde_json::json!(-1e-4);
        assert!(matches!(
            parse_value(&v),
            Err(ParamsFileError::Invalid {
                source: ParamError::Negative {
                    name: "theta_bg",
                    ..
                },
                ..
            })
        ));
        let mut v = worm_json();
        v.as_object_mut().unwrap().remove("Kg");
        assert!(matches!(
            parse_value(&v),
            Err(ParamsFileError::Invalid {
                source: ParamError::Missing { name: "Kg", .. },
                ..
            })
        ));
    }

    #[test]
    fn syntax_errors_and_unknown_fields_name_the_line() {
        let err = parse(
            "{\n  \"topology\": \"spur_gear\",\n  \"Jm\": ,\n}",
            Path::new("bad.json"),
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("bad.json, line 3"), "{err}");
        let mut v = worm_json();
        v["Kww"] = serde_json::json!(1.0);
        let err = parse_value(&v).unwrap_err().to_string();
        assert!(
            err.contains("unknown field `Kww`") && err.contains("line"),
            "{err}"
        );
    }

    #[test]
    fn a_missing_file_names_the_path() {
        let err = read(Path::new("/nonexistent/params.json"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/params.json"), "{err}");
    }
}
