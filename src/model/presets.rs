//! The shipped parameter sets, `fixtures/presets/*.json`, compiled into the binary so
//! `--preset NAME` works from any directory.

use super::params::Params;

/// Names and JSON text of the presets.
const PRESETS: &[(&str, &str)] = &[
    (
        "worm-gear",
        include_str!("../../fixtures/presets/worm-gear.json"),
    ),
    (
        "roller-gear-cam",
        include_str!("../../fixtures/presets/roller-gear-cam.json"),
    ),
    (
        "direct-drive",
        include_str!("../../fixtures/presets/direct-drive.json"),
    ),
    (
        "two-mass",
        include_str!("../../fixtures/presets/two-mass.json"),
    ),
];

/// The preset names, for help texts and error messages.
pub fn names() -> impl Iterator<Item = &'static str> {
    PRESETS.iter().map(|(n, _)| *n)
}

/// An unknown preset name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("unknown preset `{name}`: the presets are {known}")]
pub struct UnknownPreset {
    pub name: String,
    pub known: String,
}

/// Loads a preset by name. The shipped JSON is checked by the tests, so a parse
/// failure here is a build defect, reported as such rather than hidden.
pub fn load(name: &str) -> Result<Params, UnknownPreset> {
    let (_, text) = PRESETS
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| UnknownPreset {
            name: name.to_string(),
            known: names().collect::<Vec<_>>().join(", "),
        })?;
    Ok(serde_json::from_str(text)
        .unwrap_or_else(|e| panic!("shipped preset {name} does not parse: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::params::Topology;

    #[test]
    fn every_preset_loads_and_validates() {
        for name in names() {
            let p = load(name).unwrap();
            assert_eq!(p.name, name);
            p.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }

    #[test]
    fn presets_carry_the_values_of_model_md_table_1() {
        let w = load("worm-gear").unwrap();
        assert_eq!(w.topology, Topology::SpurGear);
        assert_eq!(
            (w.jm, w.kw, w.kb, w.kg),
            (13.9e-4, 3.1e5, 5.8e7, Some(850.0))
        );
        assert!((w.ratio() - 0.8 / 72.0).abs() < 1e-15);
        assert!(w.notes.contains_key("Jt"), "uncertain values are marked");
        let r = load("roller-gear-cam").unwrap();
        assert_eq!(r.topology, Topology::Direct);
        assert_eq!(
            (r.jm, r.kw, r.kb, r.ciw, r.ft),
            (4.8e-3, 1.11e6, 9.0e6, 2.0, 0.32)
        );
        assert_eq!((r.kg, r.rg, r.theta_bw), (None, None, 0.0));
    }

    #[test]
    fn unknown_preset_lists_the_known_ones() {
        let err = load("worm").unwrap_err().to_string();
        assert!(
            err.contains("worm-gear") && err.contains("roller-gear-cam"),
            "{err}"
        );
    }
}
