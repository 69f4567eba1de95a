//! The servo's settings in the drive's own form: a commented parameter list for a
//! SINAMICS drive ([`sinamics`]: speed controller p1460/p1462, current setpoint
//! filters p1656–p1676) and machine data for a SINUMERIK CNC ([`sinumerik`]: MD32200
//! Kv, MD32620/MD32610/MD32810 speed feed-forward, MD31050/MD31060 the gear).
//!
//! Pure functions from rtid's settings ([`ServoSettings`], in rtid's units,
//! docs/model.md §6) and what rtid does not know (the contexts, given by the user) to
//! text; the command writes the text. docs/drive-settings.md gives each parameter's
//! conversion and the manual, edition and page it was read from, and says which
//! readings could not be checked against a manual.

pub mod sinamics;
pub mod sinumerik;

use std::fmt::Write as _;

use crate::model::{Axis, FilterError, Params, SetpointFilter, MAX_FILTERS};

/// The servo's settings as rtid runs them (docs/model.md §6), the input of both
/// forms. Gains act on motor-side quantities; on a linear axis read m for rad and N
/// for N·m.
#[derive(Clone, Debug, PartialEq)]
pub struct ServoSettings {
    /// Rotary or linear.
    pub axis: Axis,
    /// Position gain Kpp, 1/s: ω* = Kpp·e, e the position error in motor rad, ω* in
    /// motor rad/s.
    pub kpp: f64,
    /// Position integral gain Kpi, 1/s² (0: P position loop).
    pub kpi: f64,
    /// Velocity gain Kvp, controller output·s/rad (N·m·s/rad for a torque command).
    pub kvp: f64,
    /// Velocity integral gain Kvi, controller output/rad (0: P velocity loop).
    pub kvi: f64,
    /// Torque (N·m, or N) per unit of controller output (1 for a torque command).
    pub drive_gain: f64,
    /// Velocity feed-forward Kvff, the fraction of the reference's speed added to ω*.
    pub kvff: f64,
    /// Torque feed-forward Kaff, controller output·s²/rad (the inertia at the motor
    /// over `drive_gain` is all of it).
    pub kaff: f64,
    /// Time constant of the symmetrising lag on the position reference, s (0: none).
    pub symmetrising_s: f64,
    /// Control period Tc, s.
    pub tc: f64,
    /// The current loop's lag rtid modelled, s (0: none); the drive's, not set.
    pub current_lag_s: f64,
    /// The position controller's cycle, s (0: every control period).
    pub position_period_s: f64,
    /// Table turns per motor turn, Rg·Rw ([`Params::ratio`]); 1 on direct and
    /// two-mass drives and on linear axes.
    pub ratio: f64,
    /// The torque setpoint filters, in series.
    pub filters: Vec<SetpointFilter>,
    /// The closed speed loop's equivalent time constant, s, and its −3 dB bandwidth,
    /// Hz, where computed (`rtid tune`: `tuning::closed_loop`; `None` from a parameter
    /// set alone).
    pub equivalent_time_s: Option<f64>,
    pub speed_bandwidth_hz: Option<f64>,
}

impl ServoSettings {
    /// The settings of a parameter set's controller.
    pub fn from_params(p: &Params) -> ServoSettings {
        let c = &p.controller;
        ServoSettings {
            axis: p.axis,
            kpp: c.kpp,
            kpi: c.kpi,
            kvp: c.kvp,
            kvi: c.kvi,
            drive_gain: c.drive_gain,
            kvff: c.kvff,
            kaff: c.kaff,
            symmetrising_s: c.symmetrising_s,
            tc: c.tc,
            current_lag_s: c.current_lag_s,
            position_period_s: c.position_period_s,
            ratio: p.ratio(),
            filters: c.filters.clone(),
            equivalent_time_s: None,
            speed_bandwidth_hz: None,
        }
    }

    /// The velocity gain as torque (force) per motor speed, N·m·s/rad (N·s/m):
    /// Kvp·drive_gain.
    pub fn torque_per_speed(&self) -> f64 {
        self.kvp * self.drive_gain
    }

    /// Refuses a setting that is not a finite number (naming it), a control period,
    /// drive gain or ratio that is not positive, a negative gain, and filters the
    /// controller would refuse at Tc.
    pub fn check(&self) -> Result<(), DriveFormError> {
        let fields = [
            ("Kpp", self.kpp),
            ("Kpi", self.kpi),
            ("Kvp", self.kvp),
            ("Kvi", self.kvi),
            ("drive_gain", self.drive_gain),
            ("Kvff", self.kvff),
            ("Kaff", self.kaff),
            ("symmetrising_s", self.symmetrising_s),
            ("Tc", self.tc),
            ("ratio", self.ratio),
            (
                "equivalent_time_s",
                self.equivalent_time_s.unwrap_or_default(),
            ),
        ];
        for (field, value) in fields {
            finite(field, value)?;
        }
        for (field, value) in [("Tc", self.tc), ("drive_gain", self.drive_gain)] {
            if value <= 0.0 {
                return Err(DriveFormError::OutOfRange {
                    field: field.into(),
                    value,
                    what: "positive",
                });
            }
        }
        if self.ratio == 0.0 {
            return Err(DriveFormError::OutOfRange {
                field: "ratio".into(),
                value: self.ratio,
                what: "non-zero",
            });
        }
        let gains = [
            ("Kpp", self.kpp),
            ("Kpi", self.kpi),
            ("Kvp", self.kvp),
            ("Kvi", self.kvi),
            ("Kvff", self.kvff),
            ("Kaff", self.kaff),
            ("symmetrising_s", self.symmetrising_s),
        ];
        for (field, value) in gains {
            if value < 0.0 {
                return Err(DriveFormError::OutOfRange {
                    field: field.into(),
                    value,
                    what: "≥ 0",
                });
            }
        }
        if self.filters.len() > MAX_FILTERS {
            return Err(DriveFormError::Filter(FilterError::TooMany {
                count: self.filters.len(),
            }));
        }
        for (i, f) in self.filters.iter().enumerate() {
            // A NaN or infinite field is named before the filter's own checks (which
            // read some fields as "positive and finite").
            for (name, value) in filter_fields(f) {
                finite(&format!("filters[{}].{name}", i + 1), value)?;
            }
            f.check(i + 1, self.tc)?;
        }
        Ok(())
    }
}

/// A filter's numeric fields by their names in the parameter file.
fn filter_fields(f: &SetpointFilter) -> Vec<(&'static str, f64)> {
    match *f {
        SetpointFilter::LowPass {
            frequency_hz,
            damping,
        } => vec![("frequency_hz", frequency_hz), ("damping", damping)],
        SetpointFilter::Notch {
            centre_hz,
            width_hz,
            depth_db,
        } => {
            let mut v = vec![("centre_hz", centre_hz), ("width_hz", width_hz)];
            if let Some(d) = depth_db {
                v.push(("depth_db", d));
            }
            v
        }
    }
}

fn finite(field: &str, value: f64) -> Result<(), DriveFormError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(DriveFormError::NotFinite {
            field: field.into(),
            value,
        })
    }
}

/// Why settings cannot be written in a drive's form.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum DriveFormError {
    #[error("{field} = {value}: a drive parameter must be a finite number")]
    NotFinite { field: String, value: f64 },
    #[error("{field} = {value} must be {what}")]
    OutOfRange {
        field: String,
        value: f64,
        what: &'static str,
    },
    /// A quantity rtid's model does not hold; `option` is the command-line option that
    /// gives it.
    #[error("{form} needs {what}, which rtid's model does not hold: give it with {option}")]
    Missing {
        form: &'static str,
        what: &'static str,
        option: &'static str,
    },
    #[error("{option} {given} disagrees with the model's {model}")]
    Disagrees {
        option: &'static str,
        given: String,
        model: String,
    },
    #[error("{field} = {value} has no counterpart in {form}: {why}")]
    NoCounterpart {
        form: &'static str,
        field: &'static str,
        value: f64,
        why: &'static str,
    },
    #[error(transparent)]
    Filter(#[from] FilterError),
}

/// A parameter's value as written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i64),
}

/// One line of a drive's file: the parameter (as the drive names it, index
/// included), its value and unit, and where the value comes from.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    /// `p1460[0]`, `$MA_POSCTRL_GAIN[0,AX4]`.
    pub name: String,
    pub value: Value,
    /// The drive's unit (`Nms/rad`, `ms`, `1000/min`), empty for a plain number.
    pub unit: &'static str,
    /// The rtid value it comes from and the conversion.
    pub comment: String,
}

impl Setting {
    fn real(name: String, value: f64, unit: &'static str, comment: String) -> Setting {
        Setting {
            name,
            value: Value::Real(value),
            unit,
            comment,
        }
    }

    fn integer(name: String, value: i64, unit: &'static str, comment: String) -> Setting {
        Setting {
            name,
            value: Value::Integer(value),
            unit,
            comment,
        }
    }

    /// The value as a number (an integer as f64).
    pub fn number(&self) -> f64 {
        match self.value {
            Value::Real(v) => v,
            Value::Integer(i) => i as f64,
        }
    }
}

/// `header` as `;` comment lines, then one `name=value ; unit: comment` line per
/// setting.
fn render(header: &[String], settings: &[Setting]) -> String {
    let mut s = String::new();
    for h in header {
        // Invariant: writing to a String does not fail.
        let _ = writeln!(s, "; {}", h.replace('\n', " "));
    }
    for st in settings {
        let value = match st.value {
            Value::Real(v) => number(v),
            Value::Integer(i) => i.to_string(),
        };
        let unit = if st.unit.is_empty() {
            String::new()
        } else {
            format!("[{}] ", st.unit)
        };
        let _ = writeln!(s, "{}={value} ; {unit}{}", st.name, st.comment);
    }
    s
}

/// `v` with nine significant digits, without trailing zeros: `1.332`, `0.000125`,
/// `2500`.
pub fn number(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (8 - magnitude).clamp(0, 15) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The worm-gear preset's tuned settings (docs/tuning.md), with a notch, a partial
    /// notch and a low-pass.
    pub fn tuned() -> ServoSettings {
        ServoSettings {
            axis: Axis::Rotary,
            kpp: 187.5,
            kpi: 0.0,
            kvp: 1.332,
            kvi: 249.8,
            drive_gain: 1.0,
            kvff: 1.0,
            kaff: 0.0,
            symmetrising_s: 0.002,
            tc: 250e-6,
            current_lag_s: 0.0,
            position_period_s: 0.0,
            ratio: 1.0 / 90.0,
            equivalent_time_s: None,
            speed_bandwidth_hz: None,
            filters: vec![
                SetpointFilter::Notch {
                    centre_hz: 192.0,
                    width_hz: 38.4,
                    depth_db: Some(-20.0),
                },
                SetpointFilter::Notch {
                    centre_hz: 252.9,
                    width_hz: 50.6,
                    depth_db: None,
                },
                SetpointFilter::LowPass {
                    frequency_hz: 1200.0,
                    damping: 0.7,
                },
            ],
        }
    }

    #[test]
    fn numbers_keep_nine_significant_digits_and_no_trailing_zeros() {
        assert_eq!(number(1.332), "1.332");
        assert_eq!(number(0.000125), "0.000125");
        assert_eq!(number(2500.0), "2500");
        assert_eq!(number(-5.332_266_6), "-5.3322666");
        assert_eq!(number(11.25), "11.25");
        assert_eq!(number(1.0 / 3.0), "0.333333333");
    }

    #[test]
    fn a_setting_that_is_not_finite_is_refused_by_name() {
        for (field, set) in [
            (
                "Kvp",
                (|s: &mut ServoSettings| s.kvp = f64::NAN) as fn(&mut ServoSettings),
            ),
            ("Kpp", |s| s.kpp = f64::INFINITY),
            ("Kvi", |s| s.kvi = f64::NEG_INFINITY),
            ("Kvff", |s| s.kvff = f64::NAN),
            ("Tc", |s| s.tc = f64::NAN),
            ("ratio", |s| s.ratio = f64::INFINITY),
            ("filters[1].width_hz", |s| {
                s.filters[0] = SetpointFilter::Notch {
                    centre_hz: 192.0,
                    width_hz: f64::NAN,
                    depth_db: None,
                }
            }),
            ("filters[3].damping", |s| {
                s.filters[2] = SetpointFilter::LowPass {
                    frequency_hz: 100.0,
                    damping: f64::INFINITY,
                }
            }),
        ] {
            let mut s = tuned();
            set(&mut s);
            match s.check() {
                Err(DriveFormError::NotFinite { field: f, .. }) => assert_eq!(f, field),
                other => panic!("{field}: {other:?}"),
            }
            // Both forms refuse it before writing anything.
            assert!(sinamics::program(&s, &sinamics::SinamicsContext::default()).is_err());
            let ctx = sinumerik::SinumerikContext {
                axis_number: Some(4),
                ..Default::default()
            };
            assert!(sinumerik::program(&s, &ctx).is_err());
        }
    }

    #[test]
    fn the_settings_of_a_parameter_set_are_its_controllers() {
        let p = crate::model::presets::load("worm-gear").unwrap();
        let s = ServoSettings::from_params(&p);
        assert_eq!(s.kpp, p.controller.kpp);
        assert_eq!(s.kvp, p.controller.kvp);
        assert_eq!(s.ratio, p.ratio());
        assert_eq!(s.axis, Axis::Rotary);
        s.check().unwrap();
    }
}
