//! `rtid experiment <test>`: the paper's tests run on the model, written as
//! experiment files (the same format as measured data, so the two compare directly)
//! with a plot. One file per test.

pub mod check;
pub mod fluctuation;
pub mod frequency_response;
pub mod frequency_response_time;
pub mod friction_map;
pub mod periodic_summary;
pub mod positioning;
pub mod servo_trace;
pub mod speed_loop;
pub mod torque_curve;
pub mod unbalance;

use crate::cli::common::plot::Plot;
use std::path::{Path, PathBuf};

use anyhow::Context;

use super::ModelArgs;
use rtid::io::experiment_file::{self, Data, Experiment, Manifest};
use rtid::model::LoopMode;

pub const LONG_ABOUT: &str = "\
Runs one of the paper's tests on the model and writes it as an experiment file — a JSON \
manifest and a CSV in the format `rtid evaluate` reads (docs/experiment-files.md) — plus \
an SVG plot, into --out DIR. Virtual and measured experiments compare directly. \
`rtid experiment TEST --help` describes each test and its conditions.";

/// The tests.
#[derive(Debug, clap::Subcommand)]
pub enum Test {
    /// Frequency response, 10–600 Hz, nonlinear simulation per frequency (paper §4.1, Fig. 8).
    #[command(long_about = frequency_response::LONG_ABOUT)]
    FrequencyResponse(frequency_response::Args),
    /// Frequency response recorded as raw time series (stepped sine, noise or chirp) and estimated from them (H1/Welch with coherence, or sine demodulation).
    #[command(long_about = frequency_response_time::LONG_ABOUT)]
    FrequencyResponseTime(frequency_response_time::Args),
    /// ISO 230-2 positioning accuracy and repeatability (paper §4.3, Fig. 10).
    #[command(long_about = positioning::LONG_ABOUT)]
    Positioning(positioning::Args),
    /// Friction torque curve: motor torque under harmonic table motion (paper §4.2, Fig. 9).
    #[command(long_about = torque_curve::LONG_ABOUT)]
    TorqueCurve(torque_curve::Args),
    /// Rotational fluctuation at constant speed and its spectrum (paper §4.4, Figs. 11, 12).
    #[command(long_about = fluctuation::LONG_ABOUT)]
    Fluctuation(fluctuation::Args),
    /// Vertical table with an offset mass: the backlash step (paper §4.5, Fig. 14).
    #[command(long_about = unbalance::LONG_ABOUT)]
    Unbalance(unbalance::Args),
    /// Friction map: the mean motor torque at constant speeds in both directions, and the friction law it shows.
    #[command(long_about = friction_map::LONG_ABOUT)]
    FrictionMap(friction_map::Args),
    /// A servo trace of the model along point-to-point moves, as a drive's oscilloscope records it.
    #[command(long_about = servo_trace::LONG_ABOUT)]
    ServoTrace(servo_trace::Args),
    /// The closed speed loop's response (actual over setpoint speed) as a drive's measuring function records it.
    #[command(long_about = speed_loop::LONG_ABOUT)]
    SpeedLoop(speed_loop::Args),
}

/// Arguments every test takes.
#[derive(Debug, clap::Args)]
pub struct Common {
    #[command(flatten)]
    pub model: ModelArgs,
    /// An identification result (`rtid identify --out`): its values set in the model
    /// (--preset or --params, the base the fit started from) — the test on the
    /// identified model.
    #[arg(long, value_name = "FIT.json")]
    pub fit: Option<PathBuf>,
    /// A tuned parameter file (`rtid tune -o`): the test with its controller settings.
    #[arg(long, value_name = "FILE")]
    pub tune: Option<PathBuf>,
    /// Folder for the manifest, CSV and plot (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Print the evaluation as JSON.
    #[arg(long)]
    pub json: bool,
}

/// How a test reports an experiment file: print the evaluation (table or JSON) and
/// write the plots where [`Plot`] says.
pub type Report = fn(&Experiment, &Plot, bool) -> anyhow::Result<()>;

impl Common {
    /// The model the test runs on: the named set, with --fit's values and --tune's
    /// controller.
    pub fn params(&self) -> anyhow::Result<rtid::Params> {
        crate::cli::common::model_args::fitted(
            &self.model,
            self.fit.as_deref(),
            self.tune.as_deref(),
        )
    }

    /// The files the test reads (no output may overwrite them).
    fn inputs(&self) -> Vec<&Path> {
        self.model
            .params
            .iter()
            .chain(&self.fit)
            .chain(&self.tune)
            .map(PathBuf::as_path)
            .collect()
    }

    /// Writes the test's experiment file as `STEM.json` + `STEM.csv` in the output
    /// folder, reads it back — so the report is exactly what `rtid evaluate` says of
    /// the file — and reports it with the plot `STEM.svg`.
    pub fn write_and_report(
        &self,
        stem: &str,
        mut manifest: Manifest,
        data: &Data,
        report: Report,
    ) -> anyhow::Result<()> {
        let path = self.out.join(format!("{stem}.json"));
        for ext in ["json", "csv", "svg"] {
            let output = self.out.join(format!("{stem}.{ext}"));
            crate::cli::common::inputs::refuse_overwrite("--out", &output, &self.inputs())?;
        }
        manifest.data = Some(format!("{stem}.csv"));
        experiment_file::write(&path, &manifest, data)?;
        let plot = self.out.join(format!("{stem}.svg"));
        report(
            &experiment_file::read(&path)?,
            &Plot::at(plot, &self.inputs())?,
            self.json,
        )
    }

    /// Creates the output folder.
    pub fn create_out(&self) -> anyhow::Result<()> {
        std::fs::create_dir_all(&self.out)
            .with_context(|| format!("creating {}", self.out.display()))
    }
}

/// `--loop` against the parameter set's `controller.loop`: where it overrides a
/// different one, a note on stderr (unless `quiet`) and its text, for the manifest's
/// notes; `None` where the test runs in the set's own loop.
pub fn loop_override(given: Option<LoopMode>, p: &rtid::Params, quiet: bool) -> Option<String> {
    let own = p.controller.loop_mode;
    let mode = given.filter(|&m| m != own)?;
    let note = format!("--loop {mode} overrides the parameter set's controller.loop ({own})");
    if !quiet {
        eprintln!("note: {note}");
    }
    Some(note)
}

/// `manifest` with `note` appended to its notes.
pub fn add_note(manifest: &mut Manifest, note: Option<String>) {
    if let Some(note) = note {
        manifest.notes = Some(match manifest.notes.take() {
            Some(notes) => format!("{notes}; {note}"),
            None => note,
        });
    }
}

pub fn run(test: Test) -> anyhow::Result<()> {
    match test {
        Test::FrequencyResponse(a) => frequency_response::run(a),
        Test::FrequencyResponseTime(a) => frequency_response_time::run(a),
        Test::Positioning(a) => positioning::run(a),
        Test::TorqueCurve(a) => torque_curve::run(a),
        Test::Fluctuation(a) => fluctuation::run(a),
        Test::Unbalance(a) => unbalance::run(a),
        Test::ServoTrace(a) => servo_trace::run(a),
        Test::FrictionMap(a) => friction_map::run(a),
        Test::SpeedLoop(a) => speed_loop::run(a),
    }
}
