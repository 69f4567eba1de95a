//! The physical parameters of a CNC axis drive and its servo controller
//! (docs/model.md §1, §2, §6).
//!
//! One type, [`Params`], holds everything in SI units: on a rotary axis rad, N·m,
//! kg·m²; on a linear axis m, N, kg for the same names (docs/model.md §1). Its JSON field
//! names are the paper's symbols in ASCII (`Jm`, `Kw`, `theta_bw`, …), the same names
//! `--set` and `--fit` take on the command line. The registry ([`PARAMS`]) lists every
//! name with its units, meaning and the topologies it applies to; [`Params::validate`]
//! checks each value against the physical constraint of its kind and names the
//! offending field. A parameter that does not apply to the topology (or axis) is
//! absent from files, holds its registry's `unused` value in memory, and is refused
//! by [`Params::set`] and [`Params::validate`] with an error naming it. The JSON form
//! is `params_json.rs`.

use crate::names::Num;
use std::collections::BTreeMap;
use std::fmt;

use serde::{Deserialize, Serialize};

/// Which drive train the axis has (docs/model.md §1).
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
    /// One body, motor rotor and table (or carriage): 1 DOF (θt = θm, ratio 1). A
    /// direct-drive table, or the rigid core of a feed axis.
    DirectDrive,
    /// Motor and table (or load) joined by a torsional coupling (`Kw`, `Ciw`,
    /// `theta_bw`, ratio 1, no axial DOF): 2 DOF (θm, θt).
    TwoMass,
}

impl fmt::Display for Topology {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Topology::SpurGear => "spur_gear",
            Topology::Direct => "direct",
            Topology::DirectDrive => "direct_drive",
            Topology::TwoMass => "two_mass",
        })
    }
}

/// Whether the axis turns or slides (docs/model.md §1). The equations are the same; the
/// units of positions, loads and inertias differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// rad, N·m, kg·m².
    #[default]
    Rotary,
    /// m, N, kg (the `direct_drive` and `two_mass` topologies only).
    Linear,
}

impl Axis {
    /// `rotary` or `linear`.
    pub fn name(self) -> &'static str {
        match self {
            Axis::Rotary => "rotary",
            Axis::Linear => "linear",
        }
    }

    /// The SI unit of a position on this axis: `rad` or `m`.
    pub fn position_unit(self) -> &'static str {
        match self {
            Axis::Rotary => "rad",
            Axis::Linear => "m",
        }
    }

    /// The SI unit of a drive effort on this axis: `N·m` or `N`.
    pub fn effort_unit(self) -> &'static str {
        match self {
            Axis::Rotary => "N·m",
            Axis::Linear => "N",
        }
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Feedback arrangement of the position loop (docs/model.md §6).
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

/// The discrete cascade servo (docs/model.md §1, §6; paper Fig. 6): position P or PI →
/// velocity P or PI, the output saturated in its own unit and turned into torque (or
/// force) by the drive gain.
///
/// Gains act on motor-side quantities: the position error is expressed in motor
/// radians (a table error is divided by Rg·Rw; metres on a linear axis), the velocity
/// in motor rad/s (m/s). The output unit is N·m (N) for a torque command
/// (`drive_gain` = 1, the default), else the drive's input unit (V, A).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerParams {
    /// Position loop proportional gain, 1/s (velocity command per position error).
    #[serde(rename = "Kpp")]
    pub kpp: f64,
    /// Position loop integral gain, 1/s² (integrator Tc·z/(z−1); 0: P position loop).
    #[serde(rename = "Kpi", default, skip_serializing_if = "is_zero")]
    pub kpi: f64,
    /// Velocity loop proportional gain, output unit·s/rad (N·m·s/rad for a torque
    /// command; per m/s on a linear axis).
    #[serde(rename = "Kvp")]
    pub kvp: f64,
    /// Velocity loop integral gain, output unit/rad (integrator Tc·z/(z−1)).
    #[serde(rename = "Kvi")]
    pub kvi: f64,
    /// Control period, s. Must be a whole number of integration steps.
    #[serde(rename = "Tc")]
    pub tc: f64,
    /// Limit of the controller output in its own unit (N·m or N for a torque
    /// command: the amplifier's peak torque; V or A with a `drive_gain`).
    pub torque_limit: f64,
    /// Limit of the velocity command, motor rad/s (m/s on a linear axis).
    pub speed_limit: f64,
    /// Torque (N·m) or force (N) per unit of controller output: the amplifier's gain
    /// (V→N, A→N·m); 1 for a torque command.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub drive_gain: f64,
    /// Control periods between sampling and applying the output: 0, the law
    /// evaluated at the sample (u_k from the samples at k, applied at k); 1, one
    /// sample late (u_k applied at k+1).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub output_delay_periods: f64,
    /// Motor encoder resolution, counts per motor revolution (0: ideal, or given by
    /// `motor_encoder_resolution`); rotary axes only.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub motor_encoder_counts: f64,
    /// Motor (loop) encoder resolution, rad or m per count (0: ideal, or given by
    /// `motor_encoder_counts`). A linear axis gives its encoder this way.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub motor_encoder_resolution: f64,
    /// Table encoder resolution, rad or m (0.0001° = 1.745e-6 rad; 0: no quantisation).
    pub table_encoder_resolution: f64,
    /// Semi-closed or full-closed loop.
    #[serde(rename = "loop", default)]
    pub loop_mode: LoopMode,
    /// Velocity feed-forward: the fraction of the reference's velocity added to the
    /// velocity command (0: off; 1: all of it).
    #[serde(rename = "Kvff", default, skip_serializing_if = "is_zero")]
    pub kvff: f64,
    /// Torque (acceleration) feed-forward: output per rad/s² (m/s²) of the reference's
    /// motor acceleration, added to the torque setpoint (0: off; the inertia at the
    /// motor over the drive gain: all of it).
    #[serde(rename = "Kaff", default, skip_serializing_if = "is_zero")]
    pub kaff: f64,
    /// The symmetrising filter's time constant, s: the position loop's reference
    /// passes a first-order lag of this time constant, so that it meets the motion the
    /// feed-forward makes (0: none).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub symmetrising_s: f64,
    /// Filters on the torque (current) setpoint, in series (none by default).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filters: Vec<SetpointFilter>,
    /// The current (torque) loop's closed-loop lag, s: a first-order lag of this time
    /// constant between the controller's output and the torque, sampled at Tc
    /// (0, the default: the torque follows the output at once).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub current_lag_s: f64,
    /// The position controller's own cycle, s (SINUMERIK's position-control cycle): a
    /// whole number of control periods, the speed command held between (0, the
    /// default: every control period).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub position_period_s: f64,
}

impl ControllerParams {
    /// Control periods per position-controller cycle: `position_period_s`/Tc rounded
    /// (1 for 0).
    pub fn position_every(&self) -> u32 {
        if self.position_period_s > 0.0 {
            ((self.position_period_s / self.tc).round() as u32).max(1)
        } else {
            1
        }
    }

    /// The motor encoder's quantum, rad (m on a linear axis): its resolution, or one
    /// revolution over its counts; 0 for an ideal encoder.
    pub fn motor_quantum(&self) -> f64 {
        if self.motor_encoder_resolution > 0.0 {
            self.motor_encoder_resolution
        } else if self.motor_encoder_counts > 0.0 {
            std::f64::consts::TAU / self.motor_encoder_counts
        } else {
            0.0
        }
    }
}

use super::setpoint_filter::SetpointFilter;

fn one() -> f64 {
    1.0
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// Every parameter of the model, SI units (rad, N·m, kg·m² on a rotary axis; m, N, kg
/// on a linear one). Field docs give the unit; docs/model.md §11 the paper's values. See
/// [`PARAMS`] for the names used in files and on the command line, and which
/// topologies each applies to; a parameter that does not apply holds the registry's
/// `unused` value (0, or 1 for `Rw` and `fluct_order`). Files: `params_json.rs`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    try_from = "super::params_json::ParamsJson",
    into = "super::params_json::ParamsJson"
)]
pub struct Params {
    /// Short name of this parameter set (a preset name, or free text).
    pub name: String,
    /// Drive train: `spur_gear` (4 DOF), `direct` (3 DOF), `direct_drive` (1 DOF) or
    /// `two_mass` (2 DOF).
    pub topology: Topology,
    /// Rotary (default) or linear.
    pub axis: Axis,
    /// Motor inertia, kg·m² (direct topology: motor + cam).
    pub jm: f64,
    /// Spur gears + driving shaft inertia, kg·m² (direct: added to `Jm`, may be 0).
    pub jw: f64,
    /// Table + driven part inertia, kg·m² (direct_drive: with the rotor; linear: the
    /// carriage mass, kg).
    pub jt: f64,
    /// Mass of the driving unit moving axially, kg.
    pub mw: f64,
    /// Motor viscous damping, N·m·s/rad (N·s/m).
    pub cm: f64,
    /// Driving shaft viscous damping, N·m·s/rad.
    pub cw: f64,
    /// Axial viscous damping of the driving unit, N·s/m.
    pub cb: f64,
    /// Table viscous damping, N·m·s/rad (N·s/m).
    pub ct: f64,
    /// Internal damping of the spur-gear mesh (motor–shaft), N·m·s/rad; spur gear only.
    pub cig: Option<f64>,
    /// Internal damping of the drive mesh (shaft–table; two_mass: the coupling),
    /// N·m·s/rad (N·s/m).
    pub ciw: f64,
    /// Motor Coulomb friction torque, N·m (N).
    pub fm: f64,
    /// Driving shaft Coulomb friction torque, N·m.
    pub fw: f64,
    /// Table Coulomb friction torque, N·m (N).
    pub ft: f64,
    /// Stribeck rise of the motor's friction: its static (break-away) level above
    /// `fm`, N·m (N); 0, the default, is the Coulomb law (docs/model.md §2).
    pub fsm: f64,
    /// Stribeck rise of the driving shaft's friction above `fw`, N·m; spur gear only.
    pub fsw: f64,
    /// Stribeck rise of the table's friction above `ft`, N·m (N).
    pub fst: f64,
    /// Stribeck speed of the motor's friction, rad/s (m/s): the rise falls to 1/e at
    /// this speed.
    pub vsm: f64,
    /// Stribeck speed of the driving shaft's friction, rad/s; spur gear only.
    pub vsw: f64,
    /// Stribeck speed of the table's friction, rad/s (m/s).
    pub vst: f64,
    /// Shape exponent δ of the Stribeck curves, exp(−(|ω|/vs)^δ): 2 (Gaussian, the
    /// default) or 1 (exponential), or any positive value.
    pub stribeck_shape: f64,
    /// Spur-gear torsional stiffness, N·m/rad in driving-shaft units; spur gear only.
    pub kg: Option<f64>,
    /// Drive torsional stiffness, N·m/rad in table units (two_mass: the coupling;
    /// N/m on a linear axis).
    pub kw: f64,
    /// Axial bearing stiffness of the driving unit, N/m.
    pub kb: f64,
    /// Spur-gear ratio (shaft turns per motor turn); spur gear only.
    pub rg: Option<f64>,
    /// Drive ratio (table turns per shaft turn); 1 for direct_drive and two_mass.
    pub rw: f64,
    /// Radius of the driven part (wheel pitch radius), m.
    pub r: f64,
    /// Spur-gear backlash half-width, rad in shaft units; spur gear only.
    pub theta_bg: Option<f64>,
    /// Drive backlash half-width, rad in table units (total free play 2·theta_bw; m
    /// on a linear two_mass axis).
    pub theta_bw: f64,
    /// Gear-fluctuation amplitude, rad in table units.
    pub w: f64,
    /// Gear-fluctuation cycles per driving-shaft (two_mass: motor) revolution.
    pub fluct_order: f64,
    /// Gear-fluctuation phase, rad.
    pub fluct_phase: f64,
    /// Unbalance mass on a vertical table, kg (0: none).
    pub unbalance_mass: f64,
    /// Radius of the unbalance mass, m.
    pub unbalance_radius: f64,
    /// Angular position of the unbalance mass at θt = 0, rad.
    pub unbalance_phase: f64,
    /// Dead time of the motor encoder signal, s.
    pub encoder_delay: f64,
    /// Constant external table torque, N·m (force on a linear axis, N), positive in
    /// the positive sense of motion: gravity on an inclined axis, a cable carrier, the
    /// negated offset force OF of the EMPS model (docs/model.md §1).
    pub tload: f64,
    /// Servo controller settings.
    pub controller: ControllerParams,
    /// Where each value comes from, and which ones are uncertain (free text per name).
    pub notes: BTreeMap<String, String>,
    /// The held ranges of values that are uncertain or assumed: name → relative
    /// half-width with its reason. Where such a parameter is held (not fitted), the
    /// identification's intervals and `rtid predict`'s carry the range.
    pub ranges: BTreeMap<String, HeldRange>,
}

/// How far an uncertain or assumed value may be off: value·(1 ± percent/100), and why.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeldRange {
    /// The relative half-width, per cent (0 < percent < 100).
    pub percent: f64,
    /// Why the value is uncertain ("the column is ambiguous", "assumed").
    pub reason: String,
}

/// A parameter the machine may differ in: its value times `low` to `high` — a held
/// range as ratios, or a fit's interval; `rtid tune` varies the machine over them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spread {
    pub name: String,
    pub low: f64,
    pub high: f64,
    /// `held range 25 % (assumed)`, `the fit's interval (bootstrap, 12 replicates)`.
    pub from: String,
}

impl Spread {
    /// A held range of ±`percent` % (0 < percent < 100), and why.
    pub fn held(name: &str, percent: f64, reason: &str) -> Spread {
        Spread {
            name: name.into(),
            low: 1.0 - percent / 100.0,
            high: 1.0 + percent / 100.0,
            from: format!("held range {} % ({reason})", Num(percent)),
        }
    }

    /// A fit's interval `lower … upper` of `value` as ratios (`None` where it does not
    /// bracket a positive value with a positive lower end).
    pub fn fitted(name: &str, value: f64, lower: f64, upper: f64, from: &str) -> Option<Spread> {
        let (low, high) = (lower / value, upper / value);
        let ok = value > 0.0 && low > 0.0 && low <= 1.0 && high >= 1.0 && high.is_finite();
        ok.then(|| Spread {
            name: name.into(),
            low,
            high,
            from: format!("the fit's interval ({from})"),
        })
    }
}

/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.80665;

/// A parameter value that breaks its physical constraint, or an unknown name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ParamError {
    #[error("unknown parameter `{name}`{suggestion}; `rtid params` lists the names")]
    Unknown { name: String, suggestion: String },
    #[error("parameter {name} = {} is not a finite number", Num(*value))]
    NotFinite { name: &'static str, value: f64 },
    #[error("parameter {name} = {} {unit} must be positive ({meaning})", Num(*value))]
    NotPositive {
        name: &'static str,
        value: f64,
        unit: &'static str,
        meaning: &'static str,
    },
    #[error("parameter {name} = {} {unit} must not be negative ({meaning})", Num(*value))]
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
    #[error("parameter {name} = {} must be 0 or 1 ({meaning})", Num(*value))]
    NotZeroOrOne {
        name: &'static str,
        value: f64,
        meaning: &'static str,
    },
    #[error("the parameters make the drive's {coordinate} move at up to {rate:.2e} rad/s (its stiffnesses and dampings over its inertia), beyond {limit:.0e} rad/s — no drive is that fast and no integration step could follow it: check those values for a typo or a unit slip")]
    TooFast {
        coordinate: &'static str,
        rate: f64,
        limit: f64,
    },
    #[error("parameter {name} is required by the spur_gear topology ({meaning})")]
    Missing {
        name: &'static str,
        meaning: &'static str,
    },
    #[error("missing field `{name}`: the {topology} topology requires it ({meaning})")]
    Required {
        name: &'static str,
        topology: Topology,
        meaning: &'static str,
    },
    #[error("parameter {name} does not apply to this drive's topology")]
    NotApplicable { name: &'static str },
    #[error("parameter {name} does not apply to a {axis} axis")]
    NotForAxis { name: &'static str, axis: Axis },
    #[error("a linear axis needs the direct_drive or two_mass topology, not {topology}")]
    LinearTopology { topology: Topology },
    #[error(transparent)]
    Filter(#[from] super::setpoint_filter::FilterError),
    #[error("ranges.{name}: {reason}")]
    BadRange { name: String, reason: String },
    #[error("parameter {name} = {}: {reason}", Num(*value))]
    Inconsistent {
        name: &'static str,
        value: f64,
        reason: String,
    },
}

impl Params {
    /// Total drive ratio, table turns per motor turn (Rg·Rw; Rw for the direct drive;
    /// 1 for direct_drive and two_mass).
    pub fn ratio(&self) -> f64 {
        self.rg.unwrap_or(1.0) * self.rw
    }

    /// The controller settings of `tuned` (a tuned set, `rtid tune -o`) for this
    /// model: a drive of another topology or axis has settings of other units and
    /// meanings, and is refused.
    pub fn controller_for(&self, tuned: &Params) -> Result<ControllerParams, OtherDrive> {
        if tuned.topology != self.topology || tuned.axis != self.axis {
            return Err(OtherDrive {
                tuned: format!("{:?} {:?}", tuned.topology, tuned.axis),
                model: format!("{:?} {:?}", self.topology, self.axis),
            });
        }
        Ok(tuned.controller.clone())
    }
}

/// Controller settings of another drive ([`Params::controller_for`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("a {tuned} drive's settings for a {model} model")]
pub struct OtherDrive {
    /// The tuned set's topology and axis.
    pub tuned: String,
    /// The model's.
    pub model: String,
}

#[cfg(test)]
mod spread_tests {
    use super::*;

    #[test]
    fn a_held_range_and_a_fits_interval_are_ratios_of_the_value() {
        let h = Spread::held("Jt", 25.0, "assumed");
        assert_eq!((h.low, h.high), (0.75, 1.25));
        assert_eq!(h.from, "held range 25 % (assumed)");
        let f = Spread::fitted("Kw", 2.0, 1.5, 3.0, "bootstrap, 12 replicates").unwrap();
        assert_eq!((f.low, f.high), (0.75, 1.5));
        // An interval reaching 0, or missing the value, is no ratio.
        assert!(Spread::fitted("Kw", 1.0, -0.1, 2.0, "x").is_none());
        assert!(Spread::fitted("Kw", 1.0, 1.1, 2.0, "x").is_none());
        assert!(Spread::fitted("Kw", -1.0, -2.0, -0.5, "x").is_none());
    }
}
