//! `rtid evaluate`: the statistics of a measured (or virtual) experiment file.

use std::path::PathBuf;

use anyhow::bail;

use crate::cli::common::model_args::ModelArgs;
use crate::cli::common::plot::Plot;
use crate::cli::compensate;
use crate::cli::experiment::{
    fluctuation, frequency_response, frequency_response_time, friction_map, positioning,
    servo_trace, torque_curve,
};
use rtid::io::experiment_file::{self, Kind};

pub const LONG_ABOUT: &str = "\
Evaluates an experiment file (a JSON manifest with its CSV, docs/experiment-files.md), \
measured on a real table or written by `rtid experiment`; with --plot FILE.svg, writes \
its plots (the first at FILE.svg, the others beside it: FILE-effort.svg, …). Without \
--plot nothing is written: evaluating never touches the files beside the input.

Kinds evaluated:
  frequency_response   the resonances: local maxima of the gain, located by parabolic \
interpolation (Hz, dB). Plot: gain over frequency, with the linear model's curve when the \
file carries one.
  positioning   ISO 230-2 statistics in arc-seconds: per target x̄↑, x̄↓, s↑, s↓, Bi, R↑i, \
R↓i, Ri; for the axis the reversal B and mean reversal B̄, repeatability R↑, R↓, R, \
systematic deviation E↑, E↓, E, mean deviation M, accuracy A↑, A↓, A. Plot: the paper's \
Fig. 10. With --runs, those runs only; with --compensation FILE (from `rtid compensate`), \
the axis values as the axis with that backlash and table would show them (each reading \
shifted by the offset the controller would add at its target and direction), beside the \
uncompensated ones.
  torque_curve  RMS and peak motor torque, N·m (force, N, on a linear axis), and the Coulomb friction at the motor: with the table angle (position) in the file, from the friction law F = M·a + Fv·v + Fc·sign(v) + OF fitted over the whole curve (IDIM-LS: any trajectory); without it, half the torque jump across each reversal of the commanded sine, averaged (the reversals and their jumps are listed either way). Plot: torque over time (the paper's Fig. 9), and over table angle in FILE-vs-angle.svg when the file has the angle.
  fluctuation   deviation θt − θm·ratio over table angle per direction (ratio: the \
manifest's conditions.ratio, else Rg·Rw of the preset named in `mechanism`): mean, \
peak-to-peak, the gap between the directions (lost motion), the power spectrum over \
cycles per revolution and its dominant orders with amplitudes, the largest step. Plots: \
FILE.svg (Fig. 11) and FILE-spectrum.svg (Fig. 12).
  frequency_response_time   raw motor torque, motor angle and table angle over time, \
uniformly sampled. A stepped sine (conditions.excitation = stepped_sine, frequencies_hz, \
dwell_s) is demodulated per dwell: the first --settle-fraction discarded, then a \
least-squares fit of offset, drift and sine over whole cycles; gain, phase, and the fit's \
residual (a flag for noise or backlash rattle). A broadband record (noise, chirp, an \
undescribed multisine) gives the H1 estimate with Welch averaging (Hann, 50 % overlap, \
--segment-s: resolution 1/segment) and the coherence γ²; bins below --min-coherence are \
left out. Gain = table angle / (motor angle × ratio); resonances as above (for H1 only \
peaks that stand out of the random error). A periodic multisine (conditions.excitation = \
multisine, period_s; input motor_torque_nm or motor_current_a) is cut into whole periods \
(no leakage) and gives both channels — table/motor and motor/torque (or motor/current) — \
with each line's noise from the spread over the periods, the resonances and \
antiresonances that stand out of it (fitted frequency, damping), the two-mass ratios \
Jl/Jm and k/Jl, and the nonlinear distortion at the lines left out (docs/multisine.md). \
Plots: FILE.svg (gain) and FILE-coherence.svg.
  unbalance     as fluctuation; the step (largest change of the deviation across 0.5° of \
table angle, and where) is the backlash crossed when the unbalance moment overcomes the \
friction. Plots: FILE.svg (Fig. 14) and FILE-spectrum.svg.
  friction_map  one row per constant-speed run (mean speed and effort at the motor): the friction laws fitted by least squares with standard errors — coulomb (Fc·sgn v + Fv·v + Fo), stribeck (sgn v·(Fc + (Fs − Fc)·exp(−(|v|/vs)^delta)) + Fv·v + Fo), and per direction coulomb_asymmetric and stribeck_asymmetric — compared by AIC, AICc and BIC, and the law the data support (lowest AICc). A map with one direction only, a single speed per direction, or efforts of one sign is refused. Plots: FILE.svg (effort over speed with the laws) and FILE-residuals.svg.
  servo_trace   a recorded closed-loop run (reference, loop encoder, drive effort; rotary or linear). The friction law F = M·a + Fv·v + Fc·sign(v) + OF by inverse-dynamic least squares (IDIM-LS), with standard errors; with --params or --preset, the trace replayed on that model through its sampled servo, closed loop, and the simulation error: position RMS and largest, force RMS (SI in --json; µm or arc-seconds and N or N·m in the table). Plots: FILE.svg (following error, measured and replayed) and FILE-effort.svg.

Example:
  rtid evaluate runs/worm/positioning.json --json
  rtid evaluate runs/worm/positioning.json --runs 4-5 --compensation runs/worm/compensation.json
  rtid evaluate runs/worm/torque_curve.json
  rtid evaluate runs/worm/fluctuation.json
  rtid evaluate fixtures/real/emps/emps_estimation.json --params fixtures/real/emps/axis.json";

/// Arguments of `rtid evaluate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The experiment manifest.
    #[arg(value_name = "FILE.json")]
    pub file: PathBuf,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
    /// No progress display or notes on stderr (the command is quick: it has no
    /// progress bar; accepted like every command's `--quiet`, for scripts).
    #[arg(long)]
    pub quiet: bool,
    /// Write the plots: the first at FILE.svg, the others beside it with a suffix
    /// (FILE-effort.svg, FILE_phase.svg, …). None without it. A plot is never written
    /// over an input of the command.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub estimate: frequency_response_time::EstimateArgs,
    #[command(flatten)]
    pub idim: servo_trace::IdimArgs,
    /// Positioning only: the values as the axis compensated by this file (written by
    /// `rtid compensate`) would show them, beside the uncompensated ones.
    #[arg(long, value_name = "compensation.json")]
    pub compensation: Option<PathBuf>,
    /// Positioning only: evaluate these runs (`4-5`, `2`) [default: all].
    #[arg(long, value_name = "FIRST-LAST")]
    pub runs: Option<rtid::experiments::positioning::compensate::Runs>,
    /// The model a servo trace is replayed on (servo traces only; optional).
    #[command(flatten)]
    pub model: ModelArgs,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let exp = experiment_file::read(&a.file)?;
    let mut inputs: Vec<&std::path::Path> = vec![&a.file];
    inputs.extend(exp.data_path.as_deref());
    inputs.extend(a.model.params.as_deref());
    inputs.extend(a.compensation.as_deref());
    let plot = match &a.plot {
        Some(path) => Plot::at(path.clone(), &inputs)?,
        None => Plot::none(),
    };
    report(&a, &exp, &plot).map_err(|e| {
        // Every error names the file evaluated.
        let file = a.file.display().to_string();
        if format!("{e:#}").contains(&file) {
            e
        } else {
            e.context(file)
        }
    })
}

/// The evaluation of `exp`, printed, with its plots where `plot` says.
fn report(a: &Args, exp: &experiment_file::Experiment, plot: &Plot) -> anyhow::Result<()> {
    if exp.manifest.kind != Kind::Positioning && (a.compensation.is_some() || a.runs.is_some()) {
        bail!(
            "--compensation and --runs are for positioning records; this is a `{}` experiment",
            exp.manifest.kind.name()
        );
    }
    match exp.manifest.kind {
        Kind::Positioning => match &a.compensation {
            Some(c) => compensate::evaluate(exp, c, a.runs.as_ref(), plot, a.json),
            None => positioning::report_runs(exp, plot, a.json, a.runs.as_ref()),
        },
        Kind::FrequencyResponse => frequency_response::report(exp, plot, a.json),
        Kind::TorqueCurve => torque_curve::report(exp, plot, a.json),
        Kind::Fluctuation | Kind::Unbalance => fluctuation::report(exp, plot, a.json),
        Kind::ServoTrace => {
            let model = a.model.given().then(|| a.model.load()).transpose()?;
            servo_trace::report(exp, plot, a.json, model, &a.idim)
        }
        Kind::FrequencyResponseTime => {
            frequency_response_time::report_with(exp, plot, a.json, &a.estimate.options()?)
        }
        Kind::FrictionMap => friction_map::report(exp, plot, a.json),
        other => bail!(
            "{}: evaluating `{}` experiments is not part of this version yet",
            a.file.display(),
            other.name()
        ),
    }
}
