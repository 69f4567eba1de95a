//! `rtid simulate`: one time simulation, written as a CSV of every state.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context};
use comfy_table::{presets::UTF8_FULL_CONDENSED, Table};

use crate::cli::experiment::check;
use crate::cli::ModelArgs;
use rtid::input::{Move, Samples};
use rtid::input_spec::InputSpec;
use rtid::io::{atomic, torque_file};
use rtid::limits::{MAX_ROWS, MAX_STEPS};
use rtid::model::{idx::*, NSTATE};
use rtid::recorder::Recorder;
use rtid::sim::{Simulation, STATE_NAMES};

pub const LONG_ABOUT: &str = "\
Integrates the nonlinear model (backlash, stick-slip friction, gear fluctuation, servo) \
from rest and writes every state to a CSV: time_s, motor_torque_nm, motor/shaft/table \
angles (rad) and velocities (rad/s), the worm's axial displacement (m) and velocity (m/s), \
and for closed-loop moves the commanded table angle (reference_rad).

Inputs (--input):
  sine:freq_hz=F,amp_nm=A[,offset_nm=O]   open-loop motor torque O + A·sin(2πFt)
  step:torque_nm=T[,at_s=S]                open-loop torque step at time S
  file:PATH.csv                            open-loop torque from columns time_s, motor_torque_nm
  move:target_deg=D[,speed_deg_per_min=V][,loop=semi_closed|full_closed]
                                           closed-loop move of the table to D degrees:
                                           a step command, or a ramp at V °/min
  none                                     free response (with --load-nm, a table torque)

The integration step defaults to the largest of 10, 5, 2.5, 2 µs (then decades below) that \
resolves the stiffest mode of the linearised model (|λ|·dt ≤ 0.1; docs/model.md).

Examples:
  rtid simulate --preset worm-gear --input sine:freq_hz=100,amp_nm=5 --duration-s 0.5 --out run.csv
  rtid simulate --preset worm-gear --input move:target_deg=30 --duration-s 1 --out move.csv";

/// Arguments of `rtid simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArgs,
    /// What drives the table (see above): sine:…, step:…, file:…, move:…, none.
    #[arg(long, value_name = "SPEC")]
    pub input: InputSpec,
    /// Simulated time, s.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub duration_s: f64,
    /// Output CSV (written atomically).
    #[arg(long, value_name = "FILE.csv")]
    pub out: PathBuf,
    /// Integration step, s (default: from the stiffest mode).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub dt_s: Option<f64>,
    /// Period of the output samples, s (rounded to whole steps).
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 1e-4,
        allow_negative_numbers = true
    )]
    pub sample_s: f64,
    /// Constant external torque on the table (e.g. a brake), N·m.
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub load_nm: f64,
    /// Print a JSON summary instead of a table.
    #[arg(long)]
    pub json: bool,
    /// No progress bar (shown on a terminal, with the simulated time and the time left).
    #[arg(long)]
    pub quiet: bool,
}

/// Streams every `every`-th sample into a CSV.
struct CsvRecorder<W: Write> {
    out: csv::Writer<W>,
    every: u64,
    count: u64,
    reference: Option<(Move, f64)>,
    error: Option<csv::Error>,
    /// Simulated milliseconds (hidden unless stderr is a terminal).
    bar: indicatif::ProgressBar,
}

impl<W: Write> Recorder for CsvRecorder<W> {
    fn record(&mut self, t: f64, y: &[f64; NSTATE], motor_torque: f64) {
        let keep = self.count % self.every == 0;
        self.count += 1;
        if !keep || self.error.is_some() {
            return;
        }
        let mut row: Vec<String> = Vec::with_capacity(NSTATE + 3);
        row.push(format!("{t:.9}"));
        row.push(format!("{motor_torque:.9e}"));
        row.extend(y.iter().map(|v| format!("{v:.12e}")));
        if let Some((m, _)) = &self.reference {
            use rtid::input::Trajectory;
            row.push(format!("{:.12e}", m.angle(t)));
        }
        if let Err(e) = self.out.write_record(&row) {
            self.error = Some(e);
        }
        self.bar.set_position((t * 1e3) as u64);
    }
}

impl Args {
    /// The numeric options, checked before anything runs.
    fn check(&self) -> anyhow::Result<()> {
        if !(self.duration_s > 0.0 && self.duration_s.is_finite()) {
            bail!(
                "--duration-s {}: must be a positive number of seconds",
                self.duration_s
            );
        }
        if !(self.sample_s > 0.0 && self.sample_s.is_finite()) {
            bail!(
                "--sample-s {}: must be a positive number of seconds",
                self.sample_s
            );
        }
        if let Some(dt) = self.dt_s {
            check::positive(dt, "--dt-s")?;
        }
        if !self.load_nm.is_finite() {
            bail!("--load-nm {}: must be a finite torque in N·m", self.load_nm);
        }
        Ok(())
    }
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let p = a.model.load()?;
    a.check()?;
    let mut inputs: Vec<&std::path::Path> = a.model.params.iter().map(|p| p.as_path()).collect();
    if let InputSpec::File(path) = &a.input {
        inputs.push(path);
    }
    crate::cli::common::inputs::refuse_overwrite("--out", &a.out, &inputs)?;
    let mut sim = match a.dt_s {
        Some(dt) => Simulation::new(&p, dt).context("--dt-s")?,
        None => Simulation::with_default_step(&p)?,
    };
    sim.set_load(a.load_nm);
    let steps = a.duration_s / sim.dt();
    check::work(
        steps,
        MAX_STEPS,
        "integration steps",
        "--duration-s over --dt-s (or the default step)",
    )?;
    let every = ((a.sample_s / sim.dt()).round() as u64).max(1);
    check::work(
        steps / every as f64,
        MAX_ROWS,
        "rows of CSV",
        "--duration-s over --sample-s",
    )?;
    let started = Instant::now();
    let closed = matches!(a.input, InputSpec::Move { .. });
    let mut recorded = match &a.input {
        InputSpec::File(path) => Some(torque_file::read(path)?),
        _ => None,
    };
    write_csv(
        &a.out,
        closed,
        |rec| drive(&mut sim, &p, &a.input, recorded.take(), a.duration_s, rec),
        every,
        crate::cli::common::progress::bar((a.duration_s * 1e3) as u64, "simulated ms", a.quiet),
    )
    .with_context(|| {
        format!(
            "the run of --input with --load-nm {}",
            rtid::names::Num(a.load_nm)
        )
    })?;
    let wall = started.elapsed().as_secs_f64();
    print_summary(&a, &sim, p.ratio(), wall)
}

/// Runs `duration` s of `input` (`recorded`: the torque file's samples) on `sim`,
/// a move's reference recorded beside the states.
fn drive<W: Write>(
    sim: &mut Simulation,
    p: &rtid::model::Params,
    input: &InputSpec,
    recorded: Option<(Vec<f64>, Vec<f64>)>,
    duration: f64,
    rec: &mut CsvRecorder<W>,
) -> Result<(), rtid::sim::SimError> {
    rec.reference = input.reference().map(|m| (m, 0.0));
    let torques = recorded.map(|(t, q)| Samples::new(t, q));
    input.run(sim, p, torques, duration, rec)
}

/// The run's summary: steps, wall time, final angles; a table or JSON.
fn print_summary(a: &Args, sim: &Simulation, ratio: f64, wall: f64) -> anyhow::Result<()> {
    let steps = (sim.time() / sim.dt()).round();
    let y = sim.state();
    if a.json {
        // Through the finite check: json! writes a NaN as null, silently.
        let final_state: std::collections::BTreeMap<&str, f64> =
            STATE_NAMES.iter().copied().zip(y).collect();
        let summary = serde_json::json!({
            "output": a.out,
            "steps": steps,
            "dt_s": rtid::io::json::value(&sim.dt())?,
            "simulated_s": rtid::io::json::value(&sim.time())?,
            "wall_time_s": rtid::io::json::value(&wall)?,
            "steps_per_s": rtid::io::json::value(&(steps / wall.max(1e-9)))?,
            "final": rtid::io::json::value(&final_state)?,
        });
        println!("{}", rtid::io::json::pretty(&summary)?);
        return Ok(());
    }
    let mut t = Table::new();
    t.load_preset(UTF8_FULL_CONDENSED);
    t.set_header(["", "value"]);
    t.add_row(["output", &a.out.display().to_string()]);
    t.add_row([
        "steps × dt",
        &format!("{steps} × {:.3e} s = {:.4} s", sim.dt(), sim.time()),
    ]);
    t.add_row([
        "wall time",
        &format!("{wall:.3} s ({:.1} M steps/s)", steps / wall / 1e6),
    ]);
    t.add_row([
        "final table angle",
        &format!("{:.6}°", y[THETA_T].to_degrees()),
    ]);
    t.add_row([
        "final motor angle × ratio",
        &format!("{:.6}°", (y[THETA_M] * ratio).to_degrees()),
    ]);
    println!("{t}");
    Ok(())
}

/// Runs `simulate` with a CSV recorder streaming into `path` (atomically replaced).
fn write_csv(
    path: &Path,
    closed: bool,
    simulate: impl FnOnce(
        &mut CsvRecorder<&mut std::io::BufWriter<&std::fs::File>>,
    ) -> Result<(), rtid::sim::SimError>,
    every: u64,
    bar: indicatif::ProgressBar,
) -> anyhow::Result<()> {
    let result: anyhow::Result<()> = atomic::write_with(path, |w| {
        let mut out = csv::Writer::from_writer(w);
        let mut header = vec!["time_s", "motor_torque_nm"];
        header.extend(STATE_NAMES);
        if closed {
            header.push("reference_rad");
        }
        out.write_record(&header)?;
        let mut rec = CsvRecorder {
            out,
            every,
            count: 0,
            reference: None,
            error: None,
            bar,
        };
        simulate(&mut rec)?;
        rec.bar.finish_and_clear();
        if let Some(e) = rec.error {
            return Err(e.into());
        }
        rec.out.flush()?;
        Ok(())
    });
    result.with_context(|| format!("writing {}", path.display()))
}
