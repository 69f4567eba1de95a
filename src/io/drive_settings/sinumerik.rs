//! The position loop and the feed-forward as SINUMERIK machine data for machine axis
//! `AXn`: MD32200 `$MA_POSCTRL_GAIN` (Kv), MD32620 `$MA_FFW_MODE`, MD32610
//! `$MA_VELO_FFW_WEIGHT`, MD32810 `$MA_EQUIV_SPEEDCTRL_TIME`, and on a rotary axis the
//! gear MD31050/MD31060 `$MA_DRIVE_AX_RATIO_DENOM`/`_NUMERA` the Kv is computed
//! with.
//!
//! **Conversions** (docs/drive-settings.md gives the sources):
//!
//! - Kv: rtid's ω* = Kpp·e acts on motor radians and gives motor rad/s; at the table
//!   both are scaled by the same ratio, so the table's Kv is Kpp, 1/s. SINUMERIK's
//!   unit is 1000/min ((m/min)/mm): MD32200 = Kpp·60/1000 (1 (m/min)/mm = 16.667 1/s).
//!   A rate has no length in it: the same number on a rotary axis.
//! - speed feed-forward: Kvff is the factor MD32610 (0 to 1), MD32620 = 1 (speed
//!   feed-forward with PT1 balancing, rtid's symmetrising lag a first-order lag),
//!   MD32810 its time constant in s; Kvff = 0 is MD32620 = 0.
//! - the gear: the load revolutions in MD31050, the motor revolutions in MD31060,
//!   whole numbers: 1/ratio as a fraction, or as given.

use super::{render, DriveFormError, ServoSettings, Setting};
use crate::model::Axis;

/// The parameter sets SINUMERIK holds per axis (MD32200 `POSCTRL_GAIN[0..5]`).
pub const PARAMETER_SETS: usize = 6;

/// The largest motor or load revolution count taken from the model's ratio: gears'
/// tooth counts multiply to far less, and with larger ones any real number would pass
/// as a fraction (its continued fraction's convergents come within 1e-12 once their
/// denominators pass about 1e6).
pub const MAX_REVOLUTIONS: u64 = 100_000;

/// What rtid does not know of a SINUMERIK axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SinumerikContext {
    /// The machine axis number n (machine data for `AXn`); required
    /// (`--axis-number`).
    pub axis_number: Option<u32>,
    /// The parameter set (0 to 5) the gains are written into.
    pub parameter_set: usize,
    /// The gear as the CNC counts it, motor revolutions to load revolutions
    /// (`--gear-ratio MOTOR:LOAD`); `None`: from the model's ratio, when it is a
    /// fraction of whole numbers up to [`MAX_REVOLUTIONS`].
    pub gear: Option<(u64, u64)>,
}

/// The fraction p/q = x (p, q ≤ `max`), exact to 1e-12 relative, by continued
/// fractions; `None` when none is.
pub fn fraction(x: f64, max: u64) -> Option<(u64, u64)> {
    if !(x.is_finite() && x > 0.0) {
        return None;
    }
    // Convergents h/k of x's continued fraction.
    let (mut h0, mut h1) = (0u64, 1u64);
    let (mut k0, mut k1) = (1u64, 0u64);
    let mut r = x;
    for _ in 0..64 {
        let a = r.floor();
        if a > max as f64 {
            return None;
        }
        let a = a as u64;
        let h = a.checked_mul(h1)?.checked_add(h0)?;
        let k = a.checked_mul(k1)?.checked_add(k0)?;
        if h > max || k > max {
            return None;
        }
        if ((h as f64 / k as f64) - x).abs() <= 1e-12 * x {
            return Some((h, k));
        }
        (h0, h1, k0, k1) = (h1, h, k1, k);
        let frac = r - a as f64;
        if frac <= 0.0 {
            return None;
        }
        r = 1.0 / frac;
    }
    None
}

/// The machine data's name for error messages.
const FORM: &str = "SINUMERIK machine data";

/// The machine data's lines, in order: the servo gain, the gear (rotary axes), the
/// feed-forward.
pub fn settings(s: &ServoSettings, ctx: &SinumerikContext) -> Result<Vec<Setting>, DriveFormError> {
    let (ax, p) = check(s, ctx)?;
    let mut out = vec![Setting::real(
        format!("$MA_POSCTRL_GAIN[{p},{ax}]"),
        s.kpp * 60.0 / 1000.0,
        "1000/min",
        format!(
            "MD32200 servo gain factor Kv = Kpp = {} 1/s (the ratio cancels between error and speed), ·60/1000; = (m/min)/mm",
            super::number(s.kpp)
        ),
    )];
    if s.axis == Axis::Rotary {
        out.extend(gear(s, ctx, &ax, p)?);
    }
    out.extend(feed_forward(s, &ax, p));
    Ok(out)
}

/// The settings and the context checked against what the machine data can hold: the
/// axis name (`AXn`) and the parameter set.
fn check(s: &ServoSettings, ctx: &SinumerikContext) -> Result<(String, usize), DriveFormError> {
    s.check()?;
    let Some(n) = ctx.axis_number else {
        return Err(DriveFormError::Missing {
            form: FORM,
            what: "the machine axis number (the data are written for AXn)",
            option: "--axis-number",
        });
    };
    let p = ctx.parameter_set;
    if p >= PARAMETER_SETS {
        return Err(DriveFormError::OutOfRange {
            field: "parameter set".into(),
            value: p as f64,
            what: "0 to 5",
        });
    }
    if s.kpp <= 0.0 {
        return Err(DriveFormError::OutOfRange {
            field: "Kpp".into(),
            value: s.kpp,
            what: "positive (MD32200 = 0 opens SINUMERIK's position loop)",
        });
    }
    if s.kpi > 0.0 {
        return Err(DriveFormError::NoCounterpart {
            form: FORM,
            field: "Kpi",
            value: s.kpi,
            why: "SINUMERIK's position controller is proportional (MD32200); no position integral gain was found",
        });
    }
    if s.kvff > 1.0 {
        return Err(DriveFormError::OutOfRange {
            field: "Kvff".into(),
            value: s.kvff,
            what: "0 to 1 (MD32610's range)",
        });
    }
    Ok((format!("AX{n}"), p))
}

/// The gear's motor and load revolutions (MD31060, MD31050): `--gear-ratio` checked
/// against the model's ratio, or that ratio as a fraction of whole revolutions.
fn gear(
    s: &ServoSettings,
    ctx: &SinumerikContext,
    ax: &str,
    p: usize,
) -> Result<[Setting; 2], DriveFormError> {
    let (motor, load, from) = match ctx.gear {
        Some((motor, load)) => {
            if motor == 0 || load == 0 {
                return Err(DriveFormError::OutOfRange {
                    field: "--gear-ratio".into(),
                    value: (if motor == 0 { motor } else { load }) as f64,
                    what: "whole numbers of revolutions ≥ 1",
                });
            }
            let given = load as f64 / motor as f64;
            if (given - s.ratio).abs() > 1e-9 * s.ratio.abs() {
                return Err(DriveFormError::Disagrees {
                    option: "--gear-ratio",
                    given: format!("{motor}:{load} (table turns per motor turn {given})"),
                    model: format!("ratio Rg·Rw = {}", s.ratio),
                });
            }
            (motor, load, "as given (--gear-ratio)")
        }
        None => match fraction(1.0 / s.ratio, MAX_REVOLUTIONS) {
            Some((motor, load)) => (motor, load, "1/(Rg·Rw) of the model"),
            None => {
                return Err(DriveFormError::Missing {
                    form: FORM,
                    what: "the gear as whole motor and load revolutions (MD31060/MD31050), the model's ratio Rg·Rw being no fraction of them",
                    option: "--gear-ratio MOTOR:LOAD",
                })
            }
        },
    };
    Ok([
        Setting::integer(
            format!("$MA_DRIVE_AX_RATIO_DENOM[{p},{ax}]"),
            load as i64,
            "",
            format!("MD31050 load revolutions, {from}; with MD31060 the Kv is set at the table"),
        ),
        Setting::integer(
            format!("$MA_DRIVE_AX_RATIO_NUMERA[{p},{ax}]"),
            motor as i64,
            "",
            format!(
                "MD31060 motor revolutions: {motor} per {load} table turns = 1/(Rg·Rw), Rg·Rw = {}",
                s.ratio
            ),
        ),
    ])
}

/// The feed-forward's mode (MD32620), where it is on its weight (MD32610), and the
/// speed loop's equivalent time (MD32810): the tuned closed speed loop's where rtid
/// computed it ([`ServoSettings::equivalent_time_s`]; written with the feed-forward
/// off too, ready for it), else the symmetrising lag's (with the feed-forward on).
fn feed_forward(s: &ServoSettings, ax: &str, p: usize) -> Vec<Setting> {
    let mut out = Vec::new();
    if s.kvff <= 0.0 {
        out.push(Setting::integer(
            format!("$MA_FFW_MODE[{ax}]"),
            0,
            "",
            "MD32620 feed-forward mode 0: none (Kvff = 0)".into(),
        ));
    } else {
        out.push(Setting::integer(
            format!("$MA_FFW_MODE[{ax}]"),
            1,
            "",
            "MD32620 feed-forward mode 1: speed feed-forward with PT1 balancing (rtid's symmetrising lag is first order)".into(),
        ));
        out.push(Setting::real(
            format!("$MA_VELO_FFW_WEIGHT[{p},{ax}]"),
            s.kvff,
            "",
            format!(
                "MD32610 speed feed-forward factor = Kvff = {}",
                super::number(s.kvff)
            ),
        ));
    }
    let name = format!("$MA_EQUIV_SPEEDCTRL_TIME[{p},{ax}]");
    match (s.equivalent_time_s, s.speed_bandwidth_hz) {
        (Some(t), Some(f)) => out.push(Setting::real(
            name,
            t,
            "s",
            format!(
                "MD32810 equivalent time constant of the closed speed loop = 1/(2π·f) with f = {} Hz its -3 dB bandwidth (the tuned loop, exact on the sampled loop){}",
                super::number(f),
                if s.kvff > 0.0 {
                    "; rtid's symmetrising lag runs with it"
                } else {
                    "; for when the speed feed-forward is switched on"
                }
            ),
        )),
        _ if s.kvff > 0.0 => out.push(Setting::real(
            name,
            s.symmetrising_s,
            "s",
            format!(
                "MD32810 equivalent time constant of the speed loop for the feed-forward = symmetrising_s = {} s",
                super::number(s.symmetrising_s)
            ),
        )),
        _ => {}
    }
    out
}

/// The machine data as `;`-commented lines `$MA_…[…,AXn]=value`.
pub fn program(s: &ServoSettings, ctx: &SinumerikContext) -> Result<String, DriveFormError> {
    let lines = settings(s, ctx)?;
    let mut header = vec![
        format!(
            "SINUMERIK axis machine data from rtid's settings, parameter set {}; active after NEWCONF (MD32200)",
            ctx.parameter_set
        ),
        "conversions and sources: docs/drive-settings.md; the speed controller and filters are the drive's: see the SINAMICS list".into(),
        "NOT VERIFIED against a manual: the index forms [set,AXn] and [AXn] of MD31050/31060/32610/32620/32810, MD32610's unit (a factor 0-1 here)".into(),
    ];
    if s.position_period_s > 0.0 {
        header.push(format!(
            "the position controller's cycle rtid modelled: {} s ({} control periods of {} s); SINUMERIK's position-control cycle (MD10050 SYSCLOCK_CYCLE_TIME × MD10060 POSCTRL_SYSCLOCK_TIME_RATIO as read) is NOT VERIFIED and not written",
            super::number(s.position_period_s),
            (s.position_period_s / s.tc).round(),
            super::number(s.tc)
        ));
    }
    if s.kaff > 0.0 {
        header.push(format!(
            "not written: torque feed-forward Kaff = {} (inertia at the motor Kaff·drive_gain = {} {}); MD32620 = 2/4 and MD32650 AX_INERTIA were not verified: set them by hand",
            super::number(s.kaff),
            super::number(s.kaff * s.drive_gain),
            if s.axis == Axis::Linear { "kg" } else { "kg·m²" }
        ));
    }
    Ok(render(&header, &lines))
}

#[cfg(test)]
mod tests {
    use super::super::tests::tuned;
    use super::*;

    fn ctx() -> SinumerikContext {
        SinumerikContext {
            axis_number: Some(4),
            ..Default::default()
        }
    }

    fn value(lines: &[Setting], name: &str) -> f64 {
        lines
            .iter()
            .find(|l| l.name == name)
            .unwrap_or_else(|| panic!("{name} not written"))
            .number()
    }

    #[test]
    fn kv_is_kpp_in_thousand_per_minute_on_both_axes() {
        let mut s = tuned();
        s.kpp = 1000.0 / 60.0;
        let lines = settings(&s, &ctx()).unwrap();
        assert!((value(&lines, "$MA_POSCTRL_GAIN[0,AX4]") - 1.0).abs() < 1e-15);
        s.kpp = 187.5;
        let lines = settings(&s, &ctx()).unwrap();
        assert!((value(&lines, "$MA_POSCTRL_GAIN[0,AX4]") - 11.25).abs() < 1e-12);
        // A linear axis: the same number, no gear.
        s.axis = Axis::Linear;
        s.ratio = 1.0;
        let lines = settings(&s, &ctx()).unwrap();
        assert!((value(&lines, "$MA_POSCTRL_GAIN[0,AX4]") - 11.25).abs() < 1e-12);
        assert!(!lines.iter().any(|l| l.name.contains("RATIO")));
        // The ratio does not enter Kv.
        s.axis = Axis::Rotary;
        s.ratio = 1.0 / 140.0;
        let c = SinumerikContext {
            parameter_set: 2,
            ..ctx()
        };
        let lines = settings(&s, &c).unwrap();
        assert!((value(&lines, "$MA_POSCTRL_GAIN[2,AX4]") - 11.25).abs() < 1e-12);
        assert_eq!(value(&lines, "$MA_DRIVE_AX_RATIO_NUMERA[2,AX4]"), 140.0);
        assert_eq!(value(&lines, "$MA_DRIVE_AX_RATIO_DENOM[2,AX4]"), 1.0);
    }

    #[test]
    fn the_gear_is_the_models_ratio_as_whole_revolutions() {
        let s = tuned(); // 0.8·(1/72) = 1/90
        let lines = settings(&s, &ctx()).unwrap();
        assert_eq!(value(&lines, "$MA_DRIVE_AX_RATIO_NUMERA[0,AX4]"), 90.0);
        assert_eq!(value(&lines, "$MA_DRIVE_AX_RATIO_DENOM[0,AX4]"), 1.0);
        assert_eq!(fraction(72.0 / 0.8, MAX_REVOLUTIONS), Some((90, 1)));
        assert_eq!(
            fraction(1.0 / (3.0 / 7.0 * 1.0 / 24.0), MAX_REVOLUTIONS),
            Some((56, 1))
        );
        assert_eq!(fraction(2.5, MAX_REVOLUTIONS), Some((5, 2)));
        assert_eq!(fraction(std::f64::consts::PI, 1000), None);
        assert_eq!(fraction(std::f64::consts::PI, MAX_REVOLUTIONS), None);
    }

    #[test]
    fn what_rtid_does_not_know_is_asked_for_by_its_option() {
        let s = tuned();
        let none = SinumerikContext::default();
        match settings(&s, &none) {
            Err(DriveFormError::Missing { option, .. }) => assert_eq!(option, "--axis-number"),
            other => panic!("{other:?}"),
        }
        let mut odd = tuned();
        odd.ratio = 1.0 / std::f64::consts::PI;
        let e = settings(&odd, &ctx()).unwrap_err();
        match &e {
            DriveFormError::Missing { option, .. } => {
                assert_eq!(*option, "--gear-ratio MOTOR:LOAD")
            }
            other => panic!("{other:?}"),
        }
        assert!(e.to_string().contains("give it with --gear-ratio"), "{e}");
        // Given, it must agree with the model.
        let given = SinumerikContext {
            gear: Some((22, 7)),
            ..ctx()
        };
        assert!(matches!(
            settings(&odd, &given),
            Err(DriveFormError::Disagrees { .. })
        ));
        let given = SinumerikContext {
            gear: Some((180, 2)),
            ..ctx()
        };
        let lines = settings(&s, &given).unwrap();
        assert_eq!(value(&lines, "$MA_DRIVE_AX_RATIO_NUMERA[0,AX4]"), 180.0);
    }

    #[test]
    fn the_feed_forward_is_speed_feed_forward_with_its_lag() {
        let s = tuned();
        let lines = settings(&s, &ctx()).unwrap();
        assert_eq!(value(&lines, "$MA_FFW_MODE[AX4]"), 1.0);
        assert_eq!(value(&lines, "$MA_VELO_FFW_WEIGHT[0,AX4]"), 1.0);
        assert_eq!(value(&lines, "$MA_EQUIV_SPEEDCTRL_TIME[0,AX4]"), 0.002);
        let mut off = tuned();
        off.kvff = 0.0;
        let lines = settings(&off, &ctx()).unwrap();
        assert_eq!(value(&lines, "$MA_FFW_MODE[AX4]"), 0.0);
        assert!(!lines.iter().any(|l| l.name.contains("VELO_FFW")));
        let mut over = tuned();
        over.kvff = 1.2;
        assert!(matches!(
            settings(&over, &ctx()),
            Err(DriveFormError::OutOfRange { .. })
        ));
        let mut pi = tuned();
        pi.kpi = 10.0;
        assert!(matches!(
            settings(&pi, &ctx()),
            Err(DriveFormError::NoCounterpart { field: "Kpi", .. })
        ));
        let mut torque = tuned();
        torque.kaff = 1.68e-3;
        let text = program(&torque, &ctx()).unwrap();
        assert!(text.contains("not written: torque feed-forward"), "{text}");
        assert!(text.contains("$MA_POSCTRL_GAIN[0,AX4]=11.25 ; [1000/min] MD32200"));
    }
}
