//! The physical parameters of a rotary table and its servo controller (MODEL.md §2–4).
//!
//! One serde type, [`Params`], holds everything in SI units (rad, N·m, s, kg, m). Its
//! JSON field names are the paper's symbols in ASCII (`Jm`, `Kw`, `theta_bw`, …), the
//! same names `--set` and `--fit` take on the command line. [`PARAMS`] lists every name
//! with its unit and meaning; [`Params::validate`] checks each value against the
//! physical constraint of its kind and names the offending field.

use std::collections::BTreeMap;
use std::fmt;

use serde::{Deserialize, Serialize};

/// Which drive train the table has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Topology {
    /// Motor → spur gears (Rg) → driving shaft → worm mesh (Rw) → table: 4 DOF
    /// (θm, θw, xw, θt). The worm-gear table.
    SpurGear,
    /// Motor rigidly coupled to the driving shaft → drive (Rw) → table: 3 DOF
    /// (θm, xw, θt). The roller-gear-cam table. The shaft's inertia `Jw`, viscous
    /// damping `Cw` and friction `fw` (if given) add to the motor's.
    Direct,
}

impl fmt::Display for Topology {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Topology::SpurGear => "spur_gear",
            Topology::Direct => "direct",
        })
    }
}

/// Feedback arrangement of the position loop (MODEL.md §4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum LoopMode {
    /// Position and velocity feedback from the motor encoder.
    #[default]
    SemiClosed,
    /// Position feedback from the table encoder, velocity from the motor encoder.
    FullClosed,
}

impl std::str::FromStr for LoopMode {
    type Err = crate::names::UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.replace('-', "_").as_str() {
            "semi_closed" | "semi" => Ok(LoopMode::SemiClosed),
            "full_closed" | "full" => Ok(LoopMode::FullClosed),
            _ => Err(crate::names::UnknownName {
                what: "loop",
                given: s.to_string(),
                expected: "semi_closed or full_closed".into(),
            }),
        }
    }
}

impl fmt::Display for LoopMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LoopMode::SemiClosed => "semi_closed",
            LoopMode::FullClosed => "full_closed",
        })
    }
}

/// The discrete P/PI servo controller of the paper's Fig. 6 (MODEL.md §4).
///
/// Gains act on motor-side quantities: the position error is expressed in motor
/// radians (a table error is divided by Rg·Rw), the velocity in motor rad/s.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerParams {
    /// Position loop proportional gain, 1/s (velocity command per position error).
    #[serde(rename = "Kpp")]
    pub kpp: f64,
    /// Velocity loop proportional gain, N·m·s/rad.
    #[serde(rename = "Kvp")]
    pub kvp: f64,
    /// Velocity loop integral gain, N·m/rad (integrator Tc·z/(z−1)).
    #[serde(rename = "Kvi")]
    pub kvi: f64,
    /// Control period, s. Must be a whole number of integration steps.
    #[serde(rename = "Tc")]
    pub tc: f64,
    /// Motor torque limit, N·m (the amplifier's peak torque).
    pub torque_limit: f64,
    /// Limit of the velocity command, motor rad/s (the drive's maximum speed).
    pub speed_limit: f64,
    /// Motor encoder resolution, counts per motor revolution (0: no quantisation).
    pub motor_encoder_counts: f64,
    /// Table encoder resolution, rad (0.0001° = 1.745e-6 rad; 0: no quantisation).
    pub table_encoder_resolution: f64,
    /// Semi-closed or full-closed loop.
    #[serde(rename = "loop", default)]
    pub loop_mode: LoopMode,
}

/// Every parameter of the model, SI units. Field docs give the unit; MODEL.md §3 the
/// paper's values. See [`PARAMS`] for the names used in files and on the command line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Short name of this parameter set (a preset name, or free text).
    #[serde(default)]
    pub name: String,
    /// Drive train: `spur_gear` (4 DOF) or `direct` (3 DOF).
    pub topology: Topology,
    /// Motor inertia, kg·m² (direct topology: motor + cam).
    #[serde(rename = "Jm")]
    pub jm: f64,
    /// Spur gears + driving shaft inertia, kg·m² (direct: added to `Jm`, may be 0).
    #[serde(rename = "Jw", default)]
    pub jw: f64,
    /// Table + driven part inertia, kg·m².
    #[serde(rename = "Jt")]
    pub jt: f64,
    /// Mass of the driving unit moving axially, kg.
    #[serde(rename = "Mw")]
    pub mw: f64,
    /// Motor viscous damping, N·m·s/rad.
    #[serde(rename = "Cm")]
    pub cm: f64,
    /// Driving shaft viscous damping, N·m·s/rad.
    #[serde(rename = "Cw", default)]
    pub cw: f64,
    /// Axial viscous damping of the driving unit, N·s/m.
    #[serde(rename = "Cb")]
    pub cb: f64,
    /// Table viscous damping, N·m·s/rad.
    #[serde(rename = "Ct")]
    pub ct: f64,
    /// Internal damping of the spur-gear mesh (motor–shaft), N·m·s/rad; spur gear only.
    #[serde(rename = "Cig", default, skip_serializing_if = "Option::is_none")]
    pub cig: Option<f64>,
    /// Internal damping of the drive mesh (shaft–table), N·m·s/rad.
    #[serde(rename = "Ciw")]
    pub ciw: f64,
    /// Motor Coulomb friction torque, N·m.
    #[serde(rename = "fm")]
    pub fm: f64,
    /// Driving shaft Coulomb friction torque, N·m.
    #[serde(rename = "fw", default)]
    pub fw: f64,
    /// Table Coulomb friction torque, N·m.
    #[serde(rename = "ft")]
    pub ft: f64,
    /// Spur-gear torsional stiffness, N·m/rad in driving-shaft units; spur gear only.
    #[serde(rename = "Kg", default, skip_serializing_if = "Option::is_none")]
    pub kg: Option<f64>,
    /// Drive torsional stiffness, N·m/rad in table units.
    #[serde(rename = "Kw")]
    pub kw: f64,
    /// Axial bearing stiffness of the driving unit, N/m.
    #[serde(rename = "Kb")]
    pub kb: f64,
    /// Spur-gear ratio (shaft turns per motor turn); spur gear only.
    #[serde(rename = "Rg", default, skip_serializing_if = "Option::is_none")]
    pub rg: Option<f64>,
    /// Drive ratio (table turns per shaft turn).
    #[serde(rename = "Rw")]
    pub rw: f64,
    /// Radius of the driven part (wheel pitch radius), m.
    #[serde(rename = "r")]
    pub r: f64,
    /// Spur-gear backlash half-width, rad in shaft units; spur gear only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_bg: Option<f64>,
    /// Drive backlash half-width, rad in table units (total free play 2·theta_bw).
    #[serde(default)]
    pub theta_bw: f64,
    /// Gear-fluctuation amplitude, rad in table units.
    #[serde(rename = "W", default)]
    pub w: f64,
    /// Gear-fluctuation cycles per driving-shaft revolution.
    #[serde(default = "one")]
    pub fluct_order: f64,
    /// Gear-fluctuation phase, rad.
    #[serde(default)]
    pub fluct_phase: f64,
    /// Unbalance mass on a vertical table, kg (0: none).
    #[serde(default)]
    pub unbalance_mass: f64,
    /// Radius of the unbalance mass, m.
    #[serde(default)]
    pub unbalance_radius: f64,
    /// Angular position of the unbalance mass at θt = 0, rad.
    #[serde(default)]
    pub unbalance_phase: f64,
    /// Dead time of the motor encoder signal, s.
    #[serde(default)]
    pub encoder_delay: f64,
    /// Servo controller settings.
    pub controller: ControllerParams,
    /// Where each value comes from, and which ones are uncertain (free text per name).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub notes: BTreeMap<String, String>,
}

fn one() -> f64 {
    1.0
}

/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.80665;

/// The physical constraint a parameter's value must satisfy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Constraint {
    /// > 0 (inertias, stiffnesses, radii, periods).
    Positive,
    /// ≥ 0 (damping, friction, backlash, amplitudes).
    NonNegative,
    /// ≠ 0 (gear ratios).
    NonZero,
    /// Any finite value (phases).
    Finite,
}

/// Which topology a parameter belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Applies {
    /// Both topologies.
    Always,
    /// Only with a spur-gear stage.
    SpurGearOnly,
}

/// One entry of the parameter registry.
pub struct ParamSpec {
    /// Name in files and on the command line.
    pub name: &'static str,
    /// SI unit.
    pub unit: &'static str,
    /// What it is.
    pub meaning: &'static str,
    /// The check [`Params::validate`] applies.
    pub constraint: Constraint,
    /// Topologies it applies to.
    pub applies: Applies,
    get: fn(&Params) -> Option<f64>,
    set: fn(&mut Params, f64),
}

impl ParamSpec {
    /// The value in `p`, `None` when it does not apply to `p`'s topology.
    pub fn get(&self, p: &Params) -> Option<f64> {
        (self.get)(p)
    }
}

macro_rules! spec {
    ($name:literal, $unit:literal, $meaning:literal, $c:ident, $a:ident, $($field:ident).+) => {
        ParamSpec {
            name: $name,
            unit: $unit,
            meaning: $meaning,
            constraint: Constraint::$c,
            applies: Applies::$a,
            get: |p| Some(p.$($field).+),
            set: |p, v| p.$($field).+ = v,
        }
    };
    ($name:literal, $unit:literal, $meaning:literal, $c:ident, opt $field:ident) => {
        ParamSpec {
            name: $name,
            unit: $unit,
            meaning: $meaning,
            constraint: Constraint::$c,
            applies: Applies::SpurGearOnly,
            get: |p| p.$field,
            set: |p, v| p.$field = Some(v),
        }
    };
}

/// Every named parameter, in the order of MODEL.md §3, then the controller's.
pub const PARAMS: &[ParamSpec] = &[
    spec!(
        "Jm",
        "kg·m²",
        "motor inertia (direct: motor + cam)",
        Positive,
        Always,
        jm
    ),
    spec!(
        "Jw",
        "kg·m²",
        "spur gears + driving shaft inertia",
        NonNegative,
        Always,
        jw
    ),
    spec!(
        "Jt",
        "kg·m²",
        "table + driven part inertia",
        Positive,
        Always,
        jt
    ),
    spec!(
        "Mw",
        "kg",
        "driving unit mass (axial)",
        Positive,
        Always,
        mw
    ),
    spec!(
        "Cm",
        "N·m·s/rad",
        "motor viscous damping",
        NonNegative,
        Always,
        cm
    ),
    spec!(
        "Cw",
        "N·m·s/rad",
        "driving shaft viscous damping",
        NonNegative,
        Always,
        cw
    ),
    spec!(
        "Cb",
        "N·s/m",
        "axial viscous damping",
        NonNegative,
        Always,
        cb
    ),
    spec!(
        "Ct",
        "N·m·s/rad",
        "table viscous damping",
        NonNegative,
        Always,
        ct
    ),
    spec!("Cig", "N·m·s/rad", "internal damping of the spur-gear mesh", NonNegative, opt cig),
    spec!(
        "Ciw",
        "N·m·s/rad",
        "internal damping of the drive mesh",
        NonNegative,
        Always,
        ciw
    ),
    spec!(
        "fm",
        "N·m",
        "motor Coulomb friction",
        NonNegative,
        Always,
        fm
    ),
    spec!(
        "fw",
        "N·m",
        "driving shaft Coulomb friction",
        NonNegative,
        Always,
        fw
    ),
    spec!(
        "ft",
        "N·m",
        "table Coulomb friction",
        NonNegative,
        Always,
        ft
    ),
    spec!("Kg", "N·m/rad", "spur-gear torsional stiffness (shaft units)", Positive, opt kg),
    spec!(
        "Kw",
        "N·m/rad",
        "drive torsional stiffness (table units)",
        Positive,
        Always,
        kw
    ),
    spec!("Kb", "N/m", "axial bearing stiffness", Positive, Always, kb),
    spec!("Rg", "-", "spur-gear ratio (shaft turns per motor turn)", NonZero, opt rg),
    spec!(
        "Rw",
        "-",
        "drive ratio (table turns per shaft turn)",
        NonZero,
        Always,
        rw
    ),
    spec!("r", "m", "radius of the driven part", Positive, Always, r),
    spec!("theta_bg", "rad", "spur-gear backlash half-width (shaft units)", NonNegative, opt theta_bg),
    spec!(
        "theta_bw",
        "rad",
        "drive backlash half-width (table units)",
        NonNegative,
        Always,
        theta_bw
    ),
    spec!(
        "W",
        "rad",
        "gear-fluctuation amplitude (table units)",
        NonNegative,
        Always,
        w
    ),
    spec!(
        "fluct_order",
        "-",
        "fluctuation cycles per shaft revolution",
        Positive,
        Always,
        fluct_order
    ),
    spec!(
        "fluct_phase",
        "rad",
        "fluctuation phase",
        Finite,
        Always,
        fluct_phase
    ),
    spec!(
        "unbalance_mass",
        "kg",
        "unbalance mass on a vertical table",
        NonNegative,
        Always,
        unbalance_mass
    ),
    spec!(
        "unbalance_radius",
        "m",
        "radius of the unbalance mass",
        NonNegative,
        Always,
        unbalance_radius
    ),
    spec!(
        "unbalance_phase",
        "rad",
        "angle of the unbalance mass at θt = 0",
        Finite,
        Always,
        unbalance_phase
    ),
    spec!(
        "encoder_delay",
        "s",
        "dead time of the motor encoder",
        NonNegative,
        Always,
        encoder_delay
    ),
    spec!(
        "Kpp",
        "1/s",
        "position loop gain",
        NonNegative,
        Always,
        controller.kpp
    ),
    spec!(
        "Kvp",
        "N·m·s/rad",
        "velocity loop proportional gain",
        NonNegative,
        Always,
        controller.kvp
    ),
    spec!(
        "Kvi",
        "N·m/rad",
        "velocity loop integral gain",
        NonNegative,
        Always,
        controller.kvi
    ),
    spec!("Tc", "s", "control period", Positive, Always, controller.tc),
    spec!(
        "torque_limit",
        "N·m",
        "motor torque limit",
        Positive,
        Always,
        controller.torque_limit
    ),
    spec!(
        "speed_limit",
        "rad/s",
        "velocity command limit (motor)",
        Positive,
        Always,
        controller.speed_limit
    ),
    spec!(
        "motor_encoder_counts",
        "1/rev",
        "motor encoder counts per revolution (0: ideal)",
        NonNegative,
        Always,
        controller.motor_encoder_counts
    ),
    spec!(
        "table_encoder_resolution",
        "rad",
        "table encoder resolution (0: ideal)",
        NonNegative,
        Always,
        controller.table_encoder_resolution
    ),
];

/// Looks a parameter up by name (exact, case-sensitive: `Kw` and `kw` differ in spirit).
pub fn spec(name: &str) -> Result<&'static ParamSpec, ParamError> {
    PARAMS
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| ParamError::Unknown {
            name: name.to_string(),
            suggestion: suggest(name),
        })
}

fn suggest(name: &str) -> String {
    let lower = name.to_ascii_lowercase();
    match PARAMS.iter().find(|s| s.name.to_ascii_lowercase() == lower) {
        Some(s) => format!(" (did you mean `{}`?)", s.name),
        None => String::new(),
    }
}

/// A parameter value that breaks its physical constraint, or an unknown name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    #[error("unknown parameter `{name}`{suggestion}; `rtid params` lists the names")]
    Unknown { name: String, suggestion: String },
    #[error("parameter {name} = {value} is not a finite number")]
    NotFinite { name: &'static str, value: f64 },
    #[error("parameter {name} = {value} {unit} must be positive ({meaning})")]
    NotPositive {
        name: &'static str,
        value: f64,
        unit: &'static str,
        meaning: &'static str,
    },
    #[error("parameter {name} = {value} {unit} must not be negative ({meaning})")]
    Negative {
        name: &'static str,
        value: f64,
        unit: &'static str,
        meaning: &'static str,
    },
    #[error("parameter {name} must not be zero ({meaning})")]
    Zero {
        name: &'static str,
        meaning: &'static str,
    },
    #[error("parameter {name} is required by the spur_gear topology ({meaning})")]
    Missing {
        name: &'static str,
        meaning: &'static str,
    },
    #[error("parameter {name} does not apply to the direct topology (it has no spur-gear stage)")]
    NotApplicable { name: &'static str },
    #[error("parameter {name} = {value}: {reason}")]
    Inconsistent {
        name: &'static str,
        value: f64,
        reason: String,
    },
}

impl Params {
    /// Sets one named parameter (for `--set` and the optimiser). Does not validate.
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let s = spec(name)?;
        if s.applies == Applies::SpurGearOnly && self.topology == Topology::Direct {
            return Err(ParamError::NotApplicable { name: s.name });
        }
        (s.set)(self, value);
        Ok(())
    }

    /// Reads one named parameter; `Ok(None)` if it does not apply to this topology.
    pub fn get(&self, name: &str) -> Result<Option<f64>, ParamError> {
        Ok(spec(name)?.get(self))
    }

    /// Total drive ratio, table turns per motor turn (Rg·Rw; Rw for the direct drive).
    pub fn ratio(&self) -> f64 {
        self.rg.unwrap_or(1.0) * self.rw
    }

    /// Checks every value against its constraint; the first violation is returned.
    pub fn validate(&self) -> Result<(), ParamError> {
        for s in PARAMS {
            let value = match (s.get(self), s.applies, self.topology) {
                (Some(_), Applies::SpurGearOnly, Topology::Direct) => {
                    return Err(ParamError::NotApplicable { name: s.name })
                }
                (None, _, Topology::SpurGear) => {
                    return Err(ParamError::Missing {
                        name: s.name,
                        meaning: s.meaning,
                    })
                }
                (None, _, _) => continue,
                (Some(v), _, _) => v,
            };
            check(s, value)?;
        }
        if self.topology == Topology::SpurGear && self.jw <= 0.0 {
            let s = spec("Jw").expect("Jw is registered");
            return Err(ParamError::NotPositive {
                name: s.name,
                value: self.jw,
                unit: s.unit,
                meaning: s.meaning,
            });
        }
        if self.unbalance_mass > 0.0 && self.unbalance_radius == 0.0 {
            return Err(ParamError::Inconsistent {
                name: "unbalance_radius",
                value: 0.0,
                reason: "an unbalance mass needs a radius > 0".into(),
            });
        }
        Ok(())
    }
}

fn check(s: &ParamSpec, value: f64) -> Result<(), ParamError> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite {
            name: s.name,
            value,
        });
    }
    match s.constraint {
        Constraint::Positive if value <= 0.0 => Err(ParamError::NotPositive {
            name: s.name,
            value,
            unit: s.unit,
            meaning: s.meaning,
        }),
        Constraint::NonNegative if value < 0.0 => Err(ParamError::Negative {
            name: s.name,
            value,
            unit: s.unit,
            meaning: s.meaning,
        }),
        Constraint::NonZero if value == 0.0 => Err(ParamError::Zero {
            name: s.name,
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
