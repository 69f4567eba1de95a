//! What a measured frequency-response experiment says, as the model is compared with
//! it: the lines that are measurements of the drive (inside its band, above the
//! encoder's resolution), the gain as the drive's ratio, its complex response with
//! each line's noise, the frequencies it was measured at, and the conditions of the
//! test the model must reproduce. Read by the objectives, the identification's checks
//! and the modal fit alike.

use super::FrequencyTest;
use crate::io::experiment_file::{Data, Delay, Experiment, Kind, Response, ResponseForm};

/// A local maximum of a measured gain curve counts as a resonance when it stands
/// this far above the lowest point between it and any higher point (or the curve's
/// end) on each side — its topographic prominence ([`crate::estimation::peaks::prominent`]).
/// Measurement noise makes many small maxima; a friction-damped worm resonance may
/// stand only ~1.6 dB out.
pub const PROMINENCE_DB: f64 = 1.0;

/// The nonlinear frequency-response test at an experiment's conditions.
pub fn frequency_test(exp: &Experiment) -> FrequencyTest {
    let c = &exp.manifest.conditions;
    let d = FrequencyTest::default();
    FrequencyTest {
        amplitude_nm: c.torque_amplitude_nm.unwrap_or(d.amplitude_nm),
        preload_nm: c.preload_nm.unwrap_or(d.preload_nm),
        ..d
    }
}

/// The band of an experiment's resonances (`conditions.band_hz`), Hz.
pub fn band(exp: &Experiment) -> Option<(f64, f64)> {
    exp.manifest.conditions.band_hz.map(|[lo, hi]| (lo, hi))
}

/// Whether `hz` lies in the experiment's band (always, without one).
pub fn in_band(exp: &Experiment, hz: f64) -> bool {
    band(exp).map_or(true, |(lo, hi)| lo <= hz && hz <= hi)
}

/// The (frequency, gain) points of a gain curve that are measurements of the drive,
/// inside its band when it has one: points flagged `below_resolution` (the table did
/// not move more than the encoder resolves) are left out. The gain is the drive's
/// ratio: a file referred to the ratio's other channel ([`ResponseForm::inverted`]) is
/// inverted. Empty for other kinds.
pub fn valid_points(exp: &Experiment) -> impl Iterator<Item = (f64, f64)> + '_ {
    let sign = if form(exp).inverted { -1.0 } else { 1.0 };
    let (f, g) = match &exp.data {
        Data::FrequencyResponse {
            frequency_hz,
            gain_db,
            ..
        } => (frequency_hz.as_slice(), gain_db.as_slice()),
        _ => (&[][..], &[][..]),
    };
    valid_lines(exp).map(move |i| (f[i], sign * g[i]))
}

/// The indices of the valid lines of a frequency response ([`valid_points`]).
fn valid_lines(exp: &Experiment) -> impl Iterator<Item = usize> + '_ {
    let (f, flags) = match &exp.data {
        Data::FrequencyResponse {
            frequency_hz,
            extra,
            ..
        } => (frequency_hz.as_slice(), extra.get("below_resolution")),
        _ => (&[][..], None),
    };
    (0..f.len())
        .filter(move |&i| flags.map_or(true, |c| c.get(i).map_or(true, |&v| v < 0.5)))
        .filter(move |&i| in_band(exp, f[i]))
}

/// How an experiment's complex ratio relates to the drive's (table over motor by
/// default).
pub fn form(exp: &Experiment) -> ResponseForm {
    ResponseForm::of(&exp.manifest.conditions)
}

/// dB per neper: 20/ln 10.
pub const DB_PER_NEPER: f64 = 8.685_889_638_065_036;

/// A measured complex frequency response as the drive's ratio: per valid line the
/// natural log of the gain and the phase (rad, as the file has it: wrapped or not;
/// the file's delay, when given, taken out), and each line's noise where the file
/// states it (σ of ln|H| and of the phase in rad; `None`: not stated).
#[derive(Clone, Debug, PartialEq)]
pub struct ComplexPoints {
    pub frequency_hz: Vec<f64>,
    pub ln_gain: Vec<f64>,
    pub phase_rad: Vec<f64>,
    pub sigma_ln: Option<Vec<f64>>,
    pub sigma_phase: Option<Vec<f64>>,
}

/// The RMS of the gain errors (dB) and of the phase errors (deg) of complex residuals
/// `r` (gain block, then phase block) with their σs.
pub fn rms_errors(r: &[f64], sigma_ln: &[f64], sigma_phase: &[f64]) -> (f64, f64) {
    let n = sigma_ln.len();
    let rms = |part: &[f64], s: &[f64], unit: f64| {
        (part
            .iter()
            .zip(s)
            .map(|(x, s)| (x * s * unit).powi(2))
            .sum::<f64>()
            / n.max(1) as f64)
            .sqrt()
    };
    (
        rms(&r[..n], sigma_ln, DB_PER_NEPER),
        rms(&r[n..], sigma_phase, 1f64.to_degrees()),
    )
}

/// The complex response of a frequency-response file with phase, on the lines where
/// `keep` holds; `None` without a phase. Noise per line: `gain_sigma_db` (and
/// `phase_sigma_deg`, else the same relative σ), or `coherence` (γ²) with
/// `conditions.averages` n: σ = √(1 − γ²)/(|γ|·√(2n)) for both (Bendat & Piersol,
/// *Random Data*, 4th ed., eq. 9.90 and 9.91).
pub fn complex_points(exp: &Experiment, keep: impl Fn(f64) -> bool) -> Option<ComplexPoints> {
    let Data::FrequencyResponse {
        frequency_hz,
        gain_db,
        phase_rad: Some(phase),
        extra,
    } = &exp.data
    else {
        return None;
    };
    let form = form(exp);
    let sign = if form.inverted { -1.0 } else { 1.0 };
    let delay = match form.delay {
        Delay::Given(d) => d,
        Delay::Unknown => 0.0,
    };
    let lines: Vec<usize> = valid_lines(exp)
        .filter(|&i| keep(frequency_hz[i]))
        .collect();
    let pick = |c: &[f64], scale: f64| lines.iter().map(|&i| scale * c[i]).collect::<Vec<f64>>();
    let coherence_sigma = || {
        let n = f64::from(exp.manifest.conditions.averages?);
        let c = extra.get("coherence")?;
        Some(
            lines
                .iter()
                .map(|&i| {
                    let g2 = c[i].clamp(1e-12, 1.0);
                    ((1.0 - g2) / g2 / (2.0 * n)).sqrt()
                })
                .collect::<Vec<f64>>(),
        )
    };
    let sigma_ln = extra
        .get("gain_sigma_db")
        .map(|c| pick(c, 1.0 / DB_PER_NEPER))
        .or_else(coherence_sigma);
    let sigma_phase = extra
        .get("phase_sigma_deg")
        .map(|c| pick(c, 1f64.to_radians()))
        .or_else(|| sigma_ln.clone());
    Some(ComplexPoints {
        ln_gain: pick(gain_db, sign / DB_PER_NEPER),
        phase_rad: lines
            .iter()
            .map(|&i| sign * (phase[i] + std::f64::consts::TAU * frequency_hz[i] * delay))
            .collect(),
        frequency_hz: pick(frequency_hz, 1.0),
        sigma_ln,
        sigma_phase,
    })
}

/// The frequencies of a measured gain curve (ascending), on which the nonlinear
/// model's peaks are located like for like; `None` for other kinds.
pub fn grid(exp: &Experiment) -> Option<Vec<f64>> {
    if exp.manifest.kind != Kind::FrequencyResponse
        || form(exp).response != Response::TableOverMotor
    {
        return None;
    }
    let mut f: Vec<f64> = valid_points(exp).map(|(f, _)| f).collect();
    f.sort_by(f64::total_cmp);
    Some(f)
}

/// Whether a frequency response is fitted by its whole curve by default rather than
/// by its resonances: where it has phase (the complex curve says which damping belongs
/// to which mesh; the peaks alone fix the stiffnesses only roughly when the damping is
/// unknown), or where it is not table over motor (a compliance's peaks are not the
/// motor-held modes the resonance objectives compare). A gain-only table over motor
/// feeds its resonances; `--objective gain-curve` fits its whole curve.
pub fn fits_whole_curve(exp: &Experiment) -> bool {
    exp.manifest.kind == Kind::FrequencyResponse
        && (has_phase(exp) || form(exp).response != Response::TableOverMotor)
}

/// Whether a frequency response is of the mechanics (table over motor, the motor's
/// compliance), which the gain-curve objectives compare, rather than a drive's closed
/// speed loop (`objectives::speed_loop`).
pub fn of_the_mechanics(exp: &Experiment) -> bool {
    form(exp).response != Response::SpeedLoop
}

/// Whether a frequency-response file has a phase column.
pub fn has_phase(exp: &Experiment) -> bool {
    matches!(
        exp.data,
        Data::FrequencyResponse {
            phase_rad: Some(_),
            ..
        }
    )
}
