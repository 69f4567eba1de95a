//! The units an experiment file may carry in its column names, and what they say about
//! the axis: angles and torques belong to a rotary axis, lengths and forces to a linear
//! one (docs/model.md §1, "Linear axes"). The reader converts every position to SI (rad or
//! m) and keeps which of the two it was.

use std::fmt;

use serde::{Deserialize, Serialize};

/// Radians per degree.
pub(super) const DEG: f64 = std::f64::consts::PI / 180.0;
/// Radians per arc-second.
pub(super) const ARCSEC: f64 = std::f64::consts::PI / 648_000.0;
/// Metres per millimetre.
pub(super) const MM: f64 = 1e-3;
/// Metres per micrometre.
pub(super) const UM: f64 = 1e-6;

pub use crate::model::Axis;

/// A position (or speed) suffix of a column name: the axis it implies and SI units
/// (rad or m; rad/s or m/s) per unit written.
#[derive(Clone, Copy, Debug)]
pub(super) struct PositionUnit {
    pub suffix: &'static str,
    pub axis: Axis,
    pub si: f64,
}

/// Every position suffix the reader accepts, angles first.
pub(super) const POSITION_UNITS: [PositionUnit; 6] = [
    PositionUnit {
        suffix: "deg",
        axis: Axis::Rotary,
        si: DEG,
    },
    PositionUnit {
        suffix: "rad",
        axis: Axis::Rotary,
        si: 1.0,
    },
    PositionUnit {
        suffix: "arcsec",
        axis: Axis::Rotary,
        si: ARCSEC,
    },
    PositionUnit {
        suffix: "m",
        axis: Axis::Linear,
        si: 1.0,
    },
    PositionUnit {
        suffix: "mm",
        axis: Axis::Linear,
        si: MM,
    },
    PositionUnit {
        suffix: "um",
        axis: Axis::Linear,
        si: UM,
    },
];

/// Radians per second per revolution per minute.
pub(super) const RPM: f64 = std::f64::consts::PI / 30.0;

/// Every speed suffix the reader accepts (`speed_rad_s`, …), rotary first; the
/// writer writes the first of each axis (`rad_s`, `m_s`).
pub(super) const SPEED_UNITS: [PositionUnit; 5] = [
    PositionUnit {
        suffix: "rad_s",
        axis: Axis::Rotary,
        si: 1.0,
    },
    PositionUnit {
        suffix: "rpm",
        axis: Axis::Rotary,
        si: RPM,
    },
    PositionUnit {
        suffix: "deg_s",
        axis: Axis::Rotary,
        si: DEG,
    },
    PositionUnit {
        suffix: "m_s",
        axis: Axis::Linear,
        si: 1.0,
    },
    PositionUnit {
        suffix: "mm_s",
        axis: Axis::Linear,
        si: MM,
    },
];

/// The suffixes a column named `{base}_<unit>` may take: angles only for a base that
/// says it is an angle (`table_angle`, `phase`), any position unit otherwise
/// (`target`, `position`, `table_position`).
pub(super) fn units_for(base: &str) -> &'static [PositionUnit] {
    if base.ends_with("angle") || base == "phase" {
        &POSITION_UNITS[..3]
    } else {
        &POSITION_UNITS
    }
}

/// The unit of a controller output (the command a servo amplifier receives): a voltage
/// (an analog reference), a current (a current command), or the torque or force
/// commanded directly (docs/model.md §1: "V, A, or 1 for a torque command").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CommandUnit {
    /// Volts (`_v`).
    Volt,
    /// Amperes (`_a`).
    Ampere,
    /// A torque command, N·m (`_nm`).
    NewtonMetre,
    /// A force command, N (`_n`).
    Newton,
}

impl CommandUnit {
    /// Every command unit, in the order the reader looks for them.
    pub const ALL: [CommandUnit; 4] = [
        CommandUnit::Volt,
        CommandUnit::Ampere,
        CommandUnit::NewtonMetre,
        CommandUnit::Newton,
    ];

    /// The suffix of a column in this unit: `v`, `a`, `nm` or `n`.
    pub fn suffix(self) -> &'static str {
        match self {
            CommandUnit::Volt => "v",
            CommandUnit::Ampere => "a",
            CommandUnit::NewtonMetre => "nm",
            CommandUnit::Newton => "n",
        }
    }

    /// The unit's symbol: `V`, `A`, `N·m` or `N`.
    pub fn symbol(self) -> &'static str {
        match self {
            CommandUnit::Volt => "V",
            CommandUnit::Ampere => "A",
            CommandUnit::NewtonMetre => "N·m",
            CommandUnit::Newton => "N",
        }
    }
}

impl fmt::Display for CommandUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.symbol())
    }
}
