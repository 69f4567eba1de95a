//! Every objective by name: the list of their [`Definition`]s, in the order their
//! residuals are stacked and their parameters listed. Adding an objective is one
//! file with its `DEFINITION` and one line here.

use super::definition::{Definition, ObjectiveKind, Stage};
use crate::io::experiment_file::Experiment;
use crate::names::UnknownName;

/// The objectives, in the order their residuals are stacked and their parameters
/// listed.
pub static REGISTRY: &[&Definition] = &[
    &super::resonance::DEFINITION,
    &super::peak_amplitude::DEFINITION,
    &super::gain_curve::DEFINITION,
    &super::gain_curve::NEAR_PEAKS,
    &super::torque_curve::DEFINITION,
    &super::unbalance_step::DEFINITION,
    &super::servo_trace::DEFINITION,
    &super::friction_map::DEFINITION,
    &super::speed_loop::DEFINITION,
];

impl ObjectiveKind {
    /// Every objective, in registry order.
    pub fn all() -> impl Iterator<Item = ObjectiveKind> {
        REGISTRY.iter().map(|d| ObjectiveKind(d))
    }

    /// The objective named `name` (`peak_amplitude` or `peak-amplitude`).
    pub fn named(name: &str) -> Result<ObjectiveKind, UnknownName> {
        let wanted = name.trim().replace('-', "_");
        Self::all()
            .find(|k| k.name() == wanted)
            .ok_or_else(|| UnknownName {
                what: "objective",
                given: name.to_string(),
                expected: Self::all().map(|k| k.name()).collect::<Vec<_>>().join(", "),
            })
    }

    /// The objectives `experiment` feeds by default at `stage`, with their relative
    /// weights, in registry order.
    pub fn defaults(experiment: &Experiment, stage: Stage) -> Vec<(ObjectiveKind, f64)> {
        Self::all()
            .filter_map(|k| (k.0.default_weight)(experiment, stage).map(|w| (k, w)))
            .collect()
    }
}

impl<'de> serde::Deserialize<'de> for ObjectiveKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        ObjectiveKind::named(&name).map_err(serde::de::Error::custom)
    }
}

impl std::str::FromStr for ObjectiveKind {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, UnknownName> {
        ObjectiveKind::named(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::experiment_file::Kind;

    #[test]
    fn names_are_unique_and_found_in_both_spellings() {
        for k in ObjectiveKind::all() {
            assert_eq!(
                ObjectiveKind::all()
                    .filter(|o| o.name() == k.name())
                    .count(),
                1
            );
            assert_eq!(
                ObjectiveKind::named(&k.name().replace('_', "-")).unwrap(),
                k
            );
        }
        let err = ObjectiveKind::named("torque").unwrap_err().to_string();
        assert!(err.contains("torque_curve"), "{err}");
    }

    /// An experiment of `kind` with `data`, for the defaults.
    fn experiment(kind: Kind, data: crate::io::experiment_file::Data) -> Experiment {
        Experiment {
            manifest: crate::io::experiment_file::Manifest::new(kind),
            data,
            path: "e.json".into(),
            data_path: None,
        }
    }

    fn gain_curve(phase: bool) -> Experiment {
        experiment(
            Kind::FrequencyResponse,
            crate::io::experiment_file::Data::FrequencyResponse {
                frequency_hz: vec![10.0, 20.0],
                gain_db: vec![0.0, 0.1],
                phase_rad: phase.then(|| vec![0.0, -0.1]),
                extra: Default::default(),
            },
        )
    }

    fn names(e: &Experiment, stage: Stage) -> Vec<(&'static str, f64)> {
        ObjectiveKind::defaults(e, stage)
            .into_iter()
            .map(|(k, w)| (k.name(), w))
            .collect()
    }

    #[test]
    fn a_gain_curve_feeds_resonances_and_heights_by_default() {
        let e = gain_curve(false);
        assert_eq!(
            names(&e, Stage::Search),
            [("resonance", 1.0), ("peak_amplitude", 0.01)]
        );
        assert_eq!(names(&e, Stage::Correction), [("gain_near_peaks", 1.0)]);
        let positioning = experiment(
            Kind::Positioning,
            crate::io::experiment_file::Data::Resonance {
                peaks_hz: vec![],
                peak_gain_db: None,
            },
        );
        assert!(ObjectiveKind::defaults(&positioning, Stage::Search).is_empty());
    }

    #[test]
    fn a_response_with_phase_feeds_its_whole_complex_curve_by_default() {
        let e = gain_curve(true);
        assert_eq!(names(&e, Stage::Search), [("gain_curve", 1.0)]);
        assert_eq!(names(&e, Stage::Correction), [("gain_near_peaks", 1.0)]);
        let p = crate::model::presets::load("worm-gear").unwrap();
        let fit = (ObjectiveKind::named("gain_curve")
            .unwrap()
            .definition()
            .determines)(&e, &p);
        assert_eq!(fit, ["Kw", "Kg", "Ciw", "Cig"]);
        let without = (ObjectiveKind::named("gain_curve")
            .unwrap()
            .definition()
            .determines)(&gain_curve(false), &p);
        assert_eq!(without, ["Kw", "Kg"]);
    }

    /// A drive's closed speed loop feeds its own objective alone: its peaks are no
    /// resonances of the mechanics and its gain no table over motor.
    #[test]
    fn a_speed_loop_feeds_the_speed_loop_objective_alone() {
        let mut e = gain_curve(true);
        e.manifest.conditions.response = Some(crate::io::experiment_file::Response::SpeedLoop);
        assert_eq!(names(&e, Stage::Search), [("speed_loop", 1.0)]);
        assert!(names(&e, Stage::Correction).is_empty());
    }
}
