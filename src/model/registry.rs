//! The parameter registry: every named parameter with its SI unit on a rotary and on a
//! linear axis, its meaning, the physical constraint its value must meet and the
//! topologies and axes it applies to (docs/model.md §1, §6, §11). [`Params::set`],
//! [`Params::get`], [`Params::validate`] and the file form read it.
//!
//! [`Params::set`]: super::params::Params::set
//! [`Params::get`]: super::params::Params::get
//! [`Params::validate`]: super::params::Params::validate

use super::params::{Axis, ParamError, Params, Topology};

/// The physical constraint a parameter's value must satisfy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Constraint {
    /// > 0 (inertias, stiffnesses, radii, periods).
    Positive,
    /// ≥ 0 (damping, friction, backlash, amplitudes).
    NonNegative,
    /// ≠ 0 (gear ratios).
    NonZero,
    /// Any finite value (phases, loads).
    Finite,
    /// Exactly 0 or 1 (a switch).
    ZeroOrOne,
}

impl Constraint {
    /// Why a range `lo..hi` (lo < hi) of a parameter so constrained holds values it
    /// cannot take, if it does: a stiffness through zero, a ratio through zero.
    pub fn range_fault(self, lo: f64, hi: f64) -> Option<&'static str> {
        match self {
            // A range from 0 itself is a linear search's (the search never takes
            // its ends); below 0 it holds values the model cannot take.
            Constraint::Positive if lo < 0.0 => {
                Some("the parameter must be positive: the range may not go below 0")
            }
            Constraint::NonNegative if lo < 0.0 => {
                Some("the parameter must be ≥ 0: the range may not go below 0")
            }
            Constraint::NonZero if lo <= 0.0 && hi >= 0.0 => {
                Some("the parameter must not be 0 (its sign is the direction): the range may not pass through 0")
            }
            _ => None,
        }
    }
}

/// Which topologies a parameter belongs to (docs/model.md §1, §11).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Applies {
    /// Every topology.
    Always,
    /// Only with a spur-gear stage (`spur_gear`).
    SpurGearOnly,
    /// The drives with a driving shaft, a drive ratio Rw and an axial bearing: the
    /// worm (`spur_gear`) and the cam (`direct`).
    Geared,
    /// Every topology whose motor is a body of its own, joined to the table by an
    /// elastic drive: all but `direct_drive`.
    SeparateMotor,
}

impl Applies {
    /// Whether a parameter of this kind belongs to `topology`.
    pub fn to(self, topology: Topology) -> bool {
        match self {
            Applies::Always => true,
            Applies::SpurGearOnly => topology == Topology::SpurGear,
            Applies::Geared => matches!(topology, Topology::SpurGear | Topology::Direct),
            Applies::SeparateMotor => topology != Topology::DirectDrive,
        }
    }
}

/// One entry of the parameter registry.
pub struct ParamSpec {
    /// Name in files and on the command line.
    pub name: &'static str,
    /// SI unit on a rotary axis (also the unit of sweep columns).
    pub unit: &'static str,
    /// SI unit on a linear axis (the same as `unit` where they do not differ).
    pub linear_unit: &'static str,
    /// What it is.
    pub meaning: &'static str,
    /// The check [`Params::validate`](super::params::Params::validate) applies.
    pub constraint: Constraint,
    /// Topologies it applies to.
    pub applies: Applies,
    /// Whether it applies only to a rotary axis (unbalance, fluctuation per
    /// revolution, encoder counts per revolution).
    pub rotary_only: bool,
    /// The value it holds where it does not apply (0, or 1 for ratios and orders).
    pub unused: f64,
    /// Whether it is an optional spur-gear parameter (`Option<f64>`, `None` where it
    /// does not apply).
    pub optional: bool,
    get: fn(&Params) -> Option<f64>,
    set: fn(&mut Params, f64),
}

impl ParamSpec {
    /// The value in `p`, `None` when it does not apply to `p`'s topology or axis.
    pub fn get(&self, p: &Params) -> Option<f64> {
        if self.applies_to(p.topology, p.axis) {
            (self.get)(p)
        } else {
            None
        }
    }

    /// The stored value whether or not it applies (`None`: an optional spur-gear
    /// parameter that is absent).
    pub(crate) fn raw(&self, p: &Params) -> Option<f64> {
        (self.get)(p)
    }

    /// Stores `value` without any check.
    pub(crate) fn store(&self, p: &mut Params, value: f64) {
        (self.set)(p, value)
    }

    /// Whether it belongs to a drive of `topology` on an axis of kind `axis`.
    pub(crate) fn applies_to(&self, topology: Topology, axis: Axis) -> bool {
        self.applies.to(topology) && !(self.rotary_only && axis == Axis::Linear)
    }

    /// The SI unit on an axis of kind `axis`.
    pub fn unit_for(&self, axis: Axis) -> &'static str {
        match axis {
            Axis::Rotary => self.unit,
            Axis::Linear => self.linear_unit,
        }
    }

    /// Both units where they differ, for listings: `kg·m² (linear axis: kg)`.
    pub fn units(&self) -> String {
        if self.unit == self.linear_unit {
            self.unit.to_string()
        } else {
            format!("{} (linear axis: {})", self.unit, self.linear_unit)
        }
    }
}

/// One registry entry: `spec!(name, [rotary unit, linear unit] or [unit], meaning,
/// constraint, applies, rotary_only, unused, field path)`; `opt` before the field
/// marks an optional spur-gear parameter (`Option<f64>`).
macro_rules! spec {
    ($name:literal, [$unit:literal], $($rest:tt)*) => {
        spec!($name, [$unit, $unit], $($rest)*)
    };
    ($name:literal, [$unit:literal, $lin:literal], $meaning:literal, $c:ident, $a:ident,
     $rot:literal, $unused:literal, opt $field:ident) => {
        ParamSpec {
            name: $name,
            unit: $unit,
            linear_unit: $lin,
            meaning: $meaning,
            constraint: Constraint::$c,
            applies: Applies::$a,
            rotary_only: $rot,
            unused: $unused,
            optional: true,
            get: |p| p.$field,
            set: |p, v| p.$field = Some(v),
        }
    };
    ($name:literal, [$unit:literal, $lin:literal], $meaning:literal, $c:ident, $a:ident,
     $rot:literal, $unused:literal, $($field:ident).+) => {
        ParamSpec {
            name: $name,
            unit: $unit,
            linear_unit: $lin,
            meaning: $meaning,
            constraint: Constraint::$c,
            applies: Applies::$a,
            rotary_only: $rot,
            unused: $unused,
            optional: false,
            get: |p| Some(p.$($field).+),
            set: |p, v| p.$($field).+ = v,
        }
    };
}

/// Every named parameter, in the order of docs/model.md §11, then the load and the
/// controller's. Columns: name, unit (rotary, linear), meaning, constraint,
/// topologies, rotary axes only, value where unused, field.
#[rustfmt::skip]
pub const PARAMS: &[ParamSpec] = &[
    spec!("Jm", ["kg·m²", "kg"], "motor inertia (direct: motor + cam)", Positive, SeparateMotor, false, 0.0, jm),
    spec!("Jw", ["kg·m²"], "spur gears + driving shaft inertia", NonNegative, Geared, false, 0.0, jw),
    spec!("Jt", ["kg·m²", "kg"], "table + driven part inertia (direct_drive: with the rotor; linear: carriage mass)", Positive, Always, false, 0.0, jt),
    spec!("Mw", ["kg"], "driving unit mass (axial)", Positive, Geared, false, 0.0, mw),
    spec!("Cm", ["N·m·s/rad", "N·s/m"], "motor viscous damping", NonNegative, SeparateMotor, false, 0.0, cm),
    spec!("Cw", ["N·m·s/rad"], "driving shaft viscous damping", NonNegative, Geared, false, 0.0, cw),
    spec!("Cb", ["N·s/m"], "axial viscous damping", NonNegative, Geared, false, 0.0, cb),
    spec!("Ct", ["N·m·s/rad", "N·s/m"], "table viscous damping", NonNegative, Always, false, 0.0, ct),
    spec!("Cig", ["N·m·s/rad"], "internal damping of the spur-gear mesh", NonNegative, SpurGearOnly, false, 0.0, opt cig),
    spec!("Ciw", ["N·m·s/rad", "N·s/m"], "internal damping of the drive mesh (two_mass: the coupling)", NonNegative, SeparateMotor, false, 0.0, ciw),
    spec!("fm", ["N·m", "N"], "motor Coulomb friction", NonNegative, SeparateMotor, false, 0.0, fm),
    spec!("fw", ["N·m"], "driving shaft Coulomb friction", NonNegative, Geared, false, 0.0, fw),
    spec!("ft", ["N·m", "N"], "table Coulomb friction", NonNegative, Always, false, 0.0, ft),
    spec!("fsm", ["N·m", "N"], "motor Stribeck rise: static friction above fm (0: Coulomb)", NonNegative, SeparateMotor, false, 0.0, fsm),
    spec!("fsw", ["N·m"], "driving shaft Stribeck rise: static friction above fw (0: Coulomb)", NonNegative, SpurGearOnly, false, 0.0, fsw),
    spec!("fst", ["N·m", "N"], "table Stribeck rise: static friction above ft (0: Coulomb)", NonNegative, Always, false, 0.0, fst),
    spec!("vsm", ["rad/s", "m/s"], "motor Stribeck speed (the rise falls to 1/e)", NonNegative, SeparateMotor, false, 0.0, vsm),
    spec!("vsw", ["rad/s"], "driving shaft Stribeck speed", NonNegative, SpurGearOnly, false, 0.0, vsw),
    spec!("vst", ["rad/s", "m/s"], "table Stribeck speed", NonNegative, Always, false, 0.0, vst),
    spec!("stribeck_shape", ["-"], "Stribeck shape exponent δ: rise·exp(−(|speed|/vs)^δ)", Positive, Always, false, 2.0, stribeck_shape),
    spec!("Kg", ["N·m/rad"], "spur-gear torsional stiffness (shaft units)", Positive, SpurGearOnly, false, 0.0, opt kg),
    spec!("Kw", ["N·m/rad", "N/m"], "drive torsional stiffness (table units; two_mass: the coupling)", Positive, SeparateMotor, false, 0.0, kw),
    spec!("Kb", ["N/m"], "axial bearing stiffness", Positive, Geared, false, 0.0, kb),
    spec!("Rg", ["-"], "spur-gear ratio (shaft turns per motor turn)", NonZero, SpurGearOnly, false, 0.0, opt rg),
    spec!("Rw", ["-"], "drive ratio (table turns per shaft turn)", NonZero, Geared, false, 1.0, rw),
    spec!("r", ["m"], "radius of the driven part", Positive, Geared, false, 0.0, r),
    spec!("theta_bg", ["rad"], "spur-gear backlash half-width (shaft units)", NonNegative, SpurGearOnly, false, 0.0, opt theta_bg),
    spec!("theta_bw", ["rad", "m"], "drive backlash half-width (table units; two_mass: the coupling)", NonNegative, SeparateMotor, false, 0.0, theta_bw),
    spec!("W", ["rad"], "gear-fluctuation amplitude (table units)", NonNegative, SeparateMotor, true, 0.0, w),
    spec!("fluct_order", ["-"], "fluctuation cycles per shaft revolution (two_mass: per motor revolution)", Positive, SeparateMotor, true, 1.0, fluct_order),
    spec!("fluct_phase", ["rad"], "fluctuation phase", Finite, SeparateMotor, true, 0.0, fluct_phase),
    spec!("unbalance_mass", ["kg"], "unbalance mass on a vertical table", NonNegative, Always, true, 0.0, unbalance_mass),
    spec!("unbalance_radius", ["m"], "radius of the unbalance mass", NonNegative, Always, true, 0.0, unbalance_radius),
    spec!("unbalance_phase", ["rad"], "angle of the unbalance mass at θt = 0", Finite, Always, true, 0.0, unbalance_phase),
    spec!("encoder_delay", ["s"], "dead time of the motor encoder", NonNegative, Always, false, 0.0, encoder_delay),
    spec!("Tload", ["N·m", "N"], "constant external table torque (linear: force), positive in the positive sense of motion", Finite, Always, false, 0.0, tload),
    spec!("Kpp", ["1/s"], "position loop gain", NonNegative, Always, false, 0.0, controller.kpp),
    spec!("Kpi", ["1/s²"], "position loop integral gain (0: P position loop)", NonNegative, Always, false, 0.0, controller.kpi),
    spec!("Kvp", ["N·m·s/rad", "N·s/m"], "velocity loop proportional gain (output unit·s per rad or m; N·m or N for a torque command)", NonNegative, Always, false, 0.0, controller.kvp),
    spec!("Kvi", ["N·m/rad", "N/m"], "velocity loop integral gain (output unit per rad or m)", NonNegative, Always, false, 0.0, controller.kvi),
    spec!("Tc", ["s"], "control period", Positive, Always, false, 0.0, controller.tc),
    spec!("torque_limit", ["N·m", "N"], "limit of the controller output, in its unit (N·m or N for a torque command; V or A with a drive_gain)", Positive, Always, false, 0.0, controller.torque_limit),
    spec!("speed_limit", ["rad/s", "m/s"], "velocity command limit (motor)", Positive, Always, false, 0.0, controller.speed_limit),
    spec!("drive_gain", ["N·m/output", "N/output"], "torque (force) per unit of controller output: V→N, A→N·m, 1 for a torque command", Positive, Always, false, 1.0, controller.drive_gain),
    spec!("output_delay_periods", ["-"], "control periods from sampling to output: 0 at the sample, 1 one sample late", ZeroOrOne, Always, false, 0.0, controller.output_delay_periods),
    spec!("motor_encoder_counts", ["1/rev"], "motor encoder counts per revolution (0: ideal or given by resolution)", NonNegative, Always, true, 0.0, controller.motor_encoder_counts),
    spec!("motor_encoder_resolution", ["rad", "m"], "motor (loop) encoder resolution (0: ideal or given by counts)", NonNegative, Always, false, 0.0, controller.motor_encoder_resolution),
    spec!("table_encoder_resolution", ["rad", "m"], "table encoder resolution (0: ideal)", NonNegative, Always, false, 0.0, controller.table_encoder_resolution),
    spec!("Kvff", ["-"], "velocity feed-forward: fraction of the reference's velocity added to the velocity command (0: off)", NonNegative, Always, false, 0.0, controller.kvff),
    spec!("Kaff", ["N·m·s²/rad", "N·s²/m"], "torque feed-forward: output per unit of the reference's motor acceleration (0: off; inertia at the motor over the drive gain: all of it)", NonNegative, Always, false, 0.0, controller.kaff),
    spec!("symmetrising_s", ["s"], "time constant of the symmetrising lag on the position loop's reference (0: none)", NonNegative, Always, false, 0.0, controller.symmetrising_s),
    spec!("current_lag_s", ["s"], "the current loop's closed-loop lag: a first-order lag from the controller's output to the torque, sampled at Tc (0: none)", NonNegative, Always, false, 0.0, controller.current_lag_s),
    spec!("position_period_s", ["s"], "the position controller's own cycle, a whole number of control periods (0: every control period)", NonNegative, Always, false, 0.0, controller.position_period_s),
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
    let names: Vec<&str> = PARAMS.iter().map(|s| s.name).collect();
    match crate::names::misspelling_of(name, &names) {
        Some(known) => format!(" (did you mean `{known}`?)"),
        None => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_say_both_axes_where_they_differ() {
        let jt = spec("Jt").unwrap();
        assert_eq!(jt.units(), "kg·m² (linear axis: kg)");
        assert_eq!(jt.unit_for(Axis::Linear), "kg");
        assert_eq!(spec("Tc").unwrap().units(), "s");
        assert_eq!(spec("Ct").unwrap().unit_for(Axis::Linear), "N·s/m");
    }

    #[test]
    fn applicability_follows_model_md() {
        let jm = spec("Jm").unwrap();
        assert!(jm.applies_to(Topology::TwoMass, Axis::Rotary));
        assert!(!jm.applies_to(Topology::DirectDrive, Axis::Rotary));
        let kb = spec("Kb").unwrap();
        assert!(kb.applies_to(Topology::Direct, Axis::Rotary));
        assert!(!kb.applies_to(Topology::TwoMass, Axis::Rotary));
        let unbalance = spec("unbalance_mass").unwrap();
        assert!(unbalance.applies_to(Topology::DirectDrive, Axis::Rotary));
        assert!(!unbalance.applies_to(Topology::DirectDrive, Axis::Linear));
        assert!(spec("Tload")
            .unwrap()
            .applies_to(Topology::DirectDrive, Axis::Linear));
    }
}
