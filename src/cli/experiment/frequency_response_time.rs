//! `rtid experiment frequency-response-time` and the evaluation of
//! `frequency_response_time` files (raw torque and angles over time).

use crate::cli::common::plot::Plot;
use std::path::Path;

use anyhow::bail;

use super::check::{self, positive};
use super::Common;
use crate::cli::common::progress;
use rtid::estimation::periodic::multisine::LineSet;
use rtid::experiments::frequency_response::time_evaluation::{
    self as estimate, EstimateOptions, Evaluation,
};
use rtid::experiments::frequency_response::time_record::{self as record, Excitation, RecordTest};
use rtid::io::experiment_file::{self, Experiment};
use rtid::names::Num;
use std::fmt::Write as _;

pub const LONG_ABOUT: &str = "\
The frequency-response test (paper §4.1) recorded as raw time series, the way a DAQ on a \
real rig records it: one continuous open-loop run under a stepped sine, band-limited \
random noise, a chirp or a periodic multisine, sampling motor torque, motor angle and table angle (encoders \
quantised, table 0.0001°, plus optional --noise-arcsec) at --sample-rate-hz. Written as a \
`frequency_response_time` experiment file (docs/experiment-files.md), which `rtid \
evaluate` turns into the gain curve; a measured recording in the same format is evaluated \
the same way.

Evaluation (docs/experiments.md): a stepped sine is demodulated per dwell (the first \
--settle-fraction of each dwell discarded, then a least-squares sine + drift fit over whole \
cycles); noise and chirp records give the H1 estimate with Welch averaging (Hann window, \
50 % overlap, --segment-s long segments: resolution 1/segment) and the coherence γ². Bins \
with γ² below --min-coherence are flagged and left out of the peak search. Gain = table \
angle / (motor angle × Rg·Rw), in dB; its peaks are the resonances. A multisine record \
(manifest `\"excitation\": \"multisine\"`) is cut into whole periods (no window, no \
leakage; the first dropped as transient) and gives both channels at the excited lines — \
table/motor by the reference ratio, motor/torque (or motor/current) by H1 — with the \
noise of each line from the spread over the periods; resonances and antiresonances are \
the extrema that stand out of that noise, located by a rational fit around them; the \
lines left out measure the nonlinear distortion (docs/multisine.md).

Outputs, in --out DIR: frequency_response_time.json/.csv, frequency_response_time.svg (the \
gain, kept bins only, with the resonances; a multisine's both channels with resonances \
and antiresonances) and, for noise, chirp and multisine, \
frequency_response_time-coherence.svg.

Examples:
  rtid experiment frequency-response-time --preset worm-gear --out runs/worm
  rtid experiment frequency-response-time --preset worm-gear --excitation stepped-sine --from-hz 150 --to-hz 260 --step-hz 2 --out runs/stepped
  rtid experiment frequency-response-time --preset worm-gear --excitation multisine --from-hz 100 --to-hz 400 --preload-nm 6 --out runs/multisine
  rtid experiment frequency-response-time --preset worm-gear --preload-nm 6 --noise-arcsec 1 --out runs/noisy";

/// The excitations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ExcitationKind {
    /// A sine held for --dwell-s at each frequency --from-hz, +--step-hz, … --to-hz.
    SteppedSine,
    /// Gaussian noise band-limited to --from-hz … --to-hz, held per sample.
    Noise,
    /// A linear chirp from --from-hz to --to-hz over --duration-s.
    Chirp,
    /// A periodic multisine: --periods periods of --period-s, Schroeder phases on the
    /// --lines of --from-hz … --to-hz (spacing 1/period), RMS --amplitude-nm.
    Multisine,
}

/// Which lines a multisine excites.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum LinesArg {
    /// Every line of the band: the densest gain curve; distortion not seen.
    Full,
    /// Odd lines: even-degree distortion seen at the even lines.
    Odd,
    /// Odd lines, one of every four left out at random: odd- and even-degree
    /// distortion seen apart from the noise.
    RandomOdd,
}

/// How a record is evaluated (shared with `rtid evaluate`).
#[derive(Debug, Clone, clap::Args)]
pub struct EstimateArgs {
    /// Noise/chirp records: Welch segment length, s (resolution = 1/segment; default 2 s,
    /// or a quarter of the record if shorter).
    #[arg(long, value_name = "SECONDS")]
    pub segment_s: Option<f64>,
    /// Noise/chirp records: coherence γ² below which a frequency bin is flagged and left
    /// out of the peak search and the plot.
    #[arg(long, value_name = "GAMMA2", default_value_t = 0.8)]
    pub min_coherence: f64,
    /// Stepped-sine records: fraction of each dwell discarded as settling.
    #[arg(long, value_name = "FRACTION", default_value_t = 0.5)]
    pub settle_fraction: f64,
}

impl EstimateArgs {
    /// The options, each checked naming its flag.
    pub fn options(&self) -> anyhow::Result<EstimateOptions> {
        if let Some(s) = self.segment_s {
            positive(s, "--segment-s")?;
        }
        if !(0.0..=1.0).contains(&self.min_coherence) {
            bail!(
                "--min-coherence {}: a coherence γ² lies in 0..1",
                Num(self.min_coherence)
            );
        }
        if !(0.0..1.0).contains(&self.settle_fraction) {
            bail!(
                "--settle-fraction {}: the fraction of each dwell discarded lies in 0..1 (below 1: some must be kept)",
                Num(self.settle_fraction)
            );
        }
        Ok(EstimateOptions {
            segment_s: self.segment_s,
            min_coherence: self.min_coherence,
            settle_fraction: self.settle_fraction,
            ..Default::default()
        })
    }
}

/// Arguments of `rtid experiment frequency-response-time`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// The motor-torque excitation.
    #[arg(long, value_enum, default_value = "noise")]
    pub excitation: ExcitationKind,
    /// Sine or chirp amplitude, or the noise's or multisine's RMS, N·m.
    #[arg(long, value_name = "NM", default_value_t = 5.0)]
    pub amplitude_nm: f64,
    /// Table brake torque balanced by a motor DC torque, N·m (keeps the flanks loaded).
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub preload_nm: f64,
    /// Lowest frequency (stepped sine: first step; noise: band edge; chirp: start), Hz.
    #[arg(long, value_name = "HZ", default_value_t = 10.0)]
    pub from_hz: f64,
    /// Highest frequency, Hz.
    #[arg(long, value_name = "HZ", default_value_t = 600.0)]
    pub to_hz: f64,
    /// Stepped sine: frequency step, Hz.
    #[arg(long, value_name = "HZ", default_value_t = 10.0)]
    pub step_hz: f64,
    /// Stepped sine: time at each frequency, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.5)]
    pub dwell_s: f64,
    /// Noise and chirp: record length, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 16.0)]
    pub duration_s: f64,
    /// Multisine: the period, s (line spacing 1/period; a whole number of samples).
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0)]
    pub period_s: f64,
    /// Multisine: periods recorded (the first is dropped as transient when evaluated).
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub periods: usize,
    /// Multisine: which lines of the band are excited.
    #[arg(long, value_enum, default_value = "random-odd")]
    pub lines: LinesArg,
    /// Sampling rate of the record, Hz (period rounded to whole integration steps).
    #[arg(long, value_name = "HZ", default_value_t = 5000.0)]
    pub sample_rate_hz: f64,
    /// Gaussian noise added to the table reading, arc-seconds rms.
    #[arg(long, value_name = "ARCSEC", default_value_t = 0.0)]
    pub noise_arcsec: f64,
    /// Seed of the noise excitation and the measurement noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[command(flatten)]
    pub estimate: EstimateArgs,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.common.params()?;
    let test = a.test()?;
    a.common.create_out()?;
    let bar = progress::bar(test.duration().ceil() as u64, "simulated s", a.common.quiet);
    let rec = record::run(&p, &test, |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();
    let stem = "frequency_response_time";
    let path = a.common.out.join(format!("{stem}.json"));
    let mut manifest = record::manifest(&p, &test);
    manifest.data = Some(format!("{stem}.csv"));
    experiment_file::write(&path, &manifest, &record::to_data(&rec))?;
    report_with(
        &experiment_file::read(&path)?,
        &Plot::at(a.common.out.join(format!("{stem}.svg")), &[])?,
        a.common.json,
        &a.estimate.options()?,
    )
}

impl Args {
    /// The test the flags describe, checked (and its work estimated) before anything
    /// runs.
    fn test(&self) -> anyhow::Result<RecordTest> {
        let (from, to) = (self.from_hz, self.to_hz);
        if !(from >= 0.0 && to > from && to.is_finite()) {
            bail!(
                "--from-hz {} --to-hz {}: need 0 ≤ from < to",
                Num(from),
                Num(to)
            );
        }
        check::non_negative(self.noise_arcsec, "--noise-arcsec")?;
        check::finite(self.preload_nm, "--preload-nm")?;
        let test = RecordTest {
            excitation: self.excitation()?,
            amplitude_nm: positive(self.amplitude_nm, "--amplitude-nm")?,
            preload_nm: self.preload_nm,
            duration_s: positive(self.duration_s, "--duration-s")?,
            sample_rate_hz: positive(self.sample_rate_hz, "--sample-rate-hz")?,
            table_noise_rad: (self.noise_arcsec / 3600.0).to_radians(),
            seed: self.seed,
        };
        if to >= test.sample_rate_hz / 2.0 {
            bail!(
                "--sample-rate-hz {}: a record sampled at it holds frequencies up to {} Hz \
                 (half the rate), below --to-hz {}: sample more than twice as fast as the \
                 highest frequency excited",
                Num(test.sample_rate_hz),
                Num(test.sample_rate_hz / 2.0),
                Num(to)
            );
        }
        check::work(
            test.duration(),
            check::MAX_SIMULATED_S,
            "simulated seconds",
            "--duration-s (or --periods × --period-s, frequencies × --dwell-s)",
        )?;
        check::work(
            test.duration() * test.sample_rate_hz,
            rtid::limits::MAX_RECORD_SAMPLES,
            "samples",
            "--sample-rate-hz with the record's length",
        )?;
        Ok(test)
    }

    /// The excitation the flags describe.
    fn excitation(&self) -> anyhow::Result<Excitation> {
        let (from, to) = (self.from_hz, self.to_hz);
        Ok(match self.excitation {
            ExcitationKind::SteppedSine => {
                let step = positive(self.step_hz, "--step-hz")?;
                let first = positive(from, "--from-hz")?;
                Excitation::SteppedSine {
                    frequencies_hz: check::frequency_grid(first, to, step)?,
                    dwell_s: positive(self.dwell_s, "--dwell-s")?,
                }
            }
            ExcitationKind::Noise => Excitation::Noise {
                seed: self.seed,
                from_hz: from,
                to_hz: to,
            },
            ExcitationKind::Chirp => Excitation::Chirp {
                from_hz: from,
                to_hz: to,
            },
            ExcitationKind::Multisine => {
                if self.periods < 3 {
                    bail!("--periods {}: need 3 or more (the first is dropped as transient, and the noise needs two)", self.periods);
                }
                Excitation::Multisine {
                    period_s: positive(self.period_s, "--period-s")?,
                    periods: self.periods,
                    from_hz: positive(from, "--from-hz")?,
                    to_hz: to,
                    lines: match self.lines {
                        LinesArg::Full => LineSet::Full,
                        LinesArg::Odd => LineSet::Odd,
                        LinesArg::RandomOdd => LineSet::RandomOdd {
                            group: 4,
                            seed: self.seed,
                        },
                    },
                }
            }
        })
    }
}

/// Evaluates a `frequency_response_time` experiment: printed (table or JSON), the gain
/// plot written to `plot` and, for H1, the coherence beside it (`…-coherence.svg`).
pub fn report_with(
    exp: &Experiment,
    plot: &Plot,
    json: bool,
    opts: &EstimateOptions,
) -> anyhow::Result<()> {
    let e = estimate::evaluate_experiment(exp, opts).map_err(|err| match err {
        estimate::EstimateError::Ratio(r) => anyhow::anyhow!("{r}"),
        other => anyhow::anyhow!("{}: {other}", exp.path.display()),
    })?;
    let mechanism = exp.manifest.mechanism.as_deref().unwrap_or("table");
    plot_evaluation(&e, mechanism, plot)?;
    if json {
        let source = exp.path.display().to_string();
        let value =
            rtid::report::evaluation::frequency_response_time(&e, exp.manifest.kind, &source)?;
        println!("{}", rtid::io::json::pretty(&value)?);
        return Ok(());
    }
    match &e {
        Evaluation::Periodic(p) => println!("{}", super::periodic_summary::summary(p, &exp.path)),
        _ => println!("{}", summary(&e, &exp.path)),
    }
    Ok(())
}

fn plot_evaluation(e: &Evaluation, mechanism: &str, plot: &Plot) -> anyhow::Result<()> {
    let (gain, coherence) = rtid::report::frequency_response_time::figures(e, mechanism);
    plot.write(&gain, "")?;
    if let Some(c) = coherence {
        plot.write(&c, "-coherence")?;
    }
    Ok(())
}

/// The printed evaluation.
fn summary(e: &Evaluation, source: &Path) -> String {
    let mut s = format!(
        "{}: frequency response from time series\n",
        source.display()
    );
    match e {
        Evaluation::SteppedSine { .. } => stepped_sine_summary(e, &mut s),
        Evaluation::H1 { .. } => h1_summary(e, &mut s),
        Evaluation::Periodic(_) => {}
    }
    let _ = writeln!(
        s,
        "resonances (local maxima of the gain, parabolic interpolation):"
    );
    for p in e.peaks() {
        let _ = writeln!(s, "  {:8.2} Hz  {:7.2} dB", p.frequency_hz, p.gain_db);
    }
    if e.peaks().is_empty() {
        let _ = writeln!(s, "  none found");
    }
    s.trim_end().to_string()
}

/// The demodulated points of a stepped sine, one line each.
fn stepped_sine_summary(e: &Evaluation, s: &mut String) {
    let Evaluation::SteppedSine {
        ratio,
        settle_fraction,
        points,
        ..
    } = e
    else {
        return;
    };
    let _ = writeln!(
        s,
        "stepped sine, {} frequencies, first {:.0} % of each dwell discarded; ratio {ratio:.6e}",
        points.len(),
        100.0 * settle_fraction
    );
    let _ = writeln!(
        s,
        "  freq Hz   gain dB  phase deg  table amp ″  cycles  residual"
    );
    for q in points {
        let flag = if q.table_residual > 0.5 {
            "  not a clean sine"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "{:9.2} {:9.3} {:10.2} {:12.3} {:7} {:9.3}{flag}",
            q.frequency_hz,
            q.gain_db,
            q.phase_deg,
            q.table_amplitude_rad.to_degrees() * 3600.0,
            q.cycles,
            q.table_residual
        );
    }
}

/// The H1 settings, and per 100 Hz band the share of kept bins, the mean coherence and
/// the range of the kept gains.
fn h1_summary(e: &Evaluation, s: &mut String) {
    let Evaluation::H1 {
        ratio,
        sample_rate_hz,
        segment_len,
        segments,
        resolution_hz,
        min_coherence,
        kept,
        bins,
        ..
    } = e
    else {
        return;
    };
    let _ = writeln!(
        s,
        "H1 with Welch averaging: {sample_rate_hz:.1} Hz sampling, segments of {segment_len} \
         samples (resolution {resolution_hz:.3} Hz), {segments} averaged, Hann, 50 % overlap; \
         ratio {ratio:.6e}"
    );
    let _ = writeln!(
        s,
        "{kept} of {} bins with γ² ≥ {min_coherence} (the others are left out)",
        bins.len()
    );
    let _ = writeln!(s, "  band Hz      kept   mean γ²   gain dB (kept)");
    let top = (sample_rate_hz / 2.0).min(1000.0);
    let mut lo = 0.0;
    while lo < top {
        let hi = lo + 100.0;
        let band: Vec<_> = bins
            .iter()
            .filter(|b| b.frequency_hz >= lo && b.frequency_hz < hi)
            .collect();
        if !band.is_empty() {
            let k: Vec<f64> = band.iter().filter(|b| b.kept).map(|b| b.gain_db).collect();
            let mean = band.iter().map(|b| b.coherence).sum::<f64>() / band.len() as f64;
            let range = if k.is_empty() {
                "—".to_string()
            } else {
                let (a, b) = k
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(a, b), &g| (a.min(g), b.max(g)));
                format!("{a:.1} … {b:.1}")
            };
            let _ = writeln!(
                s,
                "  {lo:4.0}–{hi:<4.0} {:5.0} %  {mean:8.3}   {range}",
                100.0 * k.len() as f64 / band.len() as f64
            );
        }
        lo = hi;
    }
}
