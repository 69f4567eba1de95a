//! The speed controller and the current setpoint filters as a SINAMICS (S120, servo
//! control) parameter list: p1460 the P gain, p1462 the integral time, p1656 the
//! filters' activation, p1657–p1676 filters 1–4 (type, denominator and numerator
//! natural frequency and damping), each indexed by the drive data set.
//!
//! **Conversions** (docs/drive-settings.md gives the sources):
//!
//! - p1460 = Kvp·drive_gain, N·m·s/rad: torque per motor speed error (N·s/m linear).
//! - p1462 = Tn = Kvp/Kvi in ms: rtid's Kvp·e + Kvi·∫e = Kvp·(e + ∫e/Tn). Kvi = 0 (a P
//!   velocity loop) is written as 0.
//! - a low-pass 1/(s²/ω² + 2D·s/ω + 1) is the PT2 type: denominator f, D.
//! - a notch (s²/ω² + 2D·g·s/ω + 1)/(s²/ω² + 2D·s/ω + 1), D = width/(2·centre),
//!   g = 10^(depth/20), is the general second-order filter (s²/ωz² + 2Dz·s/ωz +
//!   1)/(s²/ωn² + 2Dn·s/ωn + 1) with fz = fn = centre, Dn = width/(2·centre),
//!   Dz = Dn·g (0 for a full notch): the SINAMICS S120 Function Manual's conversion
//!   of a band-stop to the general filter, term for term.
//!
//! The parameter numbers after p1460 and the filter types' codes are the SINAMICS
//! S120 List Manual's as read for the task, not found in a manual with the search
//! tool: the file says so in its header, and docs/drive-settings.md lists them.

use super::{render, DriveFormError, ServoSettings, Setting};
use crate::model::{Axis, FilterError, SetpointFilter};

/// What rtid does not know of a SINAMICS drive.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SinamicsContext {
    /// The drive object the list is for (a name or number, written in the header
    /// only); `None`: not named.
    pub drive_object: Option<String>,
    /// The drive data set (DDS), the parameters' index (0: the first).
    pub data_set: usize,
    /// The current controller's sampling time, s (p0115[0]), if given: each filter's
    /// frequencies are then checked against its Nyquist frequency 1/(2·T), as the
    /// drive would refuse them. rtid checks them against the control period Tc.
    pub current_controller_s: Option<f64>,
}

/// The general second-order filter's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SinamicsFilter {
    /// 1: PT2 low-pass (denominator only), 2: general second-order filter.
    pub kind: i64,
    pub denominator_hz: f64,
    pub denominator_damping: f64,
    /// The numerator's natural frequency and damping (general filter only).
    pub numerator: Option<(f64, f64)>,
}

/// The SINAMICS form of one of rtid's setpoint filters.
pub fn filter(f: &SetpointFilter) -> SinamicsFilter {
    match *f {
        SetpointFilter::LowPass {
            frequency_hz,
            damping,
        } => SinamicsFilter {
            kind: 1,
            denominator_hz: frequency_hz,
            denominator_damping: damping,
            numerator: None,
        },
        SetpointFilter::Notch {
            centre_hz,
            width_hz,
            depth_db,
        } => {
            let d = width_hz / (2.0 * centre_hz);
            let g = depth_db.map_or(0.0, |db| 10f64.powf(db / 20.0));
            SinamicsFilter {
                kind: 2,
                denominator_hz: centre_hz,
                denominator_damping: d,
                numerator: Some((centre_hz, d * g)),
            }
        }
    }
}

/// The parameter list's lines, in order.
pub fn settings(s: &ServoSettings, ctx: &SinamicsContext) -> Result<Vec<Setting>, DriveFormError> {
    check(s, ctx)?;
    let d = ctx.data_set;
    let mut out = speed_controller(s, d);
    let mask = (0..s.filters.len()).fold(0i64, |m, i| m | 1 << i);
    out.push(Setting::integer(
        format!("p1656[{d}]"),
        mask,
        "",
        format!(
            "current setpoint filters active, bit i-1 for filter i: {}",
            if s.filters.is_empty() {
                "none".to_string()
            } else {
                format!("filters 1-{}", s.filters.len())
            }
        ),
    ));
    for (i, f) in s.filters.iter().enumerate() {
        out.extend(filter_settings(i, f, d));
    }
    Ok(out)
}

/// Refuses a gain the integral time cannot be formed from and, with the current
/// controller's sampling time given, a filter at or above its Nyquist frequency.
fn check(s: &ServoSettings, ctx: &SinamicsContext) -> Result<(), DriveFormError> {
    s.check()?;
    if s.kvp <= 0.0 {
        return Err(DriveFormError::OutOfRange {
            field: "Kvp".into(),
            value: s.kvp,
            what: "positive (p1462 = Kvp/Kvi is the integral time)",
        });
    }
    if let Some(t) = ctx.current_controller_s {
        if !(t.is_finite() && t > 0.0) {
            return Err(DriveFormError::OutOfRange {
                field: "current controller sampling time".into(),
                value: t,
                what: "positive and finite",
            });
        }
        let nyquist = 0.5 / t;
        for (i, f) in s.filters.iter().enumerate() {
            let (field, value) = f.frequency();
            if value >= nyquist {
                return Err(DriveFormError::Filter(FilterError::AboveNyquist {
                    index: i + 1,
                    field,
                    value,
                    nyquist,
                }));
            }
        }
    }
    Ok(())
}

/// p1460 and p1462 of data set `d`.
fn speed_controller(s: &ServoSettings, d: usize) -> Vec<Setting> {
    let linear = s.axis == Axis::Linear;
    let (gain_unit, speed) = if linear {
        ("Ns/m", "m/s")
    } else {
        ("Nms/rad", "rad/s")
    };
    let mut out = Vec::new();
    let gain_from = if s.drive_gain == 1.0 {
        format!("Kvp = {} (torque command)", super::number(s.kvp))
    } else {
        format!(
            "Kvp·drive_gain = {}·{}",
            super::number(s.kvp),
            super::number(s.drive_gain)
        )
    };
    out.push(Setting::real(
        format!("p1460[{d}]"),
        s.torque_per_speed(),
        gain_unit,
        format!(
            "speed controller P gain: {gain_from}, {} per motor {speed} of speed error",
            if linear { "N" } else { "N·m" }
        ),
    ));
    let (tn_ms, tn_from) = if s.kvi > 0.0 {
        (
            1000.0 * s.kvp / s.kvi,
            format!(
                "speed controller integral time Tn = Kvp/Kvi = {}/{} s",
                super::number(s.kvp),
                super::number(s.kvi)
            ),
        )
    } else {
        (
            0.0,
            "speed controller integral time: Kvi = 0, a P speed controller (0 taken as no integral action: not verified)".into(),
        )
    };
    out.push(Setting::real(format!("p1462[{d}]"), tn_ms, "ms", tn_from));
    out
}

/// The parameters of filter `i` (from 0) of data set `d`: five, or three for a low-pass.
fn filter_settings(i: usize, f: &SetpointFilter, d: usize) -> Vec<Setting> {
    let mut out = Vec::new();
    let base = 1657 + 5 * i;
    let n = i + 1;
    let g = filter(f);
    let what = match *f {
        SetpointFilter::LowPass {
            frequency_hz,
            damping,
        } => format!(
            "rtid low-pass {} Hz, damping {}",
            super::number(frequency_hz),
            super::number(damping)
        ),
        SetpointFilter::Notch {
            centre_hz,
            width_hz,
            depth_db,
        } => format!(
            "rtid notch {} Hz, {} Hz wide, {}",
            super::number(centre_hz),
            super::number(width_hz),
            depth_db.map_or("full depth".to_string(), |db| format!(
                "depth {} dB",
                super::number(db)
            ))
        ),
    };
    out.push(Setting::integer(
        format!("p{base}[{d}]"),
        g.kind,
        "",
        format!(
            "filter {n} type: {} ({what})",
            if g.kind == 1 {
                "PT2 low-pass"
            } else {
                "general second-order filter"
            }
        ),
    ));
    out.push(Setting::real(
        format!("p{}[{d}]", base + 1),
        g.denominator_hz,
        "Hz",
        format!("filter {n} denominator natural frequency"),
    ));
    out.push(Setting::real(
        format!("p{}[{d}]", base + 2),
        g.denominator_damping,
        "",
        format!(
            "filter {n} denominator damping{}",
            if g.kind == 2 {
                " = width/(2·centre)"
            } else {
                ""
            }
        ),
    ));
    if let Some((fz, dz)) = g.numerator {
        out.push(Setting::real(
            format!("p{}[{d}]", base + 3),
            fz,
            "Hz",
            format!("filter {n} numerator natural frequency = centre"),
        ));
        out.push(Setting::real(
            format!("p{}[{d}]", base + 4),
            dz,
            "",
            format!(
                "filter {n} numerator damping = denominator damping·10^(depth/20) (0: full notch)"
            ),
        ));
    }
    out
}

/// The commented parameter list: a header saying what it holds and what was not
/// verified, then one parameter per line.
pub fn program(s: &ServoSettings, ctx: &SinamicsContext) -> Result<String, DriveFormError> {
    let lines = settings(s, ctx)?;
    let object = ctx
        .drive_object
        .as_deref()
        .map_or("(not named)".to_string(), str::to_string);
    let mut header = vec![
        format!(
            "SINAMICS servo control, drive object {object}, drive data set {}: speed controller and current setpoint filters from rtid's settings",
            ctx.data_set
        ),
        "conversions and sources: docs/drive-settings.md; each value is the continuous-time equivalent of rtid's (rtid discretises its filters by Tustin prewarped at their own frequency at Tc, the drive at its current controller clock)".into(),
        "NOT VERIFIED against a manual: the parameter numbers p1460/p1462/p1656-p1676, their units and the filter type codes (1 PT2, 2 general); the filter conversion itself is the S120 Function Manual's".into(),
    ];
    if s.kpp > 0.0 || s.kvff > 0.0 || s.kaff > 0.0 {
        header.push(format!(
            "not in this list: the position loop (Kpp = {} 1/s) and the feed-forward (Kvff = {}, Kaff = {}) are the CNC's: see the SINUMERIK machine data",
            super::number(s.kpp),
            super::number(s.kvff),
            super::number(s.kaff)
        ));
    }
    if let (Some(t), Some(f)) = (s.equivalent_time_s, s.speed_bandwidth_hz) {
        header.push(format!(
            "the closed speed loop's equivalent time constant: {} s = 1/(2π·{} Hz), its -3 dB bandwidth; written as SINUMERIK's MD32810. The drive's own speed pre-control symmetrizing (p1428/p1429 as read for the task) is NOT VERIFIED and not written",
            super::number(t),
            super::number(f)
        ));
    }
    if s.current_lag_s > 0.0 {
        header.push(format!(
            "rtid modelled the current loop as a first-order lag of {} s: the drive's own current controller, not set here",
            super::number(s.current_lag_s)
        ));
    }
    Ok(render(&header, &lines))
}

#[cfg(test)]
mod tests {
    use super::super::tests::tuned;
    use super::*;
    use crate::controller::Biquad;

    /// H(jω) of (s²/ωz² + 2Dz·s/ωz + 1)/(s²/ωn² + 2Dn·s/ωn + 1), (re, im).
    fn general(f: f64, fz: f64, dz: f64, fn_: f64, dn: f64) -> (f64, f64) {
        let (xz, xn) = (f / fz, f / fn_);
        let num = (1.0 - xz * xz, 2.0 * dz * xz);
        let den = (1.0 - xn * xn, 2.0 * dn * xn);
        let m = den.0 * den.0 + den.1 * den.1;
        (
            (num.0 * den.0 + num.1 * den.1) / m,
            (num.1 * den.0 - num.0 * den.1) / m,
        )
    }

    /// rtid's continuous notch, docs/model.md §6, written from its fields.
    fn notch(f: f64, centre: f64, width: f64, depth_db: Option<f64>) -> (f64, f64) {
        let d = width / (2.0 * centre);
        let g = depth_db.map_or(0.0, |db| 10f64.powf(db / 20.0));
        let x = f / centre;
        let num = (1.0 - x * x, 2.0 * d * g * x);
        let den = (1.0 - x * x, 2.0 * d * x);
        let m = den.0 * den.0 + den.1 * den.1;
        (
            (num.0 * den.0 + num.1 * den.1) / m,
            (num.1 * den.0 - num.0 * den.1) / m,
        )
    }

    fn value(lines: &[Setting], name: &str) -> f64 {
        lines
            .iter()
            .find(|l| l.name == name)
            .unwrap_or_else(|| panic!("{name} not written"))
            .number()
    }

    #[test]
    fn the_written_notch_has_rtids_frequency_response() {
        let s = tuned();
        let lines = settings(&s, &SinamicsContext::default()).unwrap();
        for (i, (centre, width, depth)) in [(192.0, 38.4, Some(-20.0)), (252.9, 50.6, None)]
            .into_iter()
            .enumerate()
        {
            let base = 1657 + 5 * i;
            assert_eq!(value(&lines, &format!("p{base}[0]")), 2.0);
            let fn_ = value(&lines, &format!("p{}[0]", base + 1));
            let dn = value(&lines, &format!("p{}[0]", base + 2));
            let fz = value(&lines, &format!("p{}[0]", base + 3));
            let dz = value(&lines, &format!("p{}[0]", base + 4));
            for f in [1.0, 50.0, 0.9 * centre, centre, 1.1 * centre, 700.0, 1900.0] {
                let (a, b) = (general(f, fz, dz, fn_, dn), notch(f, centre, width, depth));
                let err = ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt();
                assert!(err < 1e-12, "filter {}: {f} Hz: {a:?} vs {b:?}", i + 1);
            }
            // At its centre the controller's discrete notch (Tustin prewarped there)
            // has the written filter's gain exactly: the depth.
            let q = Biquad::new(&s.filters[i], s.tc).response(centre, s.tc);
            let gain = (q.0 * q.0 + q.1 * q.1).sqrt();
            let want = depth.map_or(0.0, |db: f64| 10f64.powf(db / 20.0));
            assert!((gain - want).abs() < 1e-9, "{gain} vs {want}");
        }
        // The low-pass: PT2, its frequency and damping.
        assert_eq!(value(&lines, "p1667[0]"), 1.0);
        assert_eq!(value(&lines, "p1668[0]"), 1200.0);
        assert_eq!(value(&lines, "p1669[0]"), 0.7);
        assert!(!lines.iter().any(|l| l.name == "p1670[0]"));
        assert_eq!(value(&lines, "p1656[0]"), 7.0);
    }

    #[test]
    fn the_integral_time_is_kvp_over_kvi_in_ms_and_the_gain_is_torque_per_speed() {
        let mut s = tuned();
        s.filters.clear();
        s.drive_gain = 2.5;
        let ctx = SinamicsContext {
            data_set: 1,
            ..Default::default()
        };
        let lines = settings(&s, &ctx).unwrap();
        assert!((value(&lines, "p1460[1]") - 1.332 * 2.5).abs() < 1e-15);
        assert!((value(&lines, "p1462[1]") - 1000.0 * 1.332 / 249.8).abs() < 1e-12);
        assert_eq!(value(&lines, "p1656[1]"), 0.0);
        s.kvi = 0.0;
        let lines = settings(&s, &ctx).unwrap();
        assert_eq!(value(&lines, "p1462[1]"), 0.0);
        let text = program(&s, &ctx).unwrap();
        assert!(text.contains("p1460[1]=3.33 ; [Nms/rad]"), "{text}");
        assert!(text.contains("NOT VERIFIED"));
    }

    #[test]
    fn a_filter_above_the_current_controllers_nyquist_is_refused() {
        let s = tuned();
        let ctx = SinamicsContext {
            current_controller_s: Some(500e-6),
            ..Default::default()
        };
        match settings(&s, &ctx) {
            Err(DriveFormError::Filter(FilterError::AboveNyquist { index, .. })) => {
                assert_eq!(index, 3)
            }
            other => panic!("{other:?}"),
        }
        let ctx = SinamicsContext {
            current_controller_s: Some(125e-6),
            ..Default::default()
        };
        settings(&s, &ctx).unwrap();
    }
}
