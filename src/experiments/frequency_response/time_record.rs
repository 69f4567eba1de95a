//! The frequency-response test recorded as raw time series, as a DAQ on a real rig
//! would (a `frequency_response_time` experiment file): one continuous open-loop
//! simulation under a stepped sine, random noise or a chirp, sampling motor torque,
//! motor angle and table angle at a fixed rate. Evaluated by
//! `frequency_response_estimate.rs`.
//!
//! Motor torque `preload·Rg·Rw + excitation`, table brake `−preload` (docs/experiments.md (frequency response)).
//! The run starts at rest, with the flanks loaded by the preload (or at the edge of
//! the gap without one). Readings: the motor angle quantised to the motor encoder, the
//! table angle to the table encoder (0.0001° in the presets) plus optional Gaussian
//! noise. The torque column is the commanded torque at the sample instant (for noise
//! the value a D/A holds until the next sample).

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

use crate::controller::quantise;
use crate::estimation::periodic::multisine::{self, Level, LineSet, MultisineSpec, PhaseRule};
use crate::experiments::frequency_response::{initial_state, FrequencyTest};
use crate::input::TorqueInput;
use crate::io::experiment_file::{self, Data, Kind, Manifest};
use crate::model::drive::idx::*;
use crate::model::{Params, NSTATE};
use crate::recorder::Recorder;
use crate::sim::{SimError, Simulation};

/// The excitation of the motor torque (around the preload's DC torque).
#[derive(Clone, Debug, PartialEq)]
pub enum Excitation {
    /// `amplitude·sin(2πf_k(t − t_k))` for `dwell_s` at each frequency in turn
    /// (t_k the start of dwell k: every dwell starts at zero torque).
    SteppedSine {
        frequencies_hz: Vec<f64>,
        dwell_s: f64,
    },
    /// Gaussian noise of standard deviation `amplitude`, band-limited to
    /// `from_hz..=to_hz` (white noise with the bins outside the band removed, rescaled),
    /// a new value every sample, held in between (a D/A's zero-order hold), seeded.
    Noise { seed: u64, from_hz: f64, to_hz: f64 },
    /// `amplitude·sin(φ(t))`, frequency rising linearly from `from_hz` to `to_hz` over
    /// the record.
    Chirp { from_hz: f64, to_hz: f64 },
    /// A periodic multisine ([`crate::estimation::periodic::multisine`]): Schroeder phases on `lines` of
    /// `from_hz..=to_hz` (spacing 1/`period_s`), RMS `amplitude`, `periods` periods,
    /// a new value every sample, held in between (a D/A's zero-order hold).
    Multisine {
        period_s: f64,
        periods: usize,
        from_hz: f64,
        to_hz: f64,
        lines: LineSet,
    },
}

impl Excitation {
    /// Whether the torque is a sequence of sample values held by a D/A.
    fn held(&self) -> bool {
        matches!(
            self,
            Excitation::Noise { .. } | Excitation::Multisine { .. }
        )
    }
}

/// Conditions of the recorded test.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordTest {
    pub excitation: Excitation,
    /// Sine or chirp amplitude, or noise standard deviation, N·m (default 5).
    pub amplitude_nm: f64,
    /// Table brake balanced by a motor DC torque, N·m (default 0).
    pub preload_nm: f64,
    /// Record length for noise and chirp, s (stepped sine: frequencies × dwell).
    pub duration_s: f64,
    /// Sampling rate, Hz (default 5000; the period is rounded to whole integration
    /// steps).
    pub sample_rate_hz: f64,
    /// Standard deviation of Gaussian noise added to the table reading, rad (0).
    pub table_noise_rad: f64,
    /// Seed of the measurement noise.
    pub seed: u64,
}

impl Default for RecordTest {
    fn default() -> Self {
        RecordTest {
            excitation: Excitation::Noise {
                seed: 1,
                from_hz: 0.0,
                to_hz: 1000.0,
            },
            amplitude_nm: 5.0,
            preload_nm: 0.0,
            duration_s: 8.0,
            sample_rate_hz: 5000.0,
            table_noise_rad: 0.0,
            seed: 1,
        }
    }
}

impl RecordTest {
    /// The record's length, s.
    pub fn duration(&self) -> f64 {
        match &self.excitation {
            Excitation::SteppedSine {
                frequencies_hz,
                dwell_s,
            } => frequencies_hz.len() as f64 * dwell_s,
            Excitation::Multisine {
                period_s, periods, ..
            } => *periods as f64 * period_s,
            _ => self.duration_s,
        }
    }
}

/// The recorded series (rad, N·m, s).
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    pub time: Vec<f64>,
    pub torque: Vec<f64>,
    pub motor_angle: Vec<f64>,
    pub table_angle: Vec<f64>,
}

/// The motor torque of a test, sample-exact at the recording instants.
struct Drive {
    excitation: Excitation,
    amplitude: f64,
    offset: f64,
    duration: f64,
    /// Noise values, one per sample period.
    held: Vec<f64>,
    period: f64,
}

impl Drive {
    fn at(&self, t: f64) -> f64 {
        use std::f64::consts::TAU;
        let a = self.amplitude;
        self.offset
            + match &self.excitation {
                Excitation::SteppedSine {
                    frequencies_hz,
                    dwell_s,
                } => {
                    let k = ((t / dwell_s).floor().max(0.0) as usize).min(frequencies_hz.len() - 1);
                    a * (TAU * frequencies_hz[k] * (t - k as f64 * dwell_s)).sin()
                }
                Excitation::Noise { .. } | Excitation::Multisine { .. } => {
                    // Mid-sample times never round across a boundary.
                    let j = ((t / self.period).floor().max(0.0) as usize).min(self.held.len() - 1);
                    a * self.held[j]
                }
                Excitation::Chirp { from_hz, to_hz } => {
                    let rate = (to_hz - from_hz) / self.duration;
                    a * (TAU * (from_hz * t + 0.5 * rate * t * t)).sin()
                }
            }
    }
}

impl Drive {
    /// The torque recorded with sample `i` at `t`: for held noise the value held from
    /// this instant on.
    fn sample(&self, i: usize, t: f64) -> f64 {
        if self.excitation.held() {
            self.at((i as f64 + 0.5) * self.period)
        } else {
            self.at(t)
        }
    }
}

impl TorqueInput for &Drive {
    fn step_torques(&mut self, t: f64, h: f64) -> [f64; 3] {
        if self.excitation.held() {
            return [self.at(t + 0.5 * h); 3];
        }
        [self.at(t), self.at(t + 0.5 * h), self.at(t + h)]
    }
}

/// Samples every `every` steps: quantised encoders, table noise.
struct Sampler<'a> {
    every: u64,
    count: u64,
    drive: &'a Drive,
    motor_quantum: f64,
    table_quantum: f64,
    noise: Normal<f64>,
    rng: rand::rngs::StdRng,
    record: Record,
    samples: usize,
}

impl Recorder for Sampler<'_> {
    fn record(&mut self, t: f64, y: &[f64; NSTATE], _u: f64) {
        if self.count % self.every == 0 && self.record.time.len() < self.samples {
            let r = &mut self.record;
            r.time.push(t);
            let i = r.time.len() - 1;
            r.torque.push(self.drive.sample(i, t));
            r.motor_angle.push(quantise(y[THETA_M], self.motor_quantum));
            r.table_angle
                .push(quantise(y[THETA_T], self.table_quantum) + self.noise.sample(&mut self.rng));
        }
        self.count += 1;
    }
}

/// `n` samples of unit-RMS Gaussian noise whose spectrum (sampling period `period`)
/// is confined to `from_hz..=to_hz`: white noise, its FFT bins outside the band set to
/// zero, transformed back and rescaled.
fn band_limited_noise(n: usize, period: f64, from_hz: f64, to_hz: f64, seed: u64) -> Vec<f64> {
    use rustfft::{num_complex::Complex, FftPlanner};
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let white = Normal::new(0.0, 1.0).expect("unit normal");
    let mut x: Vec<Complex<f64>> = (0..n)
        .map(|_| Complex::new(white.sample(&mut rng), 0.0))
        .collect();
    let mut planner = FftPlanner::new();
    planner.plan_fft_forward(n).process(&mut x);
    let df = 1.0 / (n as f64 * period);
    for (k, v) in x.iter_mut().enumerate() {
        let f = k.min(n - k) as f64 * df;
        if f < from_hz || f > to_hz || k == 0 {
            *v = Complex::new(0.0, 0.0);
        }
    }
    planner.plan_fft_inverse(n).process(&mut x);
    let rms = (x.iter().map(|v| v.re * v.re).sum::<f64>() / n as f64).sqrt();
    let scale = if rms > 0.0 { 1.0 / rms } else { 0.0 };
    x.iter().map(|v| v.re * scale).collect()
}

/// Why a recorded test cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RecordError {
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error("{name} = {value}: {why}")]
    Condition {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
    #[error("the multisine: {0}")]
    Multisine(String),
}

fn check(name: &'static str, value: f64, ok: bool, why: &'static str) -> Result<(), RecordError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(RecordError::Condition { name, value, why })
    }
}

/// Checks the test's conditions, naming the first that is not valid.
fn validate(test: &RecordTest) -> Result<(), RecordError> {
    check(
        "amplitude_nm",
        test.amplitude_nm,
        test.amplitude_nm > 0.0,
        "must be positive",
    )?;
    check("preload_nm", test.preload_nm, true, "must be finite")?;
    check(
        "sample_rate_hz",
        test.sample_rate_hz,
        test.sample_rate_hz > 0.0,
        "must be positive",
    )?;
    check(
        "table_noise_rad",
        test.table_noise_rad,
        test.table_noise_rad >= 0.0,
        "must be zero or positive",
    )?;
    match &test.excitation {
        Excitation::SteppedSine {
            frequencies_hz,
            dwell_s,
        } => {
            check("dwell_s", *dwell_s, *dwell_s > 0.0, "must be positive")?;
            let bad = frequencies_hz
                .iter()
                .find(|f| !(**f > 0.0 && f.is_finite()));
            check(
                "frequencies_hz",
                bad.copied().unwrap_or(0.0),
                bad.is_none() && !frequencies_hz.is_empty(),
                "need one or more positive frequencies",
            )?;
        }
        Excitation::Noise { from_hz, to_hz, .. } | Excitation::Chirp { from_hz, to_hz } => {
            check(
                "from_hz",
                *from_hz,
                *from_hz >= 0.0,
                "must be zero or positive",
            )?;
            check("to_hz", *to_hz, to_hz > from_hz, "must be above from_hz")?;
        }
        Excitation::Multisine {
            period_s,
            periods,
            from_hz,
            to_hz,
            ..
        } => {
            check("period_s", *period_s, *period_s > 0.0, "must be positive")?;
            check(
                "periods",
                *periods as f64,
                *periods >= 3,
                "need 3 or more (the first is dropped as transient, and the noise needs two)",
            )?;
            check("from_hz", *from_hz, *from_hz > 0.0, "must be positive")?;
            check(
                "to_hz",
                *to_hz,
                to_hz >= from_hz,
                "must be at or above from_hz",
            )?;
        }
    }
    let duration = test.duration();
    check("duration_s", duration, duration > 0.0, "must be positive")
}

/// The generator's description of a multisine test sampled every `period` s (unit
/// RMS); `None` for other excitations.
fn multisine_spec(test: &RecordTest, period: f64) -> Option<MultisineSpec> {
    let Excitation::Multisine {
        period_s,
        periods,
        from_hz,
        to_hz,
        lines,
    } = test.excitation
    else {
        return None;
    };
    Some(MultisineSpec {
        sample_rate_hz: 1.0 / period,
        samples_per_period: (period_s / period).round() as usize,
        periods,
        min_frequency_hz: from_hz,
        max_frequency_hz: to_hz,
        lines,
        phases: PhaseRule::Schroeder,
        level: Level::Rms(1.0),
    })
}

/// One period of a multisine test at unit RMS, sampled every `period` s — which must
/// divide its period.
fn multisine_samples(test: &RecordTest, period: f64) -> Result<Vec<f64>, RecordError> {
    let spec = multisine_spec(test, period).expect("called for a multisine test only");
    let n = spec.samples_per_period as f64 * period;
    let period_s = test.duration() / spec.periods as f64;
    check(
        "period_s",
        period_s,
        (n - period_s).abs() <= 1e-9 * period_s,
        "must be a whole number of sample periods",
    )?;
    multisine::generate(&spec)
        .map(|m| m.period)
        .map_err(|e| RecordError::Multisine(e.to_string()))
}

/// The drive of `test` on `p`, sampled every `period` s for `samples` samples.
fn drive(p: &Params, test: &RecordTest, period: f64, samples: usize) -> Result<Drive, RecordError> {
    let held = match test.excitation {
        Excitation::Noise {
            seed,
            from_hz,
            to_hz,
        } => band_limited_noise(samples.max(2), period, from_hz, to_hz, seed),
        Excitation::Multisine { .. } => multisine_samples(test, period)?
            .into_iter()
            .cycle()
            .take(samples)
            .collect(),
        _ => Vec::new(),
    };
    Ok(Drive {
        excitation: test.excitation.clone(),
        amplitude: test.amplitude_nm,
        offset: test.preload_nm * p.ratio(),
        duration: test.duration(),
        held,
        period,
    })
}

impl<'a> Sampler<'a> {
    /// A sampler of `samples` records every `every` steps of `drive`, with `p`'s
    /// encoders and `test`'s table noise.
    fn new(p: &Params, test: &RecordTest, drive: &'a Drive, every: u64, samples: usize) -> Self {
        let counts = p.controller.motor_encoder_counts;
        Sampler {
            every,
            count: 0,
            drive,
            motor_quantum: if counts > 0.0 {
                std::f64::consts::TAU / counts
            } else {
                0.0
            },
            table_quantum: p.controller.table_encoder_resolution,
            noise: Normal::new(0.0, test.table_noise_rad).expect("validate checked σ finite"),
            rng: rand::rngs::StdRng::seed_from_u64(test.seed),
            record: Record {
                time: Vec::with_capacity(samples),
                torque: Vec::with_capacity(samples),
                motor_angle: Vec::with_capacity(samples),
                table_angle: Vec::with_capacity(samples),
            },
            samples,
        }
    }
}

/// Runs the test on the model. `progress(done_s, total_s)` after every simulated second.
pub fn run(
    p: &Params,
    test: &RecordTest,
    mut progress: impl FnMut(f64, f64),
) -> Result<Record, RecordError> {
    validate(test)?;
    let mut sim = Simulation::with_default_step(p)?;
    let dt = sim.dt();
    let every = ((1.0 / test.sample_rate_hz / dt).round() as u64).max(1);
    let period = every as f64 * dt;
    let samples = (test.duration() / period).round() as usize;
    let drive = drive(p, test, period, samples)?;
    let start = FrequencyTest {
        amplitude_nm: 0.0,
        preload_nm: test.preload_nm,
        ..Default::default()
    };
    sim.set_state(initial_state(p, 1.0, &start));
    sim.set_load(-test.preload_nm);
    let mut rec = Sampler::new(p, test, &drive, every, samples);
    let steps = samples as u64 * every;
    let total = steps as f64 * dt;
    let mut input = &drive;
    let mut done = 0u64;
    let chunk = ((1.0 / dt).round() as u64).max(1);
    while done < steps {
        let n = chunk.min(steps - done);
        sim.run_open_loop(&mut input, n as f64 * dt, &mut rec)?;
        done += n;
        progress(done as f64 * dt, total);
    }
    Ok(rec.record)
}

/// The experiment-file form of a record.
pub fn to_data(record: &Record) -> Data {
    Data::FrequencyResponseTime {
        time_s: record.time.clone(),
        motor_torque_nm: record.torque.clone(),
        motor_angle_rad: record.motor_angle.clone(),
        table_angle_rad: record.table_angle.clone(),
        extra: Default::default(),
    }
}

/// The manifest's conditions of a multisine test: the period, one transient period,
/// and the excited lines when they form a regular grid (else they are detected).
fn multisine_conditions(test: &RecordTest, c: &mut experiment_file::Conditions) {
    let Some(spec) = multisine_spec(test, 1.0 / test.sample_rate_hz) else {
        return;
    };
    let period_s = test.duration() / spec.periods as f64;
    c.excitation = Some(experiment_file::Excitation::Multisine);
    c.period_s = Some(period_s);
    c.transient_periods = Some(1);
    let Ok(lines) = multisine::excited_lines(&spec) else {
        return;
    };
    let step = match lines[..] {
        [a, b, ..] => b - a,
        _ => 1,
    };
    if lines.windows(2).all(|w| w[1] - w[0] == step) {
        let hz = |k: usize| k as f64 / period_s;
        c.first_line_hz = lines.first().map(|&k| hz(k));
        c.last_line_hz = lines.last().map(|&k| hz(k));
        c.line_step_hz = Some(hz(step));
    }
}

fn line_set_name(lines: &LineSet) -> &'static str {
    match lines {
        LineSet::Full => "every line",
        LineSet::Odd => "odd lines",
        LineSet::RandomOdd { .. } => "random-odd lines",
    }
}

/// The manifest of a record of `test` on `p`.
pub fn manifest(p: &Params, test: &RecordTest) -> Manifest {
    let mut m = Manifest::new(Kind::FrequencyResponseTime);
    m.mechanism = Some(p.name.clone());
    let c = &mut m.conditions;
    c.ratio = Some(p.ratio());
    c.torque_amplitude_nm = Some(test.amplitude_nm);
    c.preload_nm = Some(test.preload_nm);
    let what = match &test.excitation {
        Excitation::SteppedSine {
            frequencies_hz,
            dwell_s,
        } => {
            c.excitation = Some(experiment_file::Excitation::SteppedSine);
            c.frequencies_hz = Some(frequencies_hz.clone());
            c.dwell_s = Some(*dwell_s);
            format!(
                "stepped sine, {} frequencies, {dwell_s} s each",
                frequencies_hz.len()
            )
        }
        Excitation::Noise {
            seed,
            from_hz,
            to_hz,
        } => {
            c.excitation = Some(experiment_file::Excitation::Broadband);
            format!("Gaussian noise torque, {from_hz}–{to_hz} Hz, held per sample, seed {seed}")
        }
        Excitation::Chirp { from_hz, to_hz } => {
            c.excitation = Some(experiment_file::Excitation::Broadband);
            format!("linear chirp {from_hz}–{to_hz} Hz")
        }
        Excitation::Multisine {
            period_s,
            periods,
            from_hz,
            to_hz,
            lines,
        } => {
            multisine_conditions(test, c);
            format!(
                "periodic multisine ({}), Schroeder phases, lines {from_hz}–{to_hz} Hz, {periods} periods of {period_s} s, torque RMS as the amplitude, held per sample",
                line_set_name(lines)
            )
        }
    };
    m.notes = Some(format!(
        "virtual test by rtid: open loop, {what}, {} N·m; table reading quantised to {:.4}° \
         plus {:.3}″ rms noise",
        test.amplitude_nm,
        p.controller.table_encoder_resolution.to_degrees(),
        test.table_noise_rad.to_degrees() * 3600.0
    ));
    m
}
