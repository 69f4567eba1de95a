//! The kinds of experiment `rtid import` writes, and the roles each takes: what a
//! `--map ROLE=…` may name, what it must measure, and which are required.

use crate::io::experiment_file::Kind;
use crate::io::formats::units::Quantity;

/// A kind `rtid import` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImportKind {
    ServoTrace,
    TorqueCurve,
    FrequencyResponse,
    FrequencyResponseTime,
    Positioning,
    FrictionMap,
}

/// A role of a kind.
#[derive(Clone, Copy, Debug)]
pub struct Role {
    pub name: &'static str,
    /// What it may measure (any of them).
    pub quantities: &'static [Quantity],
    pub required: bool,
    /// In words, for `--help` and messages.
    pub meaning: &'static str,
}

const fn role(
    name: &'static str,
    quantities: &'static [Quantity],
    required: bool,
    meaning: &'static str,
) -> Role {
    Role {
        name,
        quantities,
        required,
        meaning,
    }
}

use Quantity::*;

const POSITION: &[Quantity] = &[Angle, Length];
const EFFORT: &[Quantity] = &[Torque, Force];
const COMMAND: &[Quantity] = &[Voltage, Current, Torque, Force];
const TIME: Role = role(
    "time",
    &[Time],
    false,
    "the time base (default: the mapped channels' own abscissa)",
);

const SERVO_TRACE: &[Role] = &[
    TIME,
    role(
        "reference_position",
        POSITION,
        true,
        "the position command the loop follows",
    ),
    role(
        "position",
        POSITION,
        true,
        "the loop's encoder (the motor's in a semi-closed loop)",
    ),
    role(
        "table_position",
        POSITION,
        false,
        "a second encoder on the table or carriage",
    ),
    role(
        "effort",
        EFFORT,
        true,
        "the drive's torque or force (computed: CHANNEL*GAIN:N·m)",
    ),
    role(
        "controller_output",
        COMMAND,
        false,
        "what the controller sent (V, A, N·m or N)",
    ),
    role(
        "controller_added",
        COMMAND,
        false,
        "a recorded signal added to the controller output",
    ),
];

const TORQUE_CURVE: &[Role] = &[
    TIME,
    role(
        "effort",
        EFFORT,
        true,
        "the motor torque (rotary) or drive force (linear)",
    ),
    role(
        "position",
        POSITION,
        false,
        "the table angle or carriage position",
    ),
];

const FREQUENCY_RESPONSE: &[Role] = &[
    role(
        "frequency",
        &[Frequency],
        false,
        "the frequencies (default: the mapped channels' own abscissa)",
    ),
    role(
        "frf",
        &[Number],
        false,
        "a complex response: gain and phase from it",
    ),
    role(
        "gain",
        &[Decibel, Number],
        false,
        "the gain, in dB or as a ratio",
    ),
    role("phase", &[Angle], false, "the phase"),
];

const FREQUENCY_RESPONSE_TIME: &[Role] = &[
    TIME,
    role(
        "motor_torque",
        &[Torque],
        false,
        "the motor torque (or motor_current)",
    ),
    role(
        "motor_current",
        &[Current],
        false,
        "the motor current (or motor_torque)",
    ),
    role("motor_angle", &[Angle], true, "the motor shaft's angle"),
    role(
        "table_angle",
        &[Angle],
        true,
        "the table's (or load's) angle",
    ),
];

const POSITIONING: &[Role] = &[
    role(
        "target",
        POSITION,
        true,
        "the target position of each approach",
    ),
    role(
        "deviation",
        POSITION,
        true,
        "measured minus target position",
    ),
    role(
        "direction",
        &[Number],
        true,
        "the approach: > 0 positive (up, ccw), < 0 negative",
    ),
    role("run", &[Number], true, "the run (cycle) number, from 1"),
];

const FRICTION_MAP: &[Role] = &[
    role(
        "time",
        &[Time],
        false,
        "each run's time base (checked for gaps only)",
    ),
    role(
        "speed",
        &[AngularVelocity, Velocity],
        true,
        "the motor's speed (rotary) or the axis's (linear)",
    ),
    role(
        "effort",
        EFFORT,
        true,
        "the motor torque (rotary) or drive force (linear)",
    ),
];

impl ImportKind {
    pub const ALL: &'static [ImportKind] = &[
        ImportKind::ServoTrace,
        ImportKind::TorqueCurve,
        ImportKind::FrequencyResponse,
        ImportKind::FrequencyResponseTime,
        ImportKind::Positioning,
        ImportKind::FrictionMap,
    ];

    /// As the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            ImportKind::ServoTrace => "servo-trace",
            ImportKind::TorqueCurve => "torque-curve",
            ImportKind::FrequencyResponse => "frequency-response",
            ImportKind::FrequencyResponseTime => "frequency-response-time",
            ImportKind::Positioning => "positioning",
            ImportKind::FrictionMap => "friction-map",
        }
    }

    /// The experiment file's kind.
    pub fn kind(self) -> Kind {
        match self {
            ImportKind::ServoTrace => Kind::ServoTrace,
            ImportKind::TorqueCurve => Kind::TorqueCurve,
            ImportKind::FrequencyResponse => Kind::FrequencyResponse,
            ImportKind::FrequencyResponseTime => Kind::FrequencyResponseTime,
            ImportKind::Positioning => Kind::Positioning,
            ImportKind::FrictionMap => Kind::FrictionMap,
        }
    }

    pub fn roles(self) -> &'static [Role] {
        match self {
            ImportKind::ServoTrace => SERVO_TRACE,
            ImportKind::TorqueCurve => TORQUE_CURVE,
            ImportKind::FrequencyResponse => FREQUENCY_RESPONSE,
            ImportKind::FrequencyResponseTime => FREQUENCY_RESPONSE_TIME,
            ImportKind::Positioning => POSITIONING,
            ImportKind::FrictionMap => FRICTION_MAP,
        }
    }

    /// The kind spelled `name` (`servo-trace` or `servo_trace`).
    pub fn parse(name: &str) -> Option<ImportKind> {
        let name = name.replace('_', "-");
        ImportKind::ALL.iter().copied().find(|k| k.name() == name)
    }

    /// The roles in words, for messages.
    pub fn describe_roles(self) -> String {
        self.roles()
            .iter()
            .map(|r| format!("{}{}", r.name, if r.required { " (required)" } else { "" }))
            .collect::<Vec<_>>()
            .join(", ")
    }
}
