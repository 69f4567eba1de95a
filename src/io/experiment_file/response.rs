//! What a frequency-response file's complex ratio is: which ratio ([`Response`]),
//! which channel the analyser divided by ([`Reference`]), and the delay of the
//! measurement chain in its phase ([`Delay`]) — the manifest's `response`,
//! `reference` and `delay_s` (docs/experiment-files.md, "frequency_response").

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::Conditions;

/// Which ratio a frequency-response file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Response {
    /// Table angle over motor angle × Rg·Rw (dimensionless): 1 at low frequency,
    /// peaks at the motor-held modes (the paper's test).
    #[default]
    TableOverMotor,
    /// Motor angle over motor torque, rad/(N·m) (gain in dB re 1 rad/(N·m)): the
    /// compliance the motor sees — antiresonances at the motor-held modes, resonances
    /// at the free ones; the only informative ratio of a direct drive.
    MotorCompliance,
    /// Actual motor speed over speed setpoint with the speed loop closed
    /// (dimensionless): the drive's own reference response of its speed loop, 1 at
    /// low frequency — the mechanics seen through the speed controller
    /// (`objectives::speed_loop`).
    SpeedLoop,
}

impl Response {
    /// The name written to manifests.
    pub fn name(self) -> &'static str {
        match self {
            Response::TableOverMotor => "table_over_motor",
            Response::MotorCompliance => "motor_compliance",
            Response::SpeedLoop => "speed_loop",
        }
    }

    /// The channel the analyser divides by when the file holds this ratio as named.
    pub fn reference(self) -> Reference {
        match self {
            Response::TableOverMotor => Reference::MotorAngle,
            Response::MotorCompliance => Reference::MotorTorque,
            Response::SpeedLoop => Reference::SpeedSetpoint,
        }
    }

    /// The other channel of the ratio: a file divided by it holds the inverse.
    pub fn output(self) -> Reference {
        match self {
            Response::TableOverMotor => Reference::TableAngle,
            Response::MotorCompliance => Reference::MotorAngle,
            Response::SpeedLoop => Reference::MotorSpeed,
        }
    }
}

/// The channel an analyser divided by (its reference, the denominator of H).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reference {
    MotorAngle,
    TableAngle,
    MotorTorque,
    /// The speed loop's setpoint.
    SpeedSetpoint,
    /// The motor's actual speed as the drive measures it.
    MotorSpeed,
}

impl Reference {
    /// The name written to manifests.
    pub fn name(self) -> &'static str {
        match self {
            Reference::MotorAngle => "motor_angle",
            Reference::TableAngle => "table_angle",
            Reference::MotorTorque => "motor_torque",
            Reference::SpeedSetpoint => "speed_setpoint",
            Reference::MotorSpeed => "motor_speed",
        }
    }
}

/// A constant delay of the measurement chain (anti-alias filters, a drive's
/// recorder): the file's phase holds −2π·f·delay on top of the drive's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Delay {
    /// Known, s (≥ 0): taken out of the phase before the fit.
    Given(f64),
    /// Not known: fitted with the model (`"delay_s": "unknown"`).
    Unknown,
}

impl Serialize for Delay {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Delay::Given(d) => s.serialize_f64(*d),
            Delay::Unknown => s.serialize_str("unknown"),
        }
    }
}

impl<'de> Deserialize<'de> for Delay {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Number(f64),
            Word(String),
        }
        match Raw::deserialize(d)? {
            Raw::Number(x) => Ok(Delay::Given(x)),
            Raw::Word(w) if w == "unknown" => Ok(Delay::Unknown),
            Raw::Word(w) => Err(serde::de::Error::custom(format!(
                "`delay_s` is \"{w}\": give the delay in seconds, or \"unknown\" to fit it"
            ))),
        }
    }
}

/// How the file's complex ratio relates to the drive's, resolved from a manifest.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResponseForm {
    pub response: Response,
    /// The file holds the inverse of `response` (its reference is the other channel).
    pub inverted: bool,
    pub delay: Delay,
}

impl ResponseForm {
    /// The form the conditions state (defaults: table over motor, referred to the
    /// motor angle, no delay).
    pub fn of(c: &Conditions) -> ResponseForm {
        let response = c.response.unwrap_or_default();
        ResponseForm {
            response,
            inverted: c.reference.is_some_and(|r| r == response.output()),
            delay: c.delay_s.unwrap_or(Delay::Given(0.0)),
        }
    }
}

/// The frequency-response conditions: a reference that is one of the ratio's two
/// channels, a finite non-negative delay, a positive number of averages.
pub(super) fn check(c: &Conditions) -> Result<(), String> {
    let response = c.response.unwrap_or_default();
    if let Some(r) = c.reference {
        if r != response.reference() && r != response.output() {
            return Err(format!(
                "`conditions.reference` is {}: a {} response is referred to {} (the \
                 default) or to {} (the file holds the inverse ratio; rtid inverts it)",
                r.name(),
                response.name(),
                response.reference().name(),
                response.output().name()
            ));
        }
    }
    if let Some(Delay::Given(d)) = c.delay_s {
        if !(d.is_finite() && d >= 0.0) {
            return Err(format!(
                "`conditions.delay_s` is {d}: a delay is a time ≥ 0 s (or \"unknown\" to fit it)"
            ));
        }
    }
    if let Some(p) = c.loop_period_s.filter(|p| *p <= 0.0) {
        return Err(format!(
            "`conditions.loop_period_s` is {p}: the speed loop's sample period must be positive"
        ));
    }
    if c.averages == Some(0) {
        return Err(
            "`conditions.averages` is 0: the estimate averages at least one segment".into(),
        );
    }
    Ok(())
}
