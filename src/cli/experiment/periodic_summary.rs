//! The printed evaluation of a multisine record.

use std::fmt::Write as _;
use std::path::Path;

use rtid::estimation::periodic::nonlinear_distortion::DistortionBand;
use rtid::experiments::frequency_response::periodic_evaluation::{
    Channel, Input, Mode, PeriodicEvaluation,
};

/// The summary: framing, each channel's modes, the two-mass ratios, the distortion.
pub fn summary(p: &PeriodicEvaluation, source: &Path) -> String {
    let mut s = format!(
        "{}: periodic multisine, every period transformed whole (no window, no leakage)\n",
        source.display()
    );
    let said = |detected: bool| if detected { "detected" } else { "given" };
    let _ = writeln!(
        s,
        "period {:.4} s ({}) at {:.1} Hz; {} periods, {} used; {} excited lines {:.2}–{:.2} Hz ({})",
        p.period_s,
        said(p.period_detected),
        p.sample_rate_hz,
        p.periods_in_record,
        p.periods_used,
        p.excited_lines,
        p.first_line_hz,
        p.last_line_hz,
        said(p.lines_detected)
    );
    if p.input == Input::Current {
        let _ = writeln!(
            s,
            "input: motor current without a torque constant — the motor channel is per ampere, and what it determines are frequencies, damping ratios and the ratios below"
        );
    }
    for c in [&p.table, &p.motor] {
        channel(c, &mut s);
    }
    match &p.two_mass {
        Some(r) => {
            let _ = writeln!(
                s,
                "two-mass ratios (motor channel: antiresonance √(k/Jl), resonance √(k/Jm + k/Jl)): Jl/Jm = {:.3}, k/Jl = {:.4e} rad²/s², k/Jm = {:.4e} rad²/s²{}",
                r.inertia_ratio,
                r.k_over_jl,
                r.k_over_jm,
                if p.input == Input::Current {
                    " (Jm, Jl and k themselves need the torque constant)"
                } else {
                    ""
                }
            );
        }
        None => {
            let _ = writeln!(
                s,
                "two-mass ratios: not formed (they need exactly one resonance above one antiresonance on the motor channel)"
            );
        }
    }
    distortion(&p.motor, &mut s);
    s.trim_end().to_string()
}

/// One channel: its modes and its lowest coherence.
fn channel(c: &Channel, s: &mut String) {
    let _ = writeln!(
        s,
        "{} ({}), coherence γ² ≥ {:.3}:",
        c.name, c.unit, c.min_coherence
    );
    for (what, modes) in [
        ("resonances", &c.resonances),
        ("antiresonances", &c.antiresonances),
    ] {
        if modes.is_empty() {
            let _ = writeln!(s, "  {what:<15} none above the noise");
        }
        for (k, m) in modes.iter().enumerate() {
            let head = if k == 0 { what } else { "" };
            let _ = writeln!(s, "  {head:<15} {}", mode(m));
        }
    }
}

fn mode(m: &Mode) -> String {
    let located = match (m.frequency_se_hz, m.damping_ratio) {
        (Some(se), Some(z)) => format!("{:8.2} ± {se:.2} Hz  ζ {z:.3}", m.frequency_hz),
        _ => format!(
            "{:8.2} Hz (extremum; the fit did not place it)",
            m.frequency_hz
        ),
    };
    format!(
        "{located}   extremum {:.2} Hz, {:.2} dB, standing {:.1} dB out ({:.1} dB needed above the noise)",
        m.extremum_hz, m.gain_db, m.prominence_db, m.threshold_db
    )
}

/// The motor output's distortion levels per band, relative to the signal.
fn distortion(c: &Channel, s: &mut String) {
    let measured = c.distortion.iter().any(|b| b.odd.lines + b.even.lines > 0);
    if !measured {
        let _ = writeln!(
            s,
            "nonlinear distortion: not measured — every line of the band is excited (an odd or random-odd multisine leaves lines out to see it)"
        );
        return;
    }
    let _ = writeln!(
        s,
        "nonlinear distortion at the motor angle (non-excited lines, dB re the excited lines' level):"
    );
    for b in &c.distortion {
        let _ = writeln!(
            s,
            "  {:7.1}–{:<7.1} Hz  odd {}  even {}",
            b.from_hz,
            b.to_hz,
            class(b, &b.odd),
            class(b, &b.even)
        );
    }
}

fn class(
    b: &DistortionBand,
    c: &rtid::estimation::periodic::nonlinear_distortion::LineClass,
) -> String {
    match (c.level_db, b.signal_db) {
        (Some(level), Some(signal)) if c.lines > 0 => format!(
            "{:+6.1} dB{}",
            level - signal,
            if c.detected {
                " (above the noise)"
            } else {
                " (noise)         "
            }
        ),
        _ => "   —                     ".into(),
    }
}
