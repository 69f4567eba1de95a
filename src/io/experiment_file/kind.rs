//! Which experiments a file can hold: one [`Definition`] per [`Kind`], listed in
//! [`KINDS`] — its name in manifests, whether it has a CSV, its table's reader and
//! reserved columns, its conditions' defaults and checks. A new kind is its variant,
//! its `Data` variant, its definition and one line in [`KINDS`]
//! (docs/architecture.md).

use std::fmt;

use serde::{Deserialize, Serialize};

use super::conditions::{self, Conditions};
use super::table::{kinds as columns, Table};
use super::{response, Data, ExperimentFileError as Error};

/// Which experiment a file holds (docs/experiments.md and docs/experiment-files.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// Open-loop gain (and optionally phase) over frequency.
    FrequencyResponse,
    /// Resonance peaks only, listed in the manifest (no CSV).
    Resonance,
    /// Motor torque over time during a commanded sinusoidal table motion.
    TorqueCurve,
    /// ISO 230-2 positioning runs: deviation per target, direction and run.
    Positioning,
    /// Table and motor angle over time at constant speed (rotational fluctuation).
    Fluctuation,
    /// As [`Kind::Fluctuation`], with an offset mass on a vertical table.
    Unbalance,
    /// Raw time series of a frequency-response test (motor torque or current, motor and
    /// table angle, uniformly sampled), from which the gain curve is estimated.
    FrequencyResponseTime,
    /// A recorded closed-loop run: position command, the loop's encoder, the drive's
    /// effort and the controller output over uniformly sampled time.
    ServoTrace,
    /// Constant-speed runs: each run's mean speed and mean effort at the motor, one row
    /// per run (the friction map).
    FrictionMap,
}

/// What rtid knows of a kind of experiment file.
pub struct Definition {
    /// The kind it defines.
    pub kind: Kind,
    /// The name used in manifests (`frequency_response`, …).
    pub name: &'static str,
    /// Whether the experiment has a CSV data file (all kinds but `resonance`).
    pub data_file: bool,
    /// Its table read into typed data.
    pub(super) read: fn(Table) -> Result<Data, Error>,
    /// The column names its reader interprets (an extra column must not take one).
    pub(super) reserved: fn() -> Vec<String>,
    /// docs/experiment-files.md's defaults of its conditions, filled in where absent.
    pub(super) defaults: fn(&mut Conditions),
    /// The checks of its conditions on the manifest alone.
    pub(super) check: fn(&Conditions) -> Result<(), String>,
}

/// No conditions to fill in, or none to check.
fn no_defaults(_: &mut Conditions) {}
fn no_check(_: &Conditions) -> Result<(), String> {
    Ok(())
}

/// Every kind, in the order of docs/experiment-files.md, then the kinds added since;
/// the `n`-th defines the `n`-th variant of [`Kind`].
pub static KINDS: &[Definition] = &[
    Definition {
        kind: Kind::FrequencyResponse,
        name: "frequency_response",
        data_file: true,
        read: Table::frequency_response,
        reserved: columns::frequency_response,
        defaults: conditions::frequency_response_defaults,
        check: response::check,
    },
    Definition {
        kind: Kind::Resonance,
        name: "resonance",
        data_file: false,
        read: Table::no_table,
        reserved: Vec::new,
        defaults: no_defaults,
        check: no_check,
    },
    Definition {
        kind: Kind::TorqueCurve,
        name: "torque_curve",
        data_file: true,
        read: Table::torque_curve,
        reserved: columns::torque_curve,
        defaults: conditions::torque_curve_defaults,
        check: no_check,
    },
    Definition {
        kind: Kind::Positioning,
        name: "positioning",
        data_file: true,
        read: Table::positioning,
        reserved: columns::positioning,
        defaults: conditions::positioning_defaults,
        check: no_check,
    },
    Definition {
        kind: Kind::Fluctuation,
        name: "fluctuation",
        data_file: true,
        read: |t| t.fluctuation(Kind::Fluctuation),
        reserved: columns::fluctuation,
        defaults: |c| conditions::fluctuation_defaults(c, 180.0),
        check: no_check,
    },
    Definition {
        kind: Kind::Unbalance,
        name: "unbalance",
        data_file: true,
        read: |t| t.fluctuation(Kind::Unbalance),
        reserved: columns::fluctuation,
        defaults: |c| conditions::fluctuation_defaults(c, 360.0),
        check: no_check,
    },
    Definition {
        kind: Kind::FrequencyResponseTime,
        name: "frequency_response_time",
        data_file: true,
        read: Table::record,
        reserved: columns::record,
        defaults: Conditions::record_defaults,
        check: conditions::check_record,
    },
    Definition {
        kind: Kind::ServoTrace,
        name: "servo_trace",
        data_file: true,
        read: Table::servo_trace,
        reserved: columns::servo_trace,
        defaults: no_defaults,
        check: conditions::check_servo,
    },
    Definition {
        kind: Kind::FrictionMap,
        name: "friction_map",
        data_file: true,
        read: Table::friction_map,
        reserved: columns::friction_map,
        defaults: no_defaults,
        check: no_check,
    },
];

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Kind {
    /// Its definition in [`KINDS`].
    pub fn definition(self) -> &'static Definition {
        &KINDS[self as usize]
    }

    /// Every kind, in the order of [`KINDS`].
    pub fn all() -> impl Iterator<Item = Kind> {
        KINDS.iter().map(|d| d.kind)
    }

    /// The name used in manifests (`frequency_response`, …).
    pub fn name(self) -> &'static str {
        self.definition().name
    }

    /// Whether the experiment has a CSV data file (all kinds but `resonance`).
    pub fn has_data_file(self) -> bool {
        self.definition().data_file
    }

    /// Every column name rtid reads from this kind's CSV: the reader's own (each
    /// position or angle under each unit suffix) and the optional ones its
    /// evaluators read (docs/experiment-files.md).
    pub fn columns(self) -> Vec<String> {
        let mut all = (self.definition().reserved)();
        all.extend(columns::optional(self));
        all
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_definition_sits_at_its_kinds_index() {
        for (i, d) in KINDS.iter().enumerate() {
            assert_eq!(d.kind as usize, i, "{}", d.name);
            assert_eq!(d.kind.definition().name, d.name);
        }
        assert_eq!(Kind::all().count(), KINDS.len());
    }
}
