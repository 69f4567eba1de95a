//! `rtid experiment speed-loop`: the drive's own measurement of its closed speed
//! loop, made on the model.

use anyhow::bail;

use super::{Common, Plot};
use rtid::io::experiment_file::Experiment;
use rtid::report::speed_loop::{bode, Curve};
use rtid::tuning::speed_loop::measured::MeasuredSpeedLoop;
use rtid::tuning::speed_loop::{self, SpeedLoopTest};

pub const LONG_ABOUT: &str = "\
The speed loop's reference response as a drive's measuring function records it \
(SINUMERIK/SINAMICS: docs/tuning.md, \"The drive's own measurement\"): actual speed over \
speed setpoint with the speed loop closed (the position loop open), one line per DFT bin \
of a PRBS period of 2^order − 1 control periods, k/(N·Tc) for k = 1 … (N − 1)/2 − 1 — on \
the model's loop exact on the sampled loop (the drive held over Tc, the encoder's dead \
time, the backward-difference speed, the PI, the setpoint filters, the output delay), \
linear (no friction, no backlash). --noise-percent adds seeded complex noise to each line \
(default 1 %) and the coherence column says it for --averages spectra (γ² = 1/(1 + 2n·σ²)), \
as the drive's file does.

The file is what `rtid import` writes from a drive's measurement (a frequency response \
with response \"speed_loop\", loop_period_s, averages, coherence): `rtid identify` fits it \
with the speed_loop objective — the gains Kvp, Kvi and the encoder's dead time (and a \
two-mass drive's Jm, Kw, Ciw) with the inertia held, as a drive's file carries no \
controller settings; --state-gains writes Kvp and Kvi into the manifest (controller), \
and the inertia is fitted instead.

Outputs, in --out DIR: speed_loop.json/.csv (gain, phase, coherence, the exact gain) and \
speed_loop.svg (Bode). Printed: lines, the −3 dB bandwidth and its phase, the peak.

Example:
  rtid experiment speed-loop --preset direct-drive --set Tc=1.25e-4 --out runs/speed
  rtid identify runs/speed/speed_loop.json --preset direct-drive --set Tc=1.25e-4 \\
      --set Kvp=100 --set Kvi=5000 --set encoder_delay=1e-4 --out fit.json";

/// Arguments of `rtid experiment speed-loop`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub common: Common,
    /// The PRBS's order: its period is 2^order − 1 control periods (4 … 20).
    #[arg(long, value_name = "ORDER", default_value_t = 11)]
    pub prbs_order: u32,
    /// Complex noise on each line, % of the response (σ of each part).
    #[arg(long, value_name = "PERCENT", default_value_t = 1.0)]
    pub noise_percent: f64,
    /// Spectra averaged per line, for the coherence column (a drive: 2, its directions).
    #[arg(long, value_name = "N", default_value_t = 2)]
    pub averages: u32,
    /// Seed of the noise.
    #[arg(long, value_name = "SEED", default_value_t = 1)]
    pub seed: u64,
    /// Write the speed controller's gains into the manifest (a drive's file has none).
    #[arg(long)]
    pub state_gains: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    if !(a.noise_percent.is_finite() && (0.0..=50.0).contains(&a.noise_percent)) {
        bail!("--noise-percent {}: give 0 … 50", a.noise_percent);
    }
    if a.averages == 0 {
        bail!("--averages 0: a spectrum averages at least one");
    }
    let p = a.common.params()?;
    let test = SpeedLoopTest {
        prbs_order: a.prbs_order,
        noise_percent: a.noise_percent,
        averages: a.averages,
        seed: a.seed,
        state_gains: a.state_gains,
    };
    let record = speed_loop::run(&p, &test)?;
    a.common.create_out()?;
    a.common.write_and_report(
        "speed_loop",
        speed_loop::manifest(&p, &test),
        &speed_loop::to_data(&record, &test),
        report,
    )
}

/// The summary, and the Bode plot.
pub fn report(exp: &Experiment, plot: &Plot, json: bool) -> anyhow::Result<()> {
    let m = MeasuredSpeedLoop::of(exp).map_err(anyhow::Error::msg)?;
    let s = m.summary();
    let (gain, phase) = m.bode();
    plot.write(
        &bode(
            "closed speed loop",
            &[Curve {
                name: "response",
                frequency_hz: &m.frequency_hz,
                gain_db: &gain,
                phase_deg: &phase,
                measured: true,
            }],
        ),
        "",
    )?;
    if json {
        println!(
            "{}",
            rtid::io::json::pretty(&serde_json::json!({ "summary": s }))?
        );
        return Ok(());
    }
    println!(
        "{} lines, {:.2} … {:.1} Hz; −3 dB at {}; peak {:+.2} dB at {:.1} Hz",
        s.lines,
        s.lowest_hz,
        s.highest_hz,
        match (s.bandwidth_hz, s.phase_at_bandwidth_deg) {
            (Some(f), Some(ph)) => format!("{f:.1} Hz (phase {ph:.0}°)"),
            _ => "no line".into(),
        },
        s.peak_db,
        s.peak_hz
    );
    Ok(())
}
