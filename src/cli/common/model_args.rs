//! `--preset`, `--params`, `--set`: the mechanism every command works on.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::Args;

use rtid::identify::result::IdentifyResult;
use rtid::io::params_file;
use rtid::model::params::ControllerParams;
use rtid::model::{presets, Params};

/// Which parameter set to use, and overrides.
#[derive(Debug, Clone, Args)]
pub struct ModelArgs {
    // Shipped parameter set; the help names every preset of the registry
    // (`presets::names`), so that a new preset cannot be left out of it.
    #[arg(long, value_name = "NAME", conflicts_with = "params", help = preset_help())]
    pub preset: Option<String>,
    /// Parameter file (JSON, SI units), e.g. one written by `rtid params --out`.
    #[arg(long, value_name = "FILE.json")]
    pub params: Option<PathBuf>,
    /// Override one parameter, SI units; repeatable: --set Kw=3.5e5 --set theta_bw=5e-5.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
}

/// The help of `--preset`: every shipped parameter set, by name.
fn preset_help() -> String {
    format!(
        "Shipped parameter set: {} (worm-gear and roller-gear-cam: IMECE2008-66108 Table 1)",
        presets::names().collect::<Vec<_>>().join(", ")
    )
}

impl ModelArgs {
    /// Whether a parameter set was named (`--preset` or `--params`).
    pub fn given(&self) -> bool {
        self.preset.is_some() || self.params.is_some()
    }

    /// The validated parameter set.
    pub fn load(&self) -> anyhow::Result<Params> {
        let mut p = match (&self.preset, &self.params) {
            (Some(name), None) => presets::load(name)?,
            (None, Some(path)) => params_file::read(path)?,
            (None, None) => bail!(
                "no mechanism given: use --preset {} or --params FILE.json",
                presets::names().collect::<Vec<_>>().join("|")
            ),
            (Some(_), Some(_)) => bail!("give either --preset or --params, not both"),
        };
        for assignment in &self.set {
            let (name, value) = parse_assignment(assignment)?;
            p.set(name, value)
                .with_context(|| format!("--set {assignment}"))?;
        }
        p.validate().context("after --set")?;
        Ok(p)
    }
}

/// The identified model with its settings: the set `model` names, the values of the
/// identification result `fit` set in it, and the controller settings of the tuned
/// parameter file `tune` (`rtid tune -o`).
pub fn fitted(
    model: &ModelArgs,
    fit: Option<&Path>,
    tune: Option<&Path>,
) -> anyhow::Result<Params> {
    let mut p = model.load()?;
    if let Some(path) = fit {
        apply_fit(&mut p, &read_fit(path)?, path)?;
    }
    if let Some(path) = tune {
        p.controller = tuned_controller(path, &p)?;
    }
    Ok(p)
}

/// Sets the values of the identification result `fit` (read from `path`) in `p`,
/// warning of each value the fit did not determine.
pub fn apply_fit(p: &mut Params, fit: &IdentifyResult, path: &Path) -> anyhow::Result<()> {
    fit.apply_to(p)
        .and_then(|()| p.validate())
        .with_context(|| format!("{}: its values on the model", path.display()))?;
    for warning in not_determined(fit, path) {
        eprintln!("warning: {warning}");
    }
    Ok(())
}

/// The fitted values `fit` (from `path`) says it did not determine: the model takes
/// them where the fit stopped.
fn not_determined(fit: &IdentifyResult, path: &Path) -> Vec<String> {
    use rtid::identify::result::interval::FitInterval;
    (fit.parameters.iter())
        .filter_map(|(name, value)| match fit.interval(name) {
            Some(FitInterval::NotDetermined(why)) => Some(format!(
                "{}: {name} = {value:.5e} is not determined ({why}): the model takes it where the fit stopped, and what follows from it rests on that value",
                path.display()
            )),
            _ => None,
        })
        .collect()
}

/// An identification result (`rtid identify --out`).
pub fn read_fit(path: &Path) -> anyhow::Result<IdentifyResult> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: not an identification result (rtid identify --out)",
            path.display()
        )
    })
}

/// The controller settings of a tuned parameter file (`rtid tune -o`) for model `p`.
pub fn tuned_controller(path: &Path, p: &Params) -> anyhow::Result<ControllerParams> {
    let tuned = params_file::read(path)?;
    p.controller_for(&tuned)
        .with_context(|| format!("--tune {}", path.display()))
}

/// `NAME=VALUE` with a finite number.
pub fn parse_assignment(s: &str) -> anyhow::Result<(&str, f64)> {
    let Some((name, value)) = s.split_once('=') else {
        bail!("--set {s}: expected NAME=VALUE, e.g. Kw=3.5e5");
    };
    match value.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok((name.trim(), v)),
        _ => bail!("--set {s}: `{value}` is not a finite number"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fitted_value_not_determined_is_named_where_the_fit_is_used() {
        let text = include_str!("../../../fixtures/predict/worm-gear/fit.json");
        let mut fit: IdentifyResult = serde_json::from_str(text).unwrap();
        let path = Path::new("fit.json");
        assert!(not_determined(&fit, path).is_empty());
        let plan = rtid::identify::result::record_plan::RecordPlan {
            stages: Vec::new(),
            refined: Vec::new(),
            refinement: None,
            undetermined: vec!["fm".into()],
            shares: Vec::new(),
        };
        fit.plan = Some(plan);
        let warnings = not_determined(&fit, path);
        assert_eq!(warnings.len(), 1);
        assert!(
            warnings[0].starts_with("fit.json: fm = ")
                && warnings[0].contains("not determined (no record determines it)"),
            "{warnings:?}"
        );
    }

    fn args(preset: &str, set: &[&str]) -> ModelArgs {
        ModelArgs {
            preset: Some(preset.into()),
            params: None,
            set: set.iter().map(|s| s.to_string()).collect(),
        }
    }

    /// `--help` of a command that flattens the model arguments names every preset.
    #[test]
    fn the_preset_help_names_every_preset() {
        use clap::CommandFactory;
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            model: ModelArgs,
        }
        for help in [
            Cli::command().render_help().to_string(),
            Cli::command().render_long_help().to_string(),
        ] {
            for name in presets::names() {
                assert!(help.contains(name), "`{name}` missing from:\n{help}");
            }
        }
    }

    #[test]
    fn set_overrides_a_preset_value() {
        let p = args("worm-gear", &["Kw=3.5e5", "theta_bw = 0"])
            .load()
            .unwrap();
        assert_eq!((p.kw, p.theta_bw), (3.5e5, 0.0));
    }

    #[test]
    fn bad_assignments_are_named() {
        for (set, expect) in [
            ("Kw", "expected NAME=VALUE"),
            ("Kw=abc", "`abc` is not a finite number"),
            ("Kx=1", "unknown parameter `Kx`"),
            ("Kw=-1", "Kw = -1"),
            ("Kg=1", "does not apply"),
        ] {
            let preset = if set.starts_with("Kg") {
                "roller-gear-cam"
            } else {
                "worm-gear"
            };
            let err = format!("{:#}", args(preset, &[set]).load().unwrap_err());
            assert!(err.contains(expect), "{set}: {err}");
        }
    }

    #[test]
    fn a_mechanism_is_required() {
        let a = ModelArgs {
            preset: None,
            params: None,
            set: vec![],
        };
        assert!(a.load().unwrap_err().to_string().contains("--preset"));
    }
}
