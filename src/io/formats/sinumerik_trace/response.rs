//! What the measurement measured, as rtid reads the file's codes, and the primary
//! frequency response from the stored spectra.
//!
//! **The loop.** The file names its loop by codes the SAT library does not document.
//! The one file seen (module docs of [`super`]) has control loop type 2, injection
//! point 3 and `m_bClosedLoop` true, and its data say what that is: the input signal's
//! series is the offset plus or minus the excitation amplitude exactly (a speed
//! setpoint carrying the PRBS), the output's follows it smoothly, and their ratio is 1
//! (0 dB, 0°) at the lowest lines — the speed loop closed, setpoint → actual speed.
//! Other codes (the mechanics, torque → speed; the position loop) are refused by name
//! until a file of them has been seen.
//!
//! **The spectra.** Checked on the shared file against the DFT of its own time series
//! (to 1e-11 dB): each stored spectrum is the average over the directions of
//! (2/N)²·A·conj(B) at DFT line k of one N-sample period, where the spectrum stored in
//! signal b's list with the other signal a is A·conj(B). So the response output/input
//! is H = conj(S)/S_in for the spectrum stored with the output, S/S_in for one stored
//! with the input, and the coherence |S|²/(S_in·S_out).
//!
//! **The frequencies.** The lines are the DFT's, k/(N·Ts) — 3.9082 Hz apart for
//! N = 2047 at 125 µs — while the file's frequency vector steps its bandwidth over its
//! lines, 4000/1022 = 3.9139 Hz: 0.15 % high at every line. The spectra are those of
//! the DFT lines, so rtid places them at k/(N·Ts) and says so.

use nalgebra::Complex;

use super::measurement::{Measurement, Signal, Spectrum};

/// Why the file's response cannot be read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ResponseError {
    #[error("control loop type {loop_type}, injection point {injection_point}, {}: rtid reads the speed loop's reference response (type 2, injection point 3, closed loop), the one kind seen in a file so far; its channels are listed as they are", if *.closed_loop { "closed loop" } else { "open loop" })]
    UnknownLoop {
        loop_type: u32,
        injection_point: u32,
        closed_loop: bool,
    },
    #[error("the file names no primary response (m_listPrimaryFreqRespSigNodeData)")]
    NoPrimary,
    #[error("the primary response's {what} is signal instance {id}, which the file does not hold")]
    MissingSignal { what: &'static str, id: i64 },
    #[error("the series hold {len} samples where a PRBS of order {order} repeats every {period}")]
    SeriesLength {
        len: usize,
        order: u32,
        period: usize,
    },
    #[error("neither time series nor a PRBS order{} say the period's length", .order.map_or(String::new(), |o| format!(" (m_uPrbsOrder {o} is out of 2 … 24)")))]
    NoPeriod { order: Option<u32> },
    #[error("signal {0} has no autospectrum")]
    NoAutospectrum(u32),
    #[error("no cross spectrum of signals {output} and {input}")]
    NoCrossSpectrum { output: u32, input: u32 },
    #[error("the spectra have {input}, {output} and {cross} lines: they must be of one length")]
    SpectraLengths {
        input: usize,
        output: usize,
        cross: usize,
    },
    #[error("{lines} spectral lines from periods of {period} samples, which have {}", .period / 2 + 1)]
    TooManyLines { lines: usize, period: usize },
    #[error("signal {input} has {input_series} series and signal {output} {output_series}: one per direction each")]
    Directions {
        input: u32,
        input_series: usize,
        output: u32,
        output_series: usize,
    },
}

/// The loops rtid knows how to read from the codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeasuredLoop {
    /// The speed loop closed, its reference response: speed setpoint → actual speed.
    SpeedClosed,
}

impl MeasuredLoop {
    /// In words, for listings.
    pub fn describe(self) -> &'static str {
        match self {
            MeasuredLoop::SpeedClosed => {
                "the speed loop closed: speed setpoint → actual speed (its reference response)"
            }
        }
    }

    /// The input's and output's names.
    pub fn signals(self) -> (&'static str, &'static str) {
        match self {
            MeasuredLoop::SpeedClosed => ("speed setpoint", "actual speed"),
        }
    }
}

/// The loop of `m`, or why rtid does not read it.
pub fn measured_loop(m: &Measurement) -> Result<MeasuredLoop, ResponseError> {
    if m.loop_type == 2 && m.injection_point == 3 && m.excitation.closed_loop {
        return Ok(MeasuredLoop::SpeedClosed);
    }
    Err(ResponseError::UnknownLoop {
        loop_type: m.loop_type,
        injection_point: m.injection_point,
        closed_loop: m.excitation.closed_loop,
    })
}

/// The primary response from the stored spectra, at the DFT's lines 1 … L − 1.
#[derive(Clone, Debug, PartialEq)]
pub struct StoredResponse {
    /// The DFT line numbers k.
    pub lines: Vec<usize>,
    /// k/(N·Ts), Hz.
    pub frequency_hz: Vec<f64>,
    /// The file's own frequency vector at those lines, Hz.
    pub file_frequency_hz: Vec<f64>,
    /// Output over input.
    pub h: Vec<Complex<f64>>,
    /// |S|²/(S_in·S_out), 0 … 1.
    pub coherence: Vec<f64>,
    /// Spectra averaged per line (`m_uNumSpectraInAvg`).
    pub averaged: u32,
    /// Samples per period N.
    pub samples_per_period: usize,
}

/// The primary input and output signals of `m`.
pub fn primary_signals(m: &Measurement) -> Result<(&Signal, &Signal), ResponseError> {
    let (input, output) = m.primary.ok_or(ResponseError::NoPrimary)?;
    let find = |id: i64, what: &'static str| {
        m.signal(id)
            .ok_or(ResponseError::MissingSignal { what, id })
    };
    Ok((find(input, "input")?, find(output, "output")?))
}

/// Samples per period: the PRBS's 2^order − 1, which the series must be.
pub fn samples_per_period(m: &Measurement) -> Result<usize, ResponseError> {
    let from_series = m
        .signals
        .iter()
        .flat_map(|s| &s.series)
        .map(|s| s.values.len())
        .next();
    match (m.excitation.prbs_order, from_series) {
        (Some(order), series) if (2..=24).contains(&order) => {
            let period = (1usize << order) - 1;
            match series {
                Some(len) if len != period => {
                    Err(ResponseError::SeriesLength { len, order, period })
                }
                _ => Ok(period),
            }
        }
        (_, Some(len)) => Ok(len),
        (order, None) => Err(ResponseError::NoPeriod { order }),
    }
}

/// The response output/input of the primary signals from the stored spectra.
pub fn stored_response(m: &Measurement) -> Result<StoredResponse, ResponseError> {
    let (input, output) = primary_signals(m)?;
    let auto = |s: &'_ Signal| {
        s.autospectrum
            .clone()
            .ok_or(ResponseError::NoAutospectrum(s.node))
    };
    let (s_in, s_out) = (auto(input)?, auto(output)?);
    let (cross, conjugate) = match (
        output.cross.iter().find(|c| c.other == input.node),
        input.cross.iter().find(|c| c.other == output.node),
    ) {
        (Some(c), _) => (c, true),
        (None, Some(c)) => (c, false),
        (None, None) => {
            return Err(ResponseError::NoCrossSpectrum {
                output: output.node,
                input: input.node,
            })
        }
    };
    let lines = s_in.re.len();
    if s_out.re.len() != lines || cross.re.len() != lines {
        return Err(ResponseError::SpectraLengths {
            input: lines,
            output: s_out.re.len(),
            cross: cross.re.len(),
        });
    }
    let n = samples_per_period(m)?;
    if lines > n / 2 + 1 {
        return Err(ResponseError::TooManyLines { lines, period: n });
    }
    Ok(assemble(m, n, &s_in, &s_out, cross, conjugate))
}

fn assemble(
    m: &Measurement,
    n: usize,
    s_in: &Spectrum,
    s_out: &Spectrum,
    cross: &Spectrum,
    conjugate: bool,
) -> StoredResponse {
    let step = 1.0 / (n as f64 * m.sample_time_s);
    let mut r = StoredResponse {
        lines: Vec::new(),
        frequency_hz: Vec::new(),
        file_frequency_hz: Vec::new(),
        h: Vec::new(),
        coherence: Vec::new(),
        averaged: s_in.averaged,
        samples_per_period: n,
    };
    for k in 1..s_in.re.len() {
        let s = Complex::new(cross.re[k], cross.im[k]);
        let s = if conjugate { s.conj() } else { s };
        let (pin, pout) = (s_in.re[k], s_out.re[k]);
        if !(pin > 0.0 && pout > 0.0 && s.is_finite()) {
            continue;
        }
        r.lines.push(k);
        r.frequency_hz.push(k as f64 * step);
        r.file_frequency_hz.push(s_in.frequency_hz[k]);
        r.h.push(s / pin);
        r.coherence.push((s.norm_sqr() / (pin * pout)).min(1.0));
    }
    r
}

/// One direction's input and output series, and the sign of its offset (+1, −1).
#[derive(Clone, Debug, PartialEq)]
pub struct Direction<'a> {
    pub sign: f64,
    pub input: &'a [f64],
    pub output: &'a [f64],
}

/// The primary signals' series, direction by direction (the file's order; the sign
/// of each from the mean of its input).
pub fn directions(m: &Measurement) -> Result<Vec<Direction<'_>>, ResponseError> {
    let (input, output) = primary_signals(m)?;
    if input.series.len() != output.series.len() {
        return Err(ResponseError::Directions {
            input: input.node,
            input_series: input.series.len(),
            output: output.node,
            output_series: output.series.len(),
        });
    }
    Ok(input
        .series
        .iter()
        .zip(&output.series)
        .map(|(i, o)| {
            let mean = i.values.iter().sum::<f64>() / i.values.len().max(1) as f64;
            Direction {
                sign: if mean < 0.0 { -1.0 } else { 1.0 },
                input: &i.values,
                output: &o.values,
            }
        })
        .collect())
}
