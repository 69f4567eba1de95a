//! A measurement as a [`Recording`]: each series, spectrum and the primary response
//! as a channel named by what it is, and what the file says about the test in notes.

use super::measurement::{Measurement, Signal, Spectrum};
use super::response::{self, MeasuredLoop};
use crate::io::formats::{Abscissa, Channel, Recording, Samples};

/// The channels and notes of `m`.
pub fn recording(m: &Measurement) -> Recording {
    let known = response::measured_loop(m).ok();
    let mut notes = describe(m, known);
    let mut channels = Vec::new();
    let unit = known.map_or("", |_| "rad/s");
    for s in &m.signals {
        let name = signal_name(m, s, known);
        let signs = series_signs(s);
        for (series, sign) in s.series.iter().zip(signs) {
            channels.push(Channel {
                name: format!("{name}, {sign}"),
                unit: unit.into(),
                abscissa: Abscissa::Uniform {
                    start: series.start_s,
                    step: m.sample_time_s,
                    unit: "s".into(),
                },
                samples: Samples::Real(series.values.clone()),
                first_line: None,
            });
        }
        if let Some(a) = &s.autospectrum {
            channels.push(spectrum(format!("autospectrum of {name}"), unit, a, false));
        }
        for c in &s.cross {
            let other = m
                .signals
                .iter()
                .find(|o| o.node == c.other)
                .map_or(format!("signal {}", c.other), |o| signal_name(m, o, known));
            channels.push(spectrum(
                format!("cross spectrum of {name} and {other}"),
                unit,
                c,
                true,
            ));
        }
    }
    match response::stored_response(m) {
        Ok(r) => channels.push(primary(m, known, &r)),
        Err(e) => notes.push(format!("no frequency response: {e}")),
    }
    Recording {
        format: super::DEFINITION.name,
        channels,
        notes,
        groups: Vec::new(),
    }
}

/// `speed setpoint` or `input (signal 62)`.
fn signal_name(m: &Measurement, s: &Signal, known: Option<MeasuredLoop>) -> String {
    let role = match m.primary {
        Some((i, _)) if i == s.instance => Some(0),
        Some((_, o)) if o == s.instance => Some(1),
        _ => None,
    };
    match (known, role) {
        (Some(l), Some(0)) => l.signals().0.into(),
        (Some(l), Some(_)) => l.signals().1.into(),
        (None, Some(0)) => format!("input (signal {})", s.node),
        (None, Some(_)) => format!("output (signal {})", s.node),
        _ => format!("signal {}", s.node),
    }
}

/// `positive` or `negative` per series, by the sign of its mean (the offset's
/// direction).
fn series_signs(s: &Signal) -> Vec<&'static str> {
    s.series
        .iter()
        .map(|v| {
            let mean = v.values.iter().sum::<f64>() / v.values.len().max(1) as f64;
            if mean < 0.0 {
                "negative"
            } else {
                "positive"
            }
        })
        .collect()
}

fn spectrum(name: String, unit: &str, s: &Spectrum, complex: bool) -> Channel {
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!("({unit})²")
    };
    Channel {
        name,
        unit,
        abscissa: Abscissa::Values {
            values: s.frequency_hz.clone(),
            unit: "Hz".into(),
        },
        samples: if complex {
            Samples::Complex {
                re: s.re.clone(),
                im: s.im.clone(),
            }
        } else {
            Samples::Real(s.re.clone())
        },
        first_line: None,
    }
}

/// The primary response as a complex channel at the DFT's lines.
fn primary(m: &Measurement, known: Option<MeasuredLoop>, r: &response::StoredResponse) -> Channel {
    let (input, output) = match response::primary_signals(m) {
        Ok((i, o)) => (signal_name(m, i, known), signal_name(m, o, known)),
        Err(_) => ("input".into(), "output".into()),
    };
    Channel {
        name: format!("{output} / {input}"),
        unit: "1".into(),
        abscissa: Abscissa::Values {
            values: r.frequency_hz.clone(),
            unit: "Hz".into(),
        },
        samples: Samples::Complex {
            re: r.h.iter().map(|h| h.re).collect(),
            im: r.h.iter().map(|h| h.im).collect(),
        },
        first_line: None,
    }
}

/// What the file says about the test, in notes.
fn describe(m: &Measurement, known: Option<MeasuredLoop>) -> Vec<String> {
    let mut notes = vec![format!(
        "{} (SAT library {}){}{}",
        m.root,
        m.version,
        m.platform
            .as_deref()
            .map_or(String::new(), |p| format!(", platform {p}")),
        m.timestamp
            .as_ref()
            .map_or(String::new(), |(d, t)| format!(", measured {d} {t}")),
    )];
    notes.push(match (known, response::measured_loop(m)) {
        (Some(l), _) => format!("measured: {}", l.describe()),
        (None, Err(e)) => format!("measured: {e}"),
        (None, Ok(_)) => String::new(),
    });
    notes.push(excitation(m));
    notes.extend(levels(m, known));
    notes.push(axis(m));
    if let (Ok(r), Ok((i, o))) = (response::stored_response(m), response::primary_signals(m)) {
        let name = format!(
            "{} / {}",
            signal_name(m, o, known),
            signal_name(m, i, known)
        );
        notes.push(frequencies(m, &r, &name));
    }
    notes.push(
        "no speed-controller settings (Kp, Tn, filters) in the file: a measurement saved \
         alone does not carry them"
            .into(),
    );
    notes.retain(|n| !n.is_empty());
    notes
}

fn excitation(m: &Measurement) -> String {
    let waveform = match (m.waveform, m.excitation.prbs_order) {
        (4, Some(o)) => format!(
            "a PRBS of order {o} (period {} samples)",
            (1u64 << o.min(63)) - 1
        ),
        (4, None) => "a PRBS".into(),
        (w, _) => format!("waveform type {w}"),
    };
    let c = m.conditions.first();
    format!(
        "excitation: {waveform} injected at point {}, sampled every {} µs{}",
        m.injection_point,
        m.sample_time_s * 1e6,
        c.map_or(String::new(), |c| format!(
            "; settling {} s, measurement {} s, {} averages set, bandwidth {} Hz",
            c.settling_time_s, c.measurement_time_s, c.averages, c.bandwidth_hz
        ))
    )
}

fn levels(m: &Measurement, known: Option<MeasuredLoop>) -> Vec<String> {
    let unit = known.map_or("", |_| " rad/s");
    let rpm = |v: f64| {
        known.map_or(String::new(), |_| {
            format!(" ({} rpm)", short(v * 60.0 / std::f64::consts::TAU))
        })
    };
    let directions = m.signals.first().map_or(0, |s| s.series.len());
    let mut out: Vec<String> = m
        .excitation
        .levels
        .iter()
        .map(|l| {
            format!(
                "role {}: offset {}{unit}{}, excitation ±{}{unit}{}",
                l.role,
                short(l.offset),
                rpm(l.offset),
                short(l.amplitude),
                rpm(l.amplitude)
            )
        })
        .collect();
    out.push(format!(
        "{directions} time series per signal: one per direction of the offset{}",
        if known.is_some() {
            "; values in rad/s of the motor (m_eSignalUnits 0: the setpoint series is the \
             offset ± the excitation stated above, in rad/s)"
        } else {
            ""
        }
    ));
    out
}

fn axis(m: &Measurement) -> String {
    let a = &m.excitation.axis;
    let kind = match (a.rotary, a.direct_drive, a.linear_motor) {
        (_, _, true) => "a linear motor",
        (true, true, _) => "a rotary direct drive",
        (true, false, _) => "a rotary axis driven through a gear",
        (false, _, _) => "a linear axis driven by a rotary motor",
    };
    let per = if a.rotary { "rad" } else { "m" };
    let lead = (!a.rotary && a.motor_to_axis_ratio > 0.0).then(|| {
        format!(
            " (a lead of {} mm per motor turn)",
            short(1e3 * std::f64::consts::TAU / a.motor_to_axis_ratio)
        )
    });
    format!(
        "axis: {kind}, {} rad of the motor per {per}{}, torque constant {} N·m/A",
        short(a.motor_to_axis_ratio),
        lead.unwrap_or_default(),
        short(a.torque_constant)
    )
}

fn frequencies(m: &Measurement, r: &response::StoredResponse, name: &str) -> String {
    let n = r.samples_per_period;
    let dft = 1.0 / (n as f64 * m.sample_time_s);
    let file = match (r.file_frequency_hz.first(), r.lines.first()) {
        (Some(f), Some(&k)) if k > 0 => f / k as f64,
        _ => dft,
    };
    format!(
        "the spectra are the DFT lines of one {n}-sample period, k·{} Hz (k/(N·Ts)); the \
         file's frequency vector steps {} Hz ({:+.3} %): the response `{name}` and rtid's \
         import place the lines at k/(N·Ts)",
        short(dft),
        short(file),
        100.0 * (file / dft - 1.0)
    )
}

/// `v` to four significant digits, as a listing shows a setting (0.4189, 628.3).
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = 3 - v.abs().log10().floor() as i32;
    format!("{:.*}", decimals.clamp(0, 12) as usize, v)
}
