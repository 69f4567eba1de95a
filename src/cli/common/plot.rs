//! Where an evaluation's plots go: only where they were asked for, never over an
//! input, each further plot beside the first with a suffix on its stem.

use std::path::{Path, PathBuf};

use rtid::report::figure::Figure;

/// The plots of one evaluation: none, or the first at `path` and the others beside it.
#[derive(Clone, Debug, Default)]
pub struct Plot {
    path: Option<PathBuf>,
    /// The command's inputs: no plot replaces one.
    inputs: Vec<PathBuf>,
}

impl Plot {
    /// No plot (`rtid evaluate` without `--plot`).
    pub fn none() -> Self {
        Plot::default()
    }

    /// Plots at `path`, refused if it or a plot beside it would replace one of
    /// `inputs` (checked again for each plot written).
    pub fn at(path: PathBuf, inputs: &[&Path]) -> anyhow::Result<Self> {
        super::inputs::refuse_overwrite("--plot", &path, inputs)?;
        Ok(Plot {
            path: Some(path),
            inputs: inputs.iter().map(|p| p.to_path_buf()).collect(),
        })
    }

    /// The path of the plot with `suffix` added to the stem (`""` for the first):
    /// `run.svg` with `-effort` → `run-effort.svg`.
    pub fn path(&self, suffix: &str) -> Option<PathBuf> {
        let path = self.path.as_ref()?;
        let stem = path
            .file_stem()
            .map_or_else(|| "plot".into(), |s| s.to_string_lossy().into_owned());
        let ext = path
            .extension()
            .map_or_else(|| "svg".into(), |e| e.to_string_lossy().into_owned());
        Some(path.with_file_name(format!("{stem}{suffix}.{ext}")))
    }

    /// Writes `figure` at [`Plot::path`] of `suffix`, if plots are asked for, unless
    /// that path is one of the inputs; the path written, if any.
    pub fn write(&self, figure: &Figure, suffix: &str) -> anyhow::Result<Option<PathBuf>> {
        let Some(path) = self.path(suffix) else {
            return Ok(None);
        };
        let inputs: Vec<&Path> = self.inputs.iter().map(PathBuf::as_path).collect();
        super::inputs::refuse_overwrite("the plot", &path, &inputs)?;
        figure.write(&path)?;
        Ok(Some(path))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn further_plots_go_beside_the_first_and_none_is_none() {
        let p = Plot::at(PathBuf::from("out/run.svg"), &[]).unwrap();
        assert_eq!(p.path("-effort"), Some(PathBuf::from("out/run-effort.svg")));
        assert_eq!(p.path(""), Some(PathBuf::from("out/run.svg")));
        assert_eq!(Plot::none().path("-effort"), None);
    }
}

#[test]
fn a_plot_over_an_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("run-effort.svg");
    std::fs::write(&input, "mine").unwrap();
    let p = Plot::at(dir.path().join("run.svg"), &[&input]).unwrap();
    assert!(p.write(&Figure::new("t", "x", "y"), "-effort").is_err());
    assert_eq!(std::fs::read_to_string(&input).unwrap(), "mine");
}
