//! Inputs are never outputs: an output path that resolves to one of the command's
//! input files (a manifest, its data file, a parameter file) is refused before any
//! work starts, naming the option and the file; so is an output in a folder that
//! does not exist.

use std::path::{Path, PathBuf};

use anyhow::bail;

/// Where `path` points: the canonical path of an existing file, or the canonical
/// folder joined with the name of a file yet to be written.
fn resolved(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(dir.canonicalize().ok()?.join(path.file_name()?))
}

/// Refuses an `output` (given with `option`) whose folder does not exist, before a
/// long run finds out at its end.
pub fn require_folder(option: &str, output: &Path) -> anyhow::Result<()> {
    match output.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => bail!(
            "{option} {}: the folder {} does not exist: create it first",
            output.display(),
            dir.display()
        ),
        _ => Ok(()),
    }
}

/// Refuses to write `output` (given with `option`) over any of `inputs`.
pub fn refuse_overwrite(option: &str, output: &Path, inputs: &[&Path]) -> anyhow::Result<()> {
    let Some(out) = resolved(output) else {
        return Ok(());
    };
    for input in inputs {
        if resolved(input).as_ref() == Some(&out) {
            bail!(
                "{option} {}: that is an input of this command ({}): write the output elsewhere",
                output.display(),
                input.display()
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_file_by_another_name_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("fr.json");
        std::fs::write(&input, "{}").unwrap();
        let other = dir.path().join("sub/../fr.json");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let err = refuse_overwrite("--out", &other, &[&input])
            .unwrap_err()
            .to_string();
        assert!(err.contains("--out") && err.contains("input"), "{err}");
        assert!(refuse_overwrite("--out", &dir.path().join("fit.json"), &[&input]).is_ok());
    }

    #[test]
    fn an_output_in_a_missing_folder_is_refused_naming_the_option_and_folder() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("runs/fit.json");
        let err = require_folder("--out", &missing).unwrap_err().to_string();
        assert!(err.starts_with("--out ") && err.contains("runs"), "{err}");
        assert!(require_folder("--out", &dir.path().join("fit.json")).is_ok());
        assert!(require_folder("--out", Path::new("fit.json")).is_ok());
    }
}
