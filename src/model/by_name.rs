//! A parameter set read, written and checked by name, through the registry of
//! parameters ([`super::registry`]): [`Params::set`], [`Params::get`] and
//! [`Params::validate`] with the checks each value and each pair of values must pass.

use super::params::{Axis, ParamError, Params, Topology};
use super::registry::{spec, Constraint, ParamSpec, PARAMS};
use crate::names::Num;

impl Params {
    /// Sets one named parameter (for `--set` and the optimiser). Does not validate
    /// the value; refuses a parameter that does not apply to this topology or axis.
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let s = spec(name)?;
        applicable(s, self)?;
        s.store(self, value);
        Ok(())
    }

    /// Reads one named parameter; `Ok(None)` if it does not apply to this topology
    /// or axis.
    pub fn get(&self, name: &str) -> Result<Option<f64>, ParamError> {
        Ok(spec(name)?.get(self))
    }

    /// Checks every value against its constraint and topology; the first violation is
    /// returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        if self.axis == Axis::Linear
            && !matches!(self.topology, Topology::DirectDrive | Topology::TwoMass)
        {
            return Err(ParamError::LinearTopology {
                topology: self.topology,
            });
        }
        for s in PARAMS {
            match (applicable(s, self), s.raw(self)) {
                (Err(e), Some(v)) if v != s.unused || s.optional => return Err(e),
                (Err(_), _) => continue,
                (Ok(()), None) => {
                    return Err(ParamError::Missing {
                        name: s.name,
                        meaning: s.meaning,
                    })
                }
                (Ok(()), Some(v)) => {
                    check(s, v, self.axis)?;
                    in_range(s, v)?;
                }
            }
        }
        self.check_consistency()?;
        self.check_ranges()
    }

    /// Each held range names a parameter of this drive, a half-width strictly
    /// between 0 and 100 % and a reason.
    fn check_ranges(&self) -> Result<(), ParamError> {
        for (name, range) in &self.ranges {
            let bad = |reason: String| ParamError::BadRange {
                name: name.clone(),
                reason,
            };
            let s = spec(name).map_err(|e| bad(e.to_string()))?;
            if s.name != name {
                return Err(bad(format!("write the parameter's name as {}", s.name)));
            }
            // A value set to 0 (`--set theta_bg=0` on a preset) carries no range: a
            // relative range of 0 is 0.
            s.get(self)
                .ok_or_else(|| bad(format!("{name} does not apply to this drive")))?;
            if !(range.percent > 0.0 && range.percent < 100.0) {
                return Err(bad(format!(
                    "percent {} must lie strictly between 0 and 100",
                    crate::names::Num(range.percent)
                )));
            }
            if range.reason.trim().is_empty() {
                return Err(bad("give the reason the value is uncertain".into()));
            }
        }
        Ok(())
    }

    /// The checks that involve two parameters.
    fn check_consistency(&self) -> Result<(), ParamError> {
        if self.topology == Topology::SpurGear && self.jw <= 0.0 {
            let s = spec("Jw").expect("Jw is registered");
            return Err(ParamError::NotPositive {
                name: s.name,
                value: self.jw,
                unit: s.unit,
                meaning: s.meaning,
            });
        }
        self.check_stribeck()?;
        super::setpoint_filter::check_all(&self.controller.filters, self.controller.tc)?;
        if self.unbalance_mass > 0.0 && self.unbalance_radius == 0.0 {
            return Err(ParamError::Inconsistent {
                name: "unbalance_radius",
                value: 0.0,
                reason: format!(
                    "unbalance_mass = {} kg needs a radius > 0",
                    Num(self.unbalance_mass)
                ),
            });
        }
        let c = &self.controller;
        let periods = c.position_period_s / c.tc;
        if c.position_period_s > 0.0
            && (periods < 1.0 - 1e-9 || (periods - periods.round()).abs() > 1e-6)
        {
            return Err(ParamError::Inconsistent {
                name: "position_period_s",
                value: c.position_period_s,
                reason: format!(
                    "the position controller's cycle is a whole number of control periods Tc = {} s (0: every period)",
                    Num(c.tc)
                ),
            });
        }
        if c.motor_encoder_counts > 0.0 && c.motor_encoder_resolution > 0.0 {
            return Err(ParamError::Inconsistent {
                name: "motor_encoder_resolution",
                value: c.motor_encoder_resolution,
                reason: "give the motor encoder either as motor_encoder_counts or as \
                         motor_encoder_resolution, not both"
                    .into(),
            });
        }
        Ok(())
    }
}

impl Params {
    /// A Stribeck rise needs a Stribeck speed: where it falls off.
    fn check_stribeck(&self) -> Result<(), ParamError> {
        for (rise, rise_name, speed, speed_name) in [
            (self.fsm, "fsm", self.vsm, "vsm"),
            (self.fsw, "fsw", self.vsw, "vsw"),
            (self.fst, "fst", self.vst, "vst"),
        ] {
            if rise > 0.0 && speed <= 0.0 {
                return Err(ParamError::Inconsistent {
                    name: speed_name,
                    value: speed,
                    reason: format!(
                        "{rise_name} = {} (a Stribeck rise) needs a Stribeck speed {speed_name} > 0, the speed at which the rise has fallen to 1/e",
                        Num(rise)
                    ),
                });
            }
        }
        Ok(())
    }
}

/// `Ok` if `s` applies to `p`'s topology and axis, else the error naming it.
fn applicable(s: &ParamSpec, p: &Params) -> Result<(), ParamError> {
    if !s.applies.to(p.topology) {
        Err(ParamError::NotApplicable { name: s.name })
    } else if s.rotary_only && p.axis == Axis::Linear {
        Err(ParamError::NotForAxis {
            name: s.name,
            axis: p.axis,
        })
    } else {
        Ok(())
    }
}

/// The magnitudes a nonzero parameter may have, in its SI unit: wider than any
/// drive's (a 1e-9 kg·m² rotor, a 1e12 N/m bearing), narrow enough that a typo or a
/// unit slip (1e308, 1e-300) is named here rather than met as a hang or a NaN.
pub const MAGNITUDE_RANGE: (f64, f64) = (1e-15, 1e15);

/// Refuses a nonzero value outside [`MAGNITUDE_RANGE`].
fn in_range(s: &ParamSpec, value: f64) -> Result<(), ParamError> {
    let (lo, hi) = MAGNITUDE_RANGE;
    let a = value.abs();
    if a == 0.0 || (lo..=hi).contains(&a) {
        return Ok(());
    }
    Err(ParamError::Inconsistent {
        name: s.name,
        value,
        reason: format!(
            "{} — outside the {lo:e}…{hi:e} {} any drive has: a typo or a unit slip?",
            s.meaning, s.unit
        ),
    })
}

fn check(s: &ParamSpec, value: f64, axis: Axis) -> Result<(), ParamError> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite {
            name: s.name,
            value,
        });
    }
    let unit = s.unit_for(axis);
    match s.constraint {
        Constraint::Positive if value <= 0.0 => Err(ParamError::NotPositive {
            name: s.name,
            value,
            unit,
            meaning: s.meaning,
        }),
        Constraint::NonNegative if value < 0.0 => Err(ParamError::Negative {
            name: s.name,
            value,
            unit,
            meaning: s.meaning,
        }),
        Constraint::NonZero if value == 0.0 => Err(ParamError::Zero {
            name: s.name,
            meaning: s.meaning,
        }),
        Constraint::ZeroOrOne if value != 0.0 && value != 1.0 => Err(ParamError::NotZeroOrOne {
            name: s.name,
            value,
            meaning: s.meaning,
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets;

    #[test]
    fn every_name_is_unique() {
        for (i, a) in PARAMS.iter().enumerate() {
            assert!(
                PARAMS[i + 1..].iter().all(|b| b.name != a.name),
                "{}",
                a.name
            );
        }
    }

    #[test]
    fn set_then_get_round_trips_every_parameter() {
        let mut p = presets::load("worm-gear").unwrap();
        for (i, s) in PARAMS.iter().enumerate() {
            let v = 1.5 + i as f64;
            p.set(s.name, v).unwrap();
            assert_eq!(p.get(s.name).unwrap(), Some(v), "{}", s.name);
        }
    }

    #[test]
    fn validation_names_the_field() {
        let base = presets::load("worm-gear").unwrap();
        let cases: &[(&str, f64, &str)] = &[
            ("Jm", 0.0, "Jm"),
            ("Kw", -1.0, "Kw"),
            ("Kg", 0.0, "Kg"),
            ("Rw", 0.0, "Rw"),
            ("theta_bw", -1e-5, "theta_bw"),
            ("ft", f64::NAN, "ft"),
            ("Jt", f64::INFINITY, "Jt"),
            ("Tc", 0.0, "Tc"),
            ("Jw", 0.0, "Jw"),
        ];
        for &(name, value, expected) in cases {
            let mut p = base.clone();
            p.set(name, value).unwrap();
            let err = p.validate().unwrap_err();
            assert!(err.to_string().contains(expected), "{name}: {err}");
        }
    }

    #[test]
    fn spur_parameters_are_rejected_on_the_direct_drive() {
        let mut p = presets::load("roller-gear-cam").unwrap();
        assert_eq!(
            p.set("Kg", 850.0),
            Err(ParamError::NotApplicable { name: "Kg" })
        );
        p.kg = Some(850.0);
        assert_eq!(p.validate(), Err(ParamError::NotApplicable { name: "Kg" }));
    }

    #[test]
    fn unknown_names_suggest_the_right_case() {
        let err = presets::load("worm-gear")
            .unwrap()
            .set("kw", 1.0)
            .unwrap_err();
        assert!(err.to_string().contains("did you mean `Kw`"), "{err}");
    }
}
